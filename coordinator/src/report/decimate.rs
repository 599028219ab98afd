//! Min/max decimation of long series for drawing: the samples are cut into
//! equal buckets by index and each bucket keeps its smallest and largest
//! finite y (in their original order), so every peak survives and the
//! global minimum and maximum are kept exactly. A bucket that contains a
//! missing reading (non-finite y or x) keeps one gap marker (NaN) at the
//! place of its first missing reading, so lines still break there.

/// Decimate `(x, y)` (same length) to at most `max_points` finite points
/// (`max_points >= 2`); shorter input is returned unchanged. Gaps are NaN.
pub fn decimate_min_max(x: &[f64], y: &[f64], max_points: usize) -> (Vec<f64>, Vec<f64>) {
    let n = x.len().min(y.len());
    let max_points = max_points.max(2);
    if n <= max_points {
        return (x[..n].to_vec(), y[..n].to_vec());
    }
    let buckets = max_points / 2;
    let size = n.div_ceil(buckets);
    let (mut xo, mut yo) =
        (Vec::with_capacity(max_points + buckets), Vec::with_capacity(max_points + buckets));
    for start in (0..n).step_by(size) {
        let end = (start + size).min(n);
        for i in bucket_keep(x, y, start, end) {
            match i {
                Some(i) => {
                    xo.push(x[i]);
                    yo.push(y[i]);
                }
                None => {
                    xo.push(f64::NAN);
                    yo.push(f64::NAN);
                }
            }
        }
    }
    (xo, yo)
}

/// Indices to keep of bucket `start..end` in order; `None` is a gap marker.
fn bucket_keep(x: &[f64], y: &[f64], start: usize, end: usize) -> Vec<Option<usize>> {
    let finite = |i: usize| x[i].is_finite() && y[i].is_finite();
    let (mut lo, mut hi, mut gap) = (None::<usize>, None::<usize>, None::<usize>);
    for i in start..end {
        if !finite(i) {
            gap.get_or_insert(i);
            continue;
        }
        if lo.is_none_or(|j| y[i] < y[j]) {
            lo = Some(i);
        }
        if hi.is_none_or(|j| y[i] > y[j]) {
            hi = Some(i);
        }
    }
    let mut keep: Vec<usize> = lo.into_iter().chain(hi).collect();
    keep.sort_unstable();
    keep.dedup();
    let mut out: Vec<Option<usize>> = keep.iter().map(|&i| Some(i)).collect();
    if let Some(g) = gap {
        let at = keep.iter().take_while(|&&i| i < g).count();
        out.insert(at, None);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn short_input_is_unchanged() {
        let (x, y) = decimate_min_max(&[0.0, 1.0], &[3.0, f64::NAN], 10);
        assert_eq!(x, [0.0, 1.0]);
        assert!(y[0] == 3.0 && y[1].is_nan());
    }

    #[test]
    fn one_spike_survives() {
        let n = 100_000;
        let x: Vec<f64> = (0..n).map(|i| i as f64 * 0.005).collect();
        let mut y = vec![0.0; n];
        y[54_321] = 9.81;
        let (xd, yd) = decimate_min_max(&x, &y, 4000);
        assert!(xd.len() <= 4000);
        let k = yd.iter().position(|&v| v == 9.81).expect("spike kept");
        assert_eq!(xd[k], x[54_321]);
    }

    #[test]
    fn gap_breaks_the_line_at_its_place() {
        let n = 1000;
        let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let mut y: Vec<f64> = x.iter().map(|v| v.sin()).collect();
        for v in &mut y[500..520] {
            *v = f64::NAN;
        }
        let (xd, yd) = decimate_min_max(&x, &y, 100);
        let gaps: Vec<usize> = (0..yd.len()).filter(|&i| yd[i].is_nan()).collect();
        assert!(!gaps.is_empty());
        for g in gaps {
            let before = xd[..g].iter().rev().find(|v| v.is_finite()).copied().unwrap_or(-1.0);
            let after = xd[g..].iter().find(|v| v.is_finite()).copied().unwrap_or(2000.0);
            assert!(before < 500.0 || after >= 520.0, "gap between {before} and {after}");
        }
    }

    proptest! {
        #[test]
        fn keeps_global_extremes_and_bound(
            y in proptest::collection::vec(prop_oneof![9 => -1e6..1e6f64, 1 => Just(f64::NAN)], 1..5000),
            max_points in 2usize..600,
        ) {
            let x: Vec<f64> = (0..y.len()).map(|i| i as f64).collect();
            let (xd, yd) = decimate_min_max(&x, &y, max_points);
            let finite_out = yd.iter().filter(|v| v.is_finite()).count();
            prop_assert!(finite_out <= max_points.max(y.len().min(max_points)));
            let fin = |v: &[f64]| v.iter().copied().filter(|v| v.is_finite()).fold(None, |a: Option<(f64, f64)>, v| {
                Some(a.map_or((v, v), |(l, h)| (l.min(v), h.max(v))))
            });
            prop_assert_eq!(fin(&y), fin(&yd));
            // every kept point is an original sample, in order
            let kept: Vec<f64> = xd.iter().copied().filter(|v| v.is_finite()).collect();
            prop_assert!(kept.windows(2).all(|w| w[0] < w[1]));
            for (xi, yi) in xd.iter().zip(&yd) {
                if xi.is_finite() {
                    prop_assert_eq!(y[*xi as usize].to_bits(), yi.to_bits());
                }
            }
        }
    }
}
