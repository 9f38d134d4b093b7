//! Order statistics, one rank rule for the whole workspace: the harness's metrics, sweeps,
//! benches and references, and the tests, all take percentiles here.
//!
//! The rule is the nearest rank: the `p` percentile of `n` sorted values is the value at rank
//! `ceil(p n)` (1-based), so it is always one of the values, p = 0.5 of an even count is the
//! lower middle value, and p = 1 is the largest.

/// The `p` (0..=1) percentile of an ascending slice by nearest rank; 0 for an empty slice.
pub fn percentile_of_sorted(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    sorted[nearest_rank(sorted.len(), p) - 1]
}

/// The `p` (0..=1) percentile of `values` in any order, by nearest rank; `None` when empty.
/// NaNs sort last (`f64::total_cmp`).
pub fn percentile(mut values: Vec<f64>, p: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    // Found by selection in linear time rather than a full sort (the sun detection takes the
    // median of every texel of an environment).
    let rank = nearest_rank(values.len(), p);
    Some(*values.select_nth_unstable_by(rank - 1, f64::total_cmp).1)
}

/// The 1-based nearest rank `ceil(p n)` of the `p` percentile of `len` (> 0) values.
fn nearest_rank(len: usize, p: f64) -> usize {
    ((len as f64 * p).ceil() as usize).clamp(1, len)
}

/// The median (the 0.5 percentile by nearest rank) of `values`; `None` when empty.
pub fn median(values: Vec<f64>) -> Option<f64> {
    percentile(values, 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank() {
        let v: Vec<f64> = (1..=10).map(f64::from).collect();
        assert_eq!(percentile_of_sorted(&v, 0.0), 1.0);
        assert_eq!(percentile_of_sorted(&v, 0.1), 1.0);
        assert_eq!(percentile_of_sorted(&v, 0.11), 2.0);
        assert_eq!(percentile_of_sorted(&v, 0.99), 10.0);
        assert_eq!(percentile_of_sorted(&v, 1.0), 10.0);
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![]), None);
        assert_eq!(percentile_of_sorted(&[], 0.5), 0.0);
    }

    /// Selection on values in any order gives the sorted slice's value at every rank.
    #[test]
    fn unsorted_values_give_the_sorted_rank() {
        let shuffled: Vec<f64> = (0..101).map(|i| f64::from((i * 37) % 101)).collect();
        let mut sorted = shuffled.clone();
        sorted.sort_by(f64::total_cmp);
        for p in [0.0, 0.01, 0.5, 0.95, 0.99, 1.0] {
            assert_eq!(
                percentile(shuffled.clone(), p),
                Some(percentile_of_sorted(&sorted, p))
            );
        }
    }
}
