//! Tests of `harness::golden::noise`.

use harness::golden::noise::*;

#[test]
fn limits_round_up_to_three_digits() {
    assert_eq!(round_up(1.14441e-4), 1.15e-4);
    assert_eq!(round_up(0.0207), 0.0207);
    assert_eq!(round_up(0.0), 0.0);
    assert!(round_up(3.0 * 3.814_697_265_625e-5) >= 3.0 * 3.814_697_265_625e-5);
}

/// A limit or figure that is not a finite number (NaN fails every check, infinity passes every
/// one) or a margin that is not positive is an error naming the file and the key; no file is
/// an empty model.
#[test]
fn a_limit_that_is_not_a_finite_positive_number_is_an_error_naming_its_key() {
    let dir = tempfile::tempdir().unwrap();
    let store = harness::golden::GoldenStore::new(dir.path());
    assert_eq!(NoiseModel::load(&store).unwrap(), NoiseModel::default());
    let good = "margin = 3.0\nregenerate = \"x\"\n\n[scenes.corner.final.\"flip_mean\"]\n\
                limit = 0.014\nresolution = 0.001\n\n[scenes.corner.final.\"flip_mean\".noise]\n\
                \"drivers/gl\" = 0.002\n";
    let path = dir.path().join(NOISE_FILE);
    std::fs::write(&path, good).unwrap();
    assert_eq!(
        NoiseModel::load(&store).unwrap().scenes["corner"]["final"]["flip_mean"].limit,
        0.014
    );
    for (from, to, says) in [
        ("limit = 0.014", "limit = nan", "limit NaN"),
        ("limit = 0.014", "limit = inf", "limit inf"),
        ("limit = 0.014", "limit = -1.0", "limit -1"),
        // A FLIP error lies in 0..1: a limit of 1 or more could never fail.
        (
            "limit = 0.014",
            "limit = 5.0",
            "limit 5 can never be exceeded",
        ),
        ("margin = 3.0", "margin = nan", "margin NaN"),
        ("= 0.002", "= -0.5", "drivers/gl -0.5"),
    ] {
        std::fs::write(&path, good.replace(from, to)).unwrap();
        let error = NoiseModel::load(&store).unwrap_err().to_string();
        assert!(
            error.contains("noise.toml") && error.contains(says),
            "{to}: {error}"
        );
    }
}
