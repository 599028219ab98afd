//! The prediction of a calibrated variant on runs it was not calibrated on:
//! the pointwise median of its histories at the estimate and one
//! finite-difference step either side of it along each of the extension's
//! own parameters (the physics that switches on and off; the resolution of
//! the final search, [`difference_step`]). The baseline, a linear model,
//! predicts by its estimate alone.
//!
//! Where the model's response depends chaotically on its parameters (a
//! grid end that strikes the wall within one time step, a support that
//! slips or sticks), histories a fraction of a percent apart in a
//! parameter differ in the timing of every impact, the calibration runs
//! cannot tell them apart, and one of them may rattle where the others do
//! not. Their pointwise median keeps what they share (the clamped
//! amplitude, the shifted resonance) and drops what none of them can
//! predict; one member that rattles cannot pull it. Where the response is
//! smooth in the parameters the members barely differ and the median is
//! the estimate's own history.

use super::fit::Simulated;

/// Finite-difference step (unit cube) of a parameter: 2e-2 for an
/// extension's own parameters (they switch contact or slip on and off, and
/// a wider step averages over the jumps a narrow one would see), 2e-3 for
/// the others.
pub fn difference_step(own_of_extension: bool) -> f64 {
    if own_of_extension {
        2e-2
    } else {
        2e-3
    }
}

/// The ensemble's unit-cube points: `u` first, then `u ± steps[i]` along
/// each dimension `i` with a positive step, clamped to the cube (a step
/// clamped back onto `u`, at a bound, is not repeated).
pub fn members(u: &[f64], steps: &[f64]) -> Vec<Vec<f64>> {
    let mut out = vec![u.to_vec()];
    for (i, h) in steps.iter().enumerate().filter(|(_, h)| **h > 0.0) {
        for sign in [1.0, -1.0] {
            let mut v = u.to_vec();
            v[i] = (u[i] + sign * h).clamp(0.0, 1.0);
            if !out.contains(&v) {
                out.push(v);
            }
        }
    }
    out
}

/// The pointwise median of members' simulated runs (member → run →
/// sensor → samples): per run, sensor and sample, the median of the finite
/// values (NaN where none is). The layout is the first member's; a member
/// whose runs or sensors differ from it is left out. None without members.
pub fn pointwise_median(members: &[Vec<Simulated>]) -> Option<Vec<Simulated>> {
    let first = members.first()?;
    let same = |m: &&Vec<Simulated>| {
        m.len() == first.len()
            && m.iter().zip(first).all(|(a, b)| {
                a.len() == b.len()
                    && a.iter().zip(b).all(|((ia, sa), (ib, sb))| ia == ib && sa.len() == sb.len())
            })
    };
    let kept: Vec<&Vec<Simulated>> = members.iter().filter(same).collect();
    let mut column = Vec::with_capacity(kept.len());
    let runs = first
        .iter()
        .enumerate()
        .map(|(r, run)| {
            run.iter()
                .enumerate()
                .map(|(s, (id, samples))| {
                    let series = (0..samples.len())
                        .map(|t| {
                            column.clear();
                            column.extend(
                                kept.iter().map(|m| m[r][s].1[t]).filter(|v| v.is_finite()),
                            );
                            median(&mut column)
                        })
                        .collect();
                    (id.clone(), series)
                })
                .collect()
        })
        .collect();
    Some(runs)
}

/// The median of `values` (reordered; NaN when empty).
fn median(values: &mut [f64]) -> f64 {
    let n = values.len();
    if n == 0 {
        return f64::NAN;
    }
    values.sort_unstable_by(f64::total_cmp);
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn one_run(values: &[f64]) -> Vec<Simulated> {
        vec![vec![("A".to_string(), values.to_vec())]]
    }

    #[test]
    fn members_step_either_way_inside_the_cube() {
        let m = members(&[0.5, 0.995], &[0.1, 0.02]);
        assert_eq!(m.len(), 5);
        assert_eq!(m[0], vec![0.5, 0.995]);
        assert_eq!((m[1][0], m[2][0]), (0.6, 0.4));
        assert_eq!((m[3][1], m[4][1]), (1.0, 0.975));
        assert!(m.iter().all(|v| v[0] == 0.5 || v[1] == 0.995));
        // At a bound the step that would leave the cube is the estimate.
        let m = members(&[1.0, 0.5], &[0.02, 0.1]);
        assert_eq!(m.len(), 4);
        assert_eq!(m[1], vec![0.98, 0.5]);
        // A dimension without a step is held.
        assert_eq!(members(&[0.3, 0.5], &[0.0, 0.1]).len(), 3);
        assert_eq!(members(&[0.3, 0.5], &[0.0, 0.0]), vec![vec![0.3, 0.5]]);
    }

    #[test]
    fn one_rattling_member_does_not_move_the_median() {
        let quiet = one_run(&[1.0, 2.0, 3.0]);
        let rattling = one_run(&[50.0, -40.0, 90.0]);
        let med = pointwise_median(&[quiet.clone(), rattling, quiet.clone()]).unwrap();
        assert_eq!(med, quiet);
    }

    #[test]
    fn missing_values_and_mismatched_members_are_skipped() {
        let a = one_run(&[1.0, f64::NAN]);
        let b = one_run(&[3.0, f64::NAN]);
        let short = one_run(&[100.0]);
        let med = pointwise_median(&[a, b, short]).unwrap();
        assert_eq!(med[0][0].1[0], 2.0);
        assert!(med[0][0].1[1].is_nan());
        assert!(pointwise_median(&[]).is_none());
    }

    proptest! {
        /// Identical members give back their history; the median lies
        /// between the members' smallest and largest value at every sample.
        #[test]
        fn the_median_is_inside_the_members(
            rows in proptest::collection::vec(proptest::collection::vec(-1e3f64..1e3, 4), 1..7),
        ) {
            let ms: Vec<Vec<Simulated>> = rows.iter().map(|r| one_run(r)).collect();
            let med = pointwise_median(&ms).unwrap();
            for t in 0..4 {
                let lo = rows.iter().map(|r| r[t]).fold(f64::INFINITY, f64::min);
                let hi = rows.iter().map(|r| r[t]).fold(f64::NEG_INFINITY, f64::max);
                prop_assert!(lo <= med[0][0].1[t] && med[0][0].1[t] <= hi);
            }
            let same = pointwise_median(&[ms[0].clone(), ms[0].clone(), ms[0].clone()]).unwrap();
            prop_assert_eq!(&same, &ms[0]);
        }
    }
}
