//! Nelder–Mead simplex minimisation (Nelder & Mead 1965; the adaptive
//! coefficients of Gao & Han 2012 for dimension n).
//!
//! Hand-written rather than argmin's `NelderMead`, measured side by side
//! (argmin 0.11, same start, same initial simplex, its `sd_tolerance` set to
//! our `f_tol`; `scripts/bench/nelder-mead/run` reprints the numbers).
//! On the real objectives of `ceilfarm select
//! configs/calibration/oscillator-select.toml` (seven candidates, 16 starts,
//! two passes each, as [`fit_ml`](super::ml::fit_ml) runs them) both find
//! the same minima: −log L within 3.2e-13, θ̂ within 4.2e-8, the same
//! winners under AIC, BIC, MDL and DIC, and `criteria.csv` (6 decimals)
//! unchanged; `criteria.json`, written in full precision, would change in
//! its last digits. argmin took 7–30 % fewer evaluations in two and three
//! dimensions (k-c-m: 5 171 against 7 341) and 43–55 % more in one (k:
//! 1 368 against 882). It refuses the adaptive coefficients of Gao & Han
//! for n = 1 (σ = 0) and n ≥ 3 (ρ > 0.5), and it stops on the standard
//! deviation of the simplex values alone, with no test of the simplex's
//! size: on 5-D Rosenbrock from (−1.2, 1, …) it stops 1.7e-7 from the
//! minimum (923 evaluations), this one 4.2e-9 (1 013); in 2-D 7.5e-9 (192)
//! against 3.2e-8 (196). It has no rule for NaN (here: +inf, so a failed
//! evaluation is never chosen). With results equal to the written
//! precision but not bit for bit, the workspace keeps this one and does
//! not declare argmin (31 crates in its tree with argmin-math).

/// Minimum found: point, value, iterations.
#[derive(Debug, Clone, PartialEq)]
pub struct Minimum {
    /// Best point.
    pub x: Vec<f64>,
    /// f at the best point.
    pub f: f64,
    /// Iterations used.
    pub iters: usize,
}

/// Adaptive coefficients (Gao & Han 2012) for dimension `n`: reflection,
/// expansion, contraction, shrink.
struct Coefficients {
    alpha: f64,
    gamma: f64,
    rho: f64,
    sigma: f64,
}

impl Coefficients {
    fn adaptive(n: usize) -> Self {
        let nf = n as f64;
        Coefficients {
            alpha: 1.0,
            gamma: 1.0 + 2.0 / nf,
            rho: 0.75 - 0.5 / nf,
            sigma: 1.0 - 1.0 / nf,
        }
    }
}

/// Minimises `f` from `x0` with initial simplex edge `step`, until the spread
/// of simplex values is below `f_tol` and its diameter below 1e-7, or `max_iters`.
/// With no coordinates, `x0` itself is the minimum.
pub fn nelder_mead(
    f: &dyn Fn(&[f64]) -> f64,
    x0: &[f64],
    step: f64,
    f_tol: f64,
    max_iters: usize,
) -> Minimum {
    let n = x0.len();
    let c = Coefficients::adaptive(n);
    let eval = |x: &[f64]| {
        let v = f(x);
        if v.is_nan() {
            f64::INFINITY
        } else {
            v
        }
    };
    let mut simplex: Vec<(Vec<f64>, f64)> = (0..=n)
        .map(|i| {
            let mut x = x0.to_vec();
            if i > 0 {
                x[i - 1] += step;
            }
            let v = eval(&x);
            (x, v)
        })
        .collect();
    let mut iters = 0;
    while n > 0 && iters < max_iters {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if converged(&simplex, f_tol) {
            break;
        }
        iters += 1;
        iterate(&mut simplex, &c, &eval);
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x, f) = simplex.swap_remove(0);
    Minimum { x, f, iters }
}

/// Whether a sorted simplex has a finite best value, a value spread within
/// `f_tol` and a diameter within 1e-7.
fn converged(simplex: &[(Vec<f64>, f64)], f_tol: f64) -> bool {
    let n = simplex.len() - 1;
    let diameter = simplex
        .iter()
        .flat_map(|p| p.0.iter().zip(&simplex[0].0).map(|(a, b)| (a - b).abs()))
        .fold(0.0, f64::max);
    (simplex[n].1 - simplex[0].1).abs() <= f_tol && diameter <= 1e-7 && simplex[0].1.is_finite()
}

/// One Nelder–Mead iteration on a sorted simplex: reflect the worst point,
/// expand, contract outside or inside, or shrink towards the best.
fn iterate(simplex: &mut [(Vec<f64>, f64)], c: &Coefficients, eval: &dyn Fn(&[f64]) -> f64) {
    let n = simplex.len() - 1;
    let nf = n as f64;
    let centroid: Vec<f64> =
        (0..n).map(|j| simplex[..n].iter().map(|p| p.0[j]).sum::<f64>() / nf).collect();
    let worst = &simplex[n].0;
    let along = |t: f64| -> (Vec<f64>, f64) {
        let x: Vec<f64> = (0..n).map(|j| centroid[j] + t * (worst[j] - centroid[j])).collect();
        let v = eval(&x);
        (x, v)
    };
    let (xr, fr) = along(-c.alpha);
    if fr < simplex[0].1 {
        let (xe, fe) = along(-c.alpha * c.gamma);
        simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
    } else if fr < simplex[n - 1].1 {
        simplex[n] = (xr, fr);
    } else {
        let (xc, fc) = if fr < simplex[n].1 { along(-c.alpha * c.rho) } else { along(c.rho) };
        if fc < simplex[n].1.min(fr) {
            simplex[n] = (xc, fc);
        } else {
            let best = simplex[0].0.clone();
            for p in simplex.iter_mut().skip(1) {
                p.0 = (0..n).map(|j| best[j] + c.sigma * (p.0[j] - best[j])).collect();
                p.1 = eval(&p.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rosenbrock_minimum() {
        let f = |x: &[f64]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
        let m = nelder_mead(&f, &[-1.2, 1.0], 0.5, 1e-14, 5000);
        assert!((m.x[0] - 1.0).abs() < 1e-4 && (m.x[1] - 1.0).abs() < 1e-4, "{m:?}");
    }

    #[test]
    fn quadratic_in_four_dimensions() {
        let f = |x: &[f64]| {
            x.iter().enumerate().map(|(i, v)| (i as f64 + 1.0) * (v - 0.5).powi(2)).sum::<f64>()
        };
        let m = nelder_mead(&f, &[0.0; 4], 1.0, 1e-16, 5000);
        assert!(m.x.iter().all(|v| (v - 0.5).abs() < 1e-5), "{m:?}");
    }

    #[test]
    fn no_coordinates_is_its_own_minimum() {
        let m = nelder_mead(&|_: &[f64]| 3.0, &[], 1.0, 1e-12, 100);
        assert_eq!(m, Minimum { x: vec![], f: 3.0, iters: 0 });
    }
}
