//! Known answers for the symptom kernels: a single-degree-of-freedom
//! oscillator on a shaking platform, linear or with a stop (a gap).

use rand::{Rng, SeedableRng};

/// Seeded white noise, uniform in [-amp, amp].
pub fn white_noise(n: usize, amp: f64, seed: u64) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.random_range(-amp..amp)).collect()
}

/// Response of an oscillator (`f_hz`, `zeta`) to base acceleration `ag`:
/// (absolute acceleration, displacement relative to the base). With
/// `gap = Some((g, k_ratio))` a stop of stiffness `k_ratio` times the
/// oscillator's acts beyond |u| = g. Newmark average acceleration with
/// 20 substeps and a fixed point on the stop force.
pub fn sdof(
    ag: &[f64],
    dt: f64,
    f_hz: f64,
    zeta: f64,
    gap: Option<(f64, f64)>,
) -> (Vec<f64>, Vec<f64>) {
    let w = 2.0 * std::f64::consts::PI * f_hz;
    let (k, c) = (w * w, 2.0 * zeta * w);
    let stop = |u: f64| match gap {
        Some((g, r)) if u.abs() > g => r * k * (u - g * u.signum()),
        _ => 0.0,
    };
    let sub = 20;
    let h = dt / sub as f64;
    let (mut u, mut v) = (0.0f64, 0.0f64);
    let mut a = -ag[0];
    let (mut acc, mut disp) = (vec![0.0; ag.len()], vec![0.0; ag.len()]);
    for i in 1..ag.len() {
        for s in 1..=sub {
            let g = ag[i - 1] + (ag[i] - ag[i - 1]) * s as f64 / sub as f64;
            // Solve for u1 with the stop force lagged one fixed-point pass at a time.
            let mut u1 = u + h * v;
            for _ in 0..8 {
                let rhs =
                    -g - stop(u1) + u * 4.0 / (h * h) + v * 4.0 / h + a + c * (2.0 * u / h + v);
                u1 = rhs / (k + 2.0 * c / h + 4.0 / (h * h));
            }
            let v1 = 2.0 * (u1 - u) / h - v;
            let a1 = 4.0 * (u1 - u) / (h * h) - 4.0 * v / h - a;
            (u, v, a) = (u1, v1, a1);
        }
        acc[i] = a + ag[i];
        disp[i] = u;
    }
    (acc, disp)
}
