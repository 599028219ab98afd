//! Analytic test functions of sensitivity analysis with known indices:
//! Ishigami (a = 7, b = 0.1, inputs U(−π, π)), Sobol' G
//! (a = 0, 1, 4.5, 9, 99, 99, 99, 99 on U(0, 1)) and the borehole flow
//! rate (m³/yr; Harper and Gupta 1983, bounds of the benchmark README).

use super::problem::Problem;
use std::f64::consts::PI;

/// Coefficients a of the Sobol' G function used in the benchmarks.
pub const G_COEFFS: [f64; 8] = [0.0, 1.0, 4.5, 9.0, 99.0, 99.0, 99.0, 99.0];

/// Ishigami f = sin x1 + 7 sin² x2 + 0.1 x3⁴ sin x1.
pub fn ishigami(x: &[f64]) -> f64 {
    x[0].sin() + 7.0 * x[1].sin().powi(2) + 0.1 * x[2].powi(4) * x[0].sin()
}

/// Sobol' G = Π (|4x_i − 2| + a_i) / (1 + a_i), a = [`G_COEFFS`].
pub fn sobol_g(x: &[f64]) -> f64 {
    x.iter().zip(G_COEFFS).map(|(v, a)| ((4.0 * v - 2.0).abs() + a) / (1.0 + a)).product()
}

/// Borehole flow, inputs (rw, r, Tu, Hu, Tl, Hl, L, Kw).
pub fn borehole(x: &[f64]) -> f64 {
    let (rw, r, tu, hu, tl, hl, l, kw) = (x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
    let lr = (r / rw).ln();
    2.0 * PI * tu * (hu - hl) / (lr * (1.0 + 2.0 * l * tu / (lr * rw * rw * kw) + tu / tl))
}

/// The problem (names and bounds) of a named test function.
pub fn problem(name: &str) -> Option<Problem> {
    let named = |names: &[&str], bounds: Vec<(f64, f64)>| Problem {
        names: names.iter().map(|s| s.to_string()).collect(),
        bounds,
    };
    match name {
        "ishigami" => Some(named(&["x1", "x2", "x3"], vec![(-PI, PI); 3])),
        "sobol-g" => {
            Some(named(&["x1", "x2", "x3", "x4", "x5", "x6", "x7", "x8"], vec![(0.0, 1.0); 8]))
        }
        "borehole" => Some(named(
            &["rw", "r", "Tu", "Hu", "Tl", "Hl", "L", "Kw"],
            vec![
                (0.05, 0.15),
                (100.0, 50000.0),
                (63070.0, 115600.0),
                (990.0, 1110.0),
                (63.1, 116.0),
                (700.0, 820.0),
                (1120.0, 1680.0),
                (9855.0, 12045.0),
            ],
        )),
        _ => None,
    }
}

/// The function of a named test problem.
pub fn function(name: &str) -> Option<fn(&[f64]) -> f64> {
    match name {
        "ishigami" => Some(ishigami),
        "sobol-g" => Some(sobol_g),
        "borehole" => Some(borehole),
        _ => None,
    }
}
