//! Tests of `harness::golden::noise`.

use harness::golden::noise::*;

#[test]
fn limits_round_up_to_three_digits() {
    assert_eq!(round_up(1.14441e-4), 1.15e-4);
    assert_eq!(round_up(0.0207), 0.0207);
    assert_eq!(round_up(0.0), 0.0);
    assert!(round_up(3.0 * 3.814_697_265_625e-5) >= 3.0 * 3.814_697_265_625e-5);
}
