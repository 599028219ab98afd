//! A small box-constrained L-BFGS: the two-loop recursion (Nocedal and
//! Wright, *Numerical Optimization*, 2006, alg. 7.4) on the free variables,
//! a strong-Wolfe line search along the direction up to the nearest bound
//! ([`super::line_search`]), and the L-BFGS-B stopping rules (projected
//! gradient, relative decrease). argmin's L-BFGS has no
//! bounds; the GP hyperparameters need them (length scales must neither
//! collapse nor run to infinity), hence this projection variant.

use super::line_search::{strong_wolfe, Trial};

/// Settings of the bounded L-BFGS.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LbfgsSettings {
    /// Number of stored correction pairs.
    pub memory: usize,
    /// Maximum iterations.
    pub max_iter: usize,
    /// Stop when the projected gradient's max-norm falls below this.
    pub gtol: f64,
    /// Stop when the relative decrease of f falls below this.
    pub ftol: f64,
}

impl Default for LbfgsSettings {
    fn default() -> Self {
        LbfgsSettings { memory: 10, max_iter: 200, gtol: 1e-5, ftol: 1e-9 }
    }
}

/// Result of a minimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct LbfgsResult {
    /// Minimiser found.
    pub x: Vec<f64>,
    /// Objective there.
    pub f: f64,
    /// Iterations taken.
    pub iterations: usize,
    /// Objective evaluations.
    pub evaluations: usize,
    /// Where the run left off, for [`resume`].
    pub state: LbfgsState,
}

/// The optimiser's state at its last point: gradient and correction pairs
/// (s, y), so that a stopped run can go on without a cold restart.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LbfgsState {
    /// Gradient at the result's x.
    pub grad: Vec<f64>,
    /// Stored correction pairs, oldest first.
    pub memory: Vec<(Vec<f64>, Vec<f64>)>,
}

/// Evaluations one line search may spend.
pub const LINE_SEARCH_BUDGET: usize = 10;

/// `d` with the components that would leave the box at a bound set to 0.
fn inward(mut d: Vec<f64>, x: &[f64], lo: &[f64], hi: &[f64]) -> Vec<f64> {
    for k in 0..d.len() {
        if (x[k] <= lo[k] && d[k] < 0.0) || (x[k] >= hi[k] && d[k] > 0.0) {
            d[k] = 0.0;
        }
    }
    d
}

/// Largest t keeping x + t d inside the box (∞ when d is 0).
fn max_step(x: &[f64], d: &[f64], lo: &[f64], hi: &[f64]) -> f64 {
    (0..d.len())
        .map(|k| match d[k] {
            v if v > 0.0 => (hi[k] - x[k]) / v,
            v if v < 0.0 => (lo[k] - x[k]) / v,
            _ => f64::INFINITY,
        })
        .fold(f64::INFINITY, f64::min)
}

fn project(x: &mut [f64], lo: &[f64], hi: &[f64]) {
    for ((v, l), h) in x.iter_mut().zip(lo).zip(hi) {
        *v = v.clamp(*l, *h);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p * q).sum()
}

/// Variables held at a bound by a gradient pointing outwards.
fn active(x: &[f64], g: &[f64], lo: &[f64], hi: &[f64]) -> Vec<bool> {
    (0..x.len()).map(|k| (x[k] <= lo[k] && g[k] > 0.0) || (x[k] >= hi[k] && g[k] < 0.0)).collect()
}

/// Two-loop recursion d = −H g restricted to free variables.
fn direction(g: &[f64], mem: &[(Vec<f64>, Vec<f64>)], fixed: &[bool]) -> Vec<f64> {
    let mut q: Vec<f64> = g.iter().zip(fixed).map(|(v, f)| if *f { 0.0 } else { *v }).collect();
    let mut a = vec![0.0; mem.len()];
    for (i, (s, y)) in mem.iter().enumerate().rev() {
        a[i] = dot(s, &q) / dot(s, y);
        for (qk, yk) in q.iter_mut().zip(y) {
            *qk -= a[i] * yk;
        }
    }
    if let Some((s, y)) = mem.last() {
        let gamma = dot(s, y) / dot(y, y);
        q.iter_mut().for_each(|v| *v *= gamma);
    }
    for (i, (s, y)) in mem.iter().enumerate() {
        let b = dot(y, &q) / dot(s, y);
        for (qk, sk) in q.iter_mut().zip(s) {
            *qk += (a[i] - b) * sk;
        }
    }
    q.iter().zip(fixed).map(|(v, f)| if *f { 0.0 } else { -v }).collect()
}

/// Minimise `f` (returning value and gradient, or None where undefined)
/// over the box [lo, hi] from `x0`. None if f is undefined at the start.
pub fn minimise<F>(
    mut f: F,
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    set: &LbfgsSettings,
) -> Option<LbfgsResult>
where
    F: FnMut(&[f64]) -> Option<(f64, Vec<f64>)>,
{
    let mut x = x0.to_vec();
    project(&mut x, lo, hi);
    let (fx, grad) = f(&x)?;
    let start = LbfgsResult {
        x,
        f: fx,
        iterations: 0,
        evaluations: 1,
        state: LbfgsState { grad, memory: Vec::new() },
    };
    Some(iterate(f, start, lo, hi, set))
}

/// Go on from a previous result (its point, gradient and correction
/// pairs) under new settings; iterations and evaluations add up.
pub fn resume<F>(
    f: F,
    from: LbfgsResult,
    lo: &[f64],
    hi: &[f64],
    set: &LbfgsSettings,
) -> LbfgsResult
where
    F: FnMut(&[f64]) -> Option<(f64, Vec<f64>)>,
{
    let done = from.iterations;
    let mut r = iterate(f, LbfgsResult { iterations: 0, ..from }, lo, hi, set);
    r.iterations += done;
    r
}

/// L-BFGS iterations from `r` until a stopping rule or `set.max_iter`.
fn iterate<F>(mut f: F, r: LbfgsResult, lo: &[f64], hi: &[f64], set: &LbfgsSettings) -> LbfgsResult
where
    F: FnMut(&[f64]) -> Option<(f64, Vec<f64>)>,
{
    let LbfgsResult { mut x, f: mut fx, mut evaluations, state, .. } = r;
    let LbfgsState { grad: mut g, memory: mut mem } = state;
    let mut iterations = 0;
    while iterations < set.max_iter {
        iterations += 1;
        let mut pg = x.clone();
        pg.iter_mut().zip(&g).for_each(|(v, gk)| *v -= gk);
        project(&mut pg, lo, hi);
        let pg_norm = pg.iter().zip(&x).map(|(p, v)| (p - v).abs()).fold(0.0, f64::max);
        if pg_norm < set.gtol {
            break;
        }
        let fixed = active(&x, &g, lo, hi);
        let mut d = inward(direction(&g, &mem, &fixed), &x, lo, hi);
        if dot(&d, &g) >= 0.0 {
            mem.clear();
            d = inward(direction(&g, &mem, &fixed), &x, lo, hi);
        }
        let slope0 = dot(&d, &g);
        let t_max = max_step(&x, &d, lo, hi);
        if slope0 >= 0.0 || t_max <= 0.0 {
            break;
        }
        let t0 = if mem.is_empty() {
            (1.0 / d.iter().map(|v| v.abs()).fold(0.0, f64::max)).min(1.0)
        } else {
            1.0
        };
        let phi = |t: f64| {
            let mut xn: Vec<f64> = x.iter().zip(&d).map(|(v, dk)| v + t * dk).collect();
            project(&mut xn, lo, hi);
            f(&xn).map(|(fv, gv)| (fv, dot(&gv, &d), (xn, gv)))
        };
        let (found, spent) = strong_wolfe(phi, (fx, slope0), t0, t_max, LINE_SEARCH_BUDGET);
        evaluations += spent;
        let Some(Trial { f: fnew, data: Some((xn, gnew)), .. }) = found else {
            break;
        };
        let s: Vec<f64> = xn.iter().zip(&x).map(|(a, b)| a - b).collect();
        let yv: Vec<f64> = gnew.iter().zip(&g).map(|(a, b)| a - b).collect();
        if dot(&s, &yv) > 1e-10 * dot(&yv, &yv).max(1e-300) {
            mem.push((s, yv));
            if mem.len() > set.memory {
                mem.remove(0);
            }
        }
        let decrease = (fx - fnew) / fx.abs().max(fnew.abs()).max(1.0);
        x = xn;
        fx = fnew;
        g = gnew;
        if decrease < set.ftol {
            break;
        }
    }
    LbfgsResult { x, f: fx, iterations, evaluations, state: LbfgsState { grad: g, memory: mem } }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rosenbrock(x: &[f64]) -> Option<(f64, Vec<f64>)> {
        let (a, b) = (x[0], x[1]);
        let f = (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2);
        let g = vec![-2.0 * (1.0 - a) - 400.0 * a * (b - a * a), 200.0 * (b - a * a)];
        Some((f, g))
    }

    #[test]
    fn finds_rosenbrock_minimum_inside_box() {
        let set = LbfgsSettings { max_iter: 500, ftol: 1e-14, gtol: 1e-8, ..Default::default() };
        let r = minimise(rosenbrock, &[-1.2, 1.0], &[-2.0, -2.0], &[2.0, 2.0], &set).unwrap();
        assert!((r.x[0] - 1.0).abs() < 1e-4 && (r.x[1] - 1.0).abs() < 1e-4, "{r:?}");
    }

    #[test]
    fn resumed_run_follows_the_uninterrupted_one() {
        let (lo, hi) = ([-2.0, -2.0], [2.0, 2.0]);
        let set =
            |max_iter| LbfgsSettings { max_iter, ftol: 1e-14, gtol: 1e-8, ..Default::default() };
        let whole = minimise(rosenbrock, &[-1.2, 1.0], &lo, &hi, &set(40)).unwrap();
        let first = minimise(rosenbrock, &[-1.2, 1.0], &lo, &hi, &set(12)).unwrap();
        assert_eq!(first.iterations, 12, "the first leg must stop on its limit");
        let second = resume(rosenbrock, first, &lo, &hi, &set(28));
        assert_eq!((second.x, second.f), (whole.x, whole.f));
        assert_eq!((second.iterations, second.evaluations), (whole.iterations, whole.evaluations));
    }

    #[test]
    fn stops_on_active_bound() {
        // Minimum of (x - 3)² on [0, 1] is at the bound x = 1.
        let f = |x: &[f64]| Some(((x[0] - 3.0).powi(2), vec![2.0 * (x[0] - 3.0)]));
        let r = minimise(f, &[0.2], &[0.0], &[1.0], &LbfgsSettings::default()).unwrap();
        assert_eq!(r.x[0], 1.0);
    }
}
