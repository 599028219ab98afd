//! A line search for the strong Wolfe conditions on φ(t) = f(x + t d),
//! t in (0, t_max]: bracketing then zoom with safeguarded cubic
//! interpolation (Nocedal and Wright, *Numerical Optimization*, 2006,
//! alg. 3.5 and 3.6, eq. 3.59). Every evaluation returns the value and the
//! slope φ'(t) together, as the GP likelihood does.

/// Sufficient decrease constant c₁.
pub const C1: f64 = 1e-4;
/// Curvature constant c₂ (0.9: the usual choice for quasi-Newton methods).
pub const C2: f64 = 0.9;

/// One evaluated step: t, φ(t), φ'(t) and what the evaluation produced.
#[derive(Debug, Clone)]
pub struct Trial<T> {
    /// Step length.
    pub t: f64,
    /// φ(t).
    pub f: f64,
    /// φ'(t).
    pub slope: f64,
    /// The evaluation's payload (None only for the start, t = 0).
    pub data: Option<T>,
}

/// Outcome of a search: the accepted trial (strong Wolfe, or the best
/// sufficient-decrease point when the budget ran out or the step reached
/// t_max) and the evaluations spent; None when no trial decreased φ enough.
pub type Search<T> = (Option<Trial<T>>, usize);

/// Searches φ from φ(0) = `f0`, φ'(0) = `slope0` < 0, first trying
/// `t_init`, never beyond `t_max`, with at most `budget` evaluations.
/// `phi` returns None where φ is undefined (treated as too long a step).
pub fn strong_wolfe<T, P>(
    phi: P,
    (f0, slope0): (f64, f64),
    t_init: f64,
    t_max: f64,
    budget: usize,
) -> Search<T>
where
    P: FnMut(f64) -> Option<(f64, f64, T)>,
{
    let mut s = Searcher { phi, f0, slope0, spent: 0, budget };
    let found = s.bracket(t_init.min(t_max), t_max);
    (found, s.spent)
}

/// The state of one search.
struct Searcher<P> {
    phi: P,
    f0: f64,
    slope0: f64,
    spent: usize,
    budget: usize,
}

impl<P> Searcher<P> {
    fn eval<T>(&mut self, t: f64) -> Trial<T>
    where
        P: FnMut(f64) -> Option<(f64, f64, T)>,
    {
        self.spent += 1;
        match (self.phi)(t) {
            Some((f, slope, data)) if f.is_finite() && slope.is_finite() => {
                Trial { t, f, slope, data: Some(data) }
            }
            _ => Trial { t, f: f64::INFINITY, slope: f64::NAN, data: None },
        }
    }

    fn sufficient<T>(&self, tr: &Trial<T>) -> bool {
        tr.f <= self.f0 + C1 * tr.t * self.slope0
    }

    fn curvature<T>(&self, tr: &Trial<T>) -> bool {
        tr.slope.abs() <= -C2 * self.slope0
    }

    /// Alg. 3.5: grow t until a trial brackets a Wolfe point or satisfies it.
    fn bracket<T>(&mut self, mut t: f64, t_max: f64) -> Option<Trial<T>>
    where
        P: FnMut(f64) -> Option<(f64, f64, T)>,
    {
        let mut lo = Trial { t: 0.0, f: self.f0, slope: self.slope0, data: None };
        while self.spent < self.budget {
            let tr = self.eval(t);
            if !self.sufficient(&tr) || (lo.t > 0.0 && tr.f >= lo.f) {
                return self.zoom(lo, tr);
            }
            if self.curvature(&tr) || t >= t_max {
                return Some(tr);
            }
            if tr.slope >= 0.0 {
                return self.zoom(tr, lo);
            }
            t = (2.0 * t).min(t_max);
            lo = tr;
        }
        lo.data.is_some().then_some(lo)
    }

    /// Alg. 3.6: shrink [lo, hi] (lo: the best sufficient-decrease trial)
    /// around a Wolfe point by safeguarded cubic interpolation.
    fn zoom<T>(&mut self, mut lo: Trial<T>, mut hi: Trial<T>) -> Option<Trial<T>>
    where
        P: FnMut(f64) -> Option<(f64, f64, T)>,
    {
        while self.spent < self.budget && (hi.t - lo.t).abs() > 1e-12 * lo.t.abs().max(1e-300) {
            let tr = self.eval(interpolate(&lo, &hi));
            if !self.sufficient(&tr) || tr.f >= lo.f {
                hi = tr;
                continue;
            }
            if self.curvature(&tr) {
                return Some(tr);
            }
            if tr.slope * (hi.t - lo.t) >= 0.0 {
                hi = lo;
            }
            lo = tr;
        }
        lo.data.is_some().then_some(lo)
    }
}

/// Minimiser of the cubic through two trials' values and slopes (eq. 3.59),
/// kept at least a tenth of the interval from either end; the midpoint
/// when the cubic is undefined (a failed evaluation, no real minimiser).
pub fn interpolate<T>(a: &Trial<T>, b: &Trial<T>) -> f64 {
    let (lo, hi) = (a.t.min(b.t), a.t.max(b.t));
    let w = hi - lo;
    let d1 = a.slope + b.slope - 3.0 * (a.f - b.f) / (a.t - b.t);
    let disc = d1 * d1 - a.slope * b.slope;
    let t = if disc >= 0.0 && b.f.is_finite() {
        let d2 = (b.t - a.t).signum() * disc.sqrt();
        b.t - (b.t - a.t) * (b.slope + d2 - d1) / (b.slope - a.slope + 2.0 * d2)
    } else {
        f64::NAN
    };
    if t.is_finite() {
        t.clamp(lo + 0.1 * w, hi - 0.1 * w)
    } else {
        0.5 * (lo + hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn quadratic(c: f64) -> impl FnMut(f64) -> Option<(f64, f64, ())> {
        move |t| Some(((t - c).powi(2), 2.0 * (t - c), ()))
    }

    #[test]
    fn cubic_interpolation_is_exact_on_a_cubic() {
        // φ(t) = t³ − 3t: minimiser t = 1 inside [0, 3].
        let p = |t: f64| Trial::<()> {
            t,
            f: t * t * t - 3.0 * t,
            slope: 3.0 * t * t - 3.0,
            data: None,
        };
        assert!((interpolate(&p(0.0), &p(3.0)) - 1.0).abs() < 1e-12);
        assert!((interpolate(&p(3.0), &p(0.0)) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn stops_at_t_max_with_sufficient_decrease() {
        let (tr, spent) = strong_wolfe(quadratic(10.0), (100.0, -20.0), 1.0, 0.5, 20);
        let tr = tr.expect("accepted");
        assert_eq!((tr.t, spent), (0.5, 1));
    }

    #[test]
    fn undefined_region_is_treated_as_too_long_a_step() {
        let mut phi = quadratic(1.0);
        let guarded = move |t: f64| if t > 1.5 { None } else { phi(t) };
        let (tr, _) = strong_wolfe(guarded, (1.0, -2.0), 4.0, 10.0, 30);
        let tr = tr.expect("accepted");
        assert!(tr.t <= 1.5 && tr.f < 1.0, "{tr:?}");
    }

    proptest! {
        #[test]
        fn finds_a_strong_wolfe_point_on_quadratics(c in 0.01..50.0f64, t0 in 1e-3..10.0f64) {
            // φ(t) = (t − c)², φ(0) = c², φ'(0) = −2c.
            let (f0, s0) = (c * c, -2.0 * c);
            let (tr, spent) = strong_wolfe(quadratic(c), (f0, s0), t0, f64::INFINITY, 50);
            let tr = tr.expect("accepted");
            prop_assert!(tr.f <= f0 + C1 * tr.t * s0);
            prop_assert!(tr.slope.abs() <= -C2 * s0 + 1e-12, "{tr:?}");
            prop_assert!(spent <= 50);
        }
    }
}
