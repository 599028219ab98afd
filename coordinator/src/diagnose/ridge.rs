//! Ridge walks: a profile of an extension's likelihood along one of its
//! shape parameters, the onset re-fitted at every step.
//!
//! The time-history likelihood of a contact or slip model is needle-sharp
//! in its onset (a gap, a slip force): the impacts or slips must fall at
//! the measured instants. Where the law in the specimen differs from the
//! model's (a contact that softens after its first 0.1 mm), the needle
//! runs along a curved ridge in (onset, shape), and the windowed misfits
//! that bring a search near it can favour another end of the ridge than
//! the time histories do. On an OpenSees-simulated campaign with such a
//! contact, a pounding calibration stopped at the stiffest contact of the
//! prior, −log L = −11506, 0.03 in the gap off the ridge; the ridge's best
//! point, at the seed's contact stiffness, had −14718. Forward differences
//! (0.02 in the unit cube) step across a needle 0.01 wide, and a straight
//! probe along the least-determined direction falls off a curved ridge;
//! a walk that re-fits the onset on a fine window at each step stays on it.

use super::calibrate::{Calibration, Point, Search};
use super::executor::ExecutorError;

/// Step of the shape parameter between ridge points (unit cube).
pub const RIDGE_STEP: f64 = 0.06;

/// Ridge points per direction at most.
pub const RIDGE_STEPS: usize = 6;

/// Ridge points in a row worse than the one before, in the time histories
/// and in their envelopes, that a direction goes on past.
pub const RIDGE_PATIENCE: usize = 1;

/// Onset probes per ridge point (odd: one at the predicted onset).
pub const ONSET_PROBES: usize = 7;

/// Spacing of the onset probes (unit cube), under the needle's width.
pub const ONSET_SPACING: f64 = 0.008;

/// The two dimensions a ridge walk moves: the shape parameter it steps
/// and the onset it re-fits at every step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ridge {
    /// Dimension of the onset (re-fitted).
    pub onset: usize,
    /// Dimension of the shape parameter (stepped).
    pub shape: usize,
}

/// What a ridge walk knows of a point: −log L of the time histories (its
/// objective) and of their envelopes (its trend). The first is bumpy along
/// a shape parameter that sets a post-slip or post-contact frequency: the
/// phase of a 12 s record wraps, and a friction fit's profile along its
/// hardening ran −8153, −8148, −8150, −8167, −8194 nats in steps of 0.06
/// while the envelopes' fell steadily, −125 to −160.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Value {
    /// −log L of the time histories (+∞: failed).
    pub fit: f64,
    /// −log L of the windowed RMS misfits (+∞: failed).
    pub trend: f64,
}

impl Value {
    /// Worse than `other` in the time histories and in their envelopes.
    fn worse_than(&self, other: &Value) -> bool {
        self.fit > other.fit && self.trend > other.trend
    }
}

/// Evaluates a batch of unit-cube points.
pub type Evaluate<'f, E> = dyn FnMut(&[Vec<f64>]) -> Result<Vec<Value>, E> + 'f;

/// FE points a ridge walk evaluates at most.
pub const fn max_runs() -> usize {
    2 * RIDGE_STEPS * (ONSET_PROBES + ONSET_PROBES / 2 + 1)
}

impl Search<'_, '_> {
    /// A [`walk_ridge`] from `u` along each of the extension's own
    /// parameters other than its onset (`onset`, a dimension), one after
    /// the other from where the last ended; every point evaluated joins
    /// `cal`. Returns the best point when it beats `u` by 0.01 nats.
    pub(super) fn ridge_walks(
        &mut self,
        cal: &mut Calibration,
        u: &[f64],
        onset: usize,
        progress: &mut dyn FnMut(usize),
    ) -> Result<Option<Vec<f64>>, ExecutorError> {
        let n_eff = self.n_eff;
        let value = |p: &Point| Value { fit: p.neg_log_lik(n_eff), trend: p.coarse };
        let f_u = cal.last_at(u).map_or(Value { fit: f64::INFINITY, trend: f64::INFINITY }, value);
        let mut at = (u.to_vec(), f_u);
        let shapes: Vec<usize> = self.own.iter().copied().filter(|i| *i != onset).collect();
        for shape in shapes {
            let mut eval = |us: &[Vec<f64>]| -> Result<Vec<Value>, ExecutorError> {
                Ok(self.evaluate_into(cal, us, progress)?.iter().map(value).collect())
            };
            at = walk_ridge(&at.0, at.1, Ridge { onset, shape }, &mut eval)?;
        }
        Ok((at.1.fit < f_u.fit - 0.01).then_some(at.0))
    }
}

/// Walks the ridge from `start` (value `v_start`) both ways along
/// `ridge.shape` in steps of [`RIDGE_STEP`]: at each step the onset is
/// probed on [`ONSET_PROBES`] points around where the last two ridge points
/// predict it (more beyond the window when the best probe is on its edge,
/// and one at the vertex of a parabola through the best three), the other
/// dimensions held at `start`; a direction ends at the cube's face, after
/// [`RIDGE_STEPS`], or when more than [`RIDGE_PATIENCE`] ridge points in a
/// row are each worse than the one before in both [`Value`]s. Returns the
/// best point seen by −log L (`start` when none beat it).
pub fn walk_ridge<E>(
    start: &[f64],
    v_start: Value,
    ridge: Ridge,
    eval: &mut Evaluate<'_, E>,
) -> Result<(Vec<f64>, Value), E> {
    let mut best = (start.to_vec(), v_start);
    for dir in [-1.0, 1.0] {
        let mut last = (start[ridge.shape], start[ridge.onset], v_start);
        let (mut slope, mut worse) = (0.0, 0);
        for _ in 0..RIDGE_STEPS {
            let s = (last.0 + dir * RIDGE_STEP).clamp(0.0, 1.0);
            if (s - last.0).abs() < 1e-9 {
                break;
            }
            let centre = last.1 + slope * (s - last.0);
            let Some((u, f)) = refit_onset(start, ridge, s, centre, eval)? else { break };
            tracing::debug!(shape = s, onset = u[ridge.onset], ?f, "ridge point");
            if f.fit < best.1.fit {
                best = (u.clone(), f);
            }
            slope = (u[ridge.onset] - last.1) / (s - last.0);
            worse = if f.worse_than(&last.2) { worse + 1 } else { 0 };
            last = (s, u[ridge.onset], f);
            if worse > RIDGE_PATIENCE {
                break;
            }
        }
    }
    Ok(best)
}

/// The best of the onset probes at shape `s` around `centre` (and of
/// those beyond the window's edge when the best is on it), then of one more
/// at the vertex of the parabola through the best and its neighbours; None
/// when every probe failed.
fn refit_onset<E>(
    start: &[f64],
    ridge: Ridge,
    s: f64,
    centre: f64,
    eval: &mut Evaluate<'_, E>,
) -> Result<Option<(Vec<f64>, Value)>, E> {
    let half = (ONSET_PROBES / 2) as f64;
    let offsets: Vec<f64> = (0..ONSET_PROBES).map(|j| (j as f64 - half) * ONSET_SPACING).collect();
    let mut seen = probe(start, ridge, s, centre, &offsets, eval)?;
    let Some(k) = argmin(&seen) else { return Ok(None) };
    let edge = seen[k].0[ridge.onset] - centre;
    if edge.abs() >= half * ONSET_SPACING - 1e-12 {
        let beyond: Vec<f64> = (1..=ONSET_PROBES / 2)
            .map(|j| edge + edge.signum() * j as f64 * ONSET_SPACING)
            .collect();
        seen.extend(probe(start, ridge, s, centre, &beyond, eval)?);
    }
    seen.sort_by(|a, b| a.0[ridge.onset].total_cmp(&b.0[ridge.onset]));
    if let Some(x) = argmin(&seen).and_then(|k| vertex(&seen, k, ridge.onset)) {
        seen.extend(probe(start, ridge, s, x, &[0.0], eval)?);
    }
    Ok(argmin(&seen).map(|k| seen.swap_remove(k)))
}

/// The onset at the vertex of the parabola through probe `k` and its
/// neighbours (`seen` sorted by onset), when it is a minimum within one
/// spacing of probe `k` and not already probed.
fn vertex(seen: &[(Vec<f64>, Value)], k: usize, onset: usize) -> Option<f64> {
    let (lo, mid, hi) = (seen.get(k.checked_sub(1)?)?, &seen[k], seen.get(k + 1)?);
    let f = [lo.1.fit, mid.1.fit, hi.1.fit];
    let x = quadratic_vertex([lo.0[onset], mid.0[onset], hi.0[onset]], f)?;
    let near = (x - mid.0[onset]).abs() <= ONSET_SPACING;
    let new = seen.iter().all(|p| (p.0[onset] - x).abs() > 1e-4 * ONSET_SPACING);
    (near && new).then_some(x)
}

/// Abscissa of the minimum of the parabola through three points (None
/// when they do not bound a minimum or are not finite).
pub fn quadratic_vertex(x: [f64; 3], f: [f64; 3]) -> Option<f64> {
    let (d1, d2) = (x[1] - x[0], x[2] - x[1]);
    let (s1, s2) = ((f[1] - f[0]) / d1, (f[2] - f[1]) / d2);
    let curvature = (s2 - s1) / (x[2] - x[0]);
    let v = 0.5 * (x[0] + x[1]) - s1 / (2.0 * curvature);
    (curvature > 0.0 && v.is_finite()).then_some(v)
}

/// Points at shape `s` and onset `centre + offset` (clamped to the cube,
/// without repeats) with their values.
fn probe<E>(
    start: &[f64],
    ridge: Ridge,
    s: f64,
    centre: f64,
    offsets: &[f64],
    eval: &mut Evaluate<'_, E>,
) -> Result<Vec<(Vec<f64>, Value)>, E> {
    let mut us: Vec<Vec<f64>> = Vec::new();
    for o in offsets {
        let mut u = start.to_vec();
        u[ridge.shape] = s;
        u[ridge.onset] = (centre + o).clamp(0.0, 1.0);
        if !us.contains(&u) {
            us.push(u);
        }
    }
    if us.is_empty() {
        return Ok(Vec::new());
    }
    let f = eval(&us)?;
    Ok(us.into_iter().zip(f).collect())
}

/// Index of the lowest finite −log L.
fn argmin(seen: &[(Vec<f64>, Value)]) -> Option<usize> {
    (0..seen.len())
        .filter(|k| seen[*k].1.fit.is_finite())
        .min_by(|a, b| seen[*a].1.fit.total_cmp(&seen[*b].1.fit))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::convert::Infallible;

    /// A needle ridge 0.01 wide along the curve onset = c + a (shape −
    /// s0)², deepest at shape `peak`, over a third baseline dimension.
    fn needle(c: f64, a: f64, peak: f64) -> impl Fn(&[f64]) -> f64 {
        move |u: &[f64]| {
            let ridge = c + a * (u[1] - 0.5).powi(2);
            let across = ((u[0] - ridge) / 0.01).powi(2);
            -1000.0 * (-across).exp() * (1.0 - 4.0 * (u[1] - peak).powi(2))
                + 0.1 * (u[2] - 0.5).powi(2)
        }
    }

    /// A walk on `f` whose envelopes follow `f` too.
    fn walk(f: &dyn Fn(&[f64]) -> f64, start: &[f64]) -> (Vec<f64>, f64, usize) {
        walk_with_trend(f, f, start)
    }

    fn walk_with_trend(
        f: &dyn Fn(&[f64]) -> f64,
        trend: &dyn Fn(&[f64]) -> f64,
        start: &[f64],
    ) -> (Vec<f64>, f64, usize) {
        let mut n = 0;
        let value = |u: &[f64]| Value { fit: f(u), trend: trend(u) };
        let mut eval = |us: &[Vec<f64>]| -> Result<Vec<Value>, Infallible> {
            n += us.len();
            Ok(us.iter().map(|u| value(u)).collect())
        };
        let ridge = Ridge { onset: 0, shape: 1 };
        let (u, v) = walk_ridge(start, value(start), ridge, &mut eval).unwrap();
        (u, v.fit, n)
    }

    #[test]
    fn a_walk_follows_a_curved_needle_to_its_deepest_point() {
        let f = needle(0.6, 0.4, 0.75);
        // On the ridge at shape 1.0, far from the deepest point.
        let start = [0.6 + 0.4 * 0.25, 1.0, 0.5];
        let (u, v, n) = walk(&f, &start);
        assert!((u[1] - 0.76).abs() < 1e-9, "{u:?}");
        let ridge = 0.6 + 0.4 * (u[1] - 0.5f64).powi(2);
        assert!((u[0] - ridge).abs() <= 1e-3, "{u:?}");
        assert!(v < f(&start) - 200.0, "{v} vs {}", f(&start));
        assert_eq!(u[2], 0.5);
        assert!(n <= max_runs(), "{n}");
    }

    #[test]
    fn a_straight_probe_off_the_ridge_is_what_the_walk_avoids() {
        // The same needle probed along the start's tangent misses it: the
        // walk's gain is not that of any straight step.
        let f = needle(0.6, 0.4, 0.75);
        let start = [0.7, 1.0, 0.5];
        let tangent = 0.8; // d onset / d shape at shape 1.0
        let straight = [0.7 - 0.24 * tangent, 0.76, 0.5];
        assert!(f(&straight) > f(&start) - 1.0);
        assert!(walk(&f, &start).1 < f(&start) - 200.0);
    }

    #[test]
    fn a_start_at_the_deepest_point_stays_there_after_the_patience_each_way() {
        let f = needle(0.6, 0.0, 0.5);
        let start = [0.6, 0.5, 0.5];
        let (u, v, n) = walk(&f, &start);
        assert_eq!(u, start.to_vec());
        assert_eq!(v, f(&start));
        let per_step = ONSET_PROBES + ONSET_PROBES / 2 + 1;
        assert!(n <= 2 * (RIDGE_PATIENCE + 1) * per_step, "{n}");
    }

    #[test]
    fn a_walk_goes_on_past_one_worse_ridge_point() {
        // A straight needle whose depth dips once on the way to its deepest point.
        let f = |u: &[f64]| {
            let depth = match u[1] {
                s if s > 0.8 => 100.0,
                s if s > 0.7 => 90.0,
                _ => 200.0,
            };
            -depth * (-((u[0] - 0.5) / 0.01).powi(2)).exp()
        };
        let (u, v, _) = walk(&f, &[0.5, 0.85, 0.5]);
        assert!(u[1] < 0.7 && v < -150.0, "{u:?} {v}");
    }

    #[test]
    fn a_walk_goes_on_through_a_bumpy_profile_while_the_envelopes_improve() {
        // Depth dips three times in a row on the way to the deepest point
        // at shape 0.5; the envelopes fall steadily towards it.
        let f = |u: &[f64]| {
            let depth = match u[1] {
                s if s > 0.82 => 100.0,
                s if s > 0.55 => 90.0 - 10.0 * (0.82 - s),
                s if s > 0.45 => 200.0,
                _ => 50.0,
            };
            -depth * (-((u[0] - 0.5) / 0.01).powi(2)).exp()
        };
        let trend = |u: &[f64]| (u[1] - 0.5).powi(2) + (u[0] - 0.5).powi(2);
        let (u, v, _) = walk_with_trend(&f, &trend, &[0.5, 0.85, 0.5]);
        assert!(u[1] < 0.56 && v < -150.0, "{u:?} {v}");
        // Without the envelopes' trend the dips end the walk.
        let (u, v, _) = walk(&f, &[0.5, 0.85, 0.5]);
        assert!(u[1] > 0.8 && v > -150.0, "{u:?} {v}");
    }

    #[test]
    fn failed_points_end_the_direction() {
        let inf = Value { fit: f64::INFINITY, trend: f64::INFINITY };
        let mut eval =
            |us: &[Vec<f64>]| -> Result<Vec<Value>, Infallible> { Ok(vec![inf; us.len()]) };
        let ridge = Ridge { onset: 0, shape: 1 };
        let start = Value { fit: -1.0, trend: -1.0 };
        let (u, v) = walk_ridge(&[0.5, 0.5], start, ridge, &mut eval).unwrap();
        assert_eq!((u, v), (vec![0.5, 0.5], start));
    }

    #[test]
    fn the_vertex_of_a_parabola_is_its_minimum() {
        let f = |x: f64| 3.0 * (x - 0.37).powi(2) - 1.0;
        let x = [0.3, 0.35, 0.42];
        let v = quadratic_vertex(x, x.map(f)).unwrap();
        assert!((v - 0.37).abs() < 1e-12, "{v}");
        assert!(quadratic_vertex(x, x.map(|x| -f(x))).is_none());
        assert!(quadratic_vertex(x, [0.0, f64::NAN, 1.0]).is_none());
    }

    proptest! {
        /// Never worse than the start, inside the cube, within the
        /// budget, and only the onset and shape move.
        #[test]
        fn a_walk_never_loses(c in 0.2f64..0.8, a in -0.5f64..0.5, peak in 0.0f64..1.0,
                              s0 in 0.0f64..1.0, off in -0.05f64..0.05) {
            let f = needle(c, a, peak);
            let start = [(c + a * (s0 - 0.5).powi(2) + off).clamp(0.0, 1.0), s0, 0.3];
            let (u, v, n) = walk(&f, &start);
            prop_assert!(v <= f(&start));
            prop_assert!((v - f(&u)).abs() < 1e-12);
            prop_assert!(u.iter().all(|x| (0.0..=1.0).contains(x)));
            prop_assert_eq!(u[2], 0.3);
            prop_assert!(n <= max_runs());
        }
    }
}
