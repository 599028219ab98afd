//! Shared pieces of the calibration benchmark tests (shared benchmarks §3):
//! the oscillator simulator, its data files, and exact posterior moments by
//! quadrature on a grid.
#![allow(dead_code)]

use stats::calibration::{
    FnSimulator, GaussianLikelihood, Hyper, KohLikelihood, KohSettings, Likelihood, Posterior,
    Simulator, UniformBox,
};

/// eta(x; k, c, m) = 1 / sqrt((k − m w²)² + (c w)²), w = 0.5 + 1.5 x.
pub fn eta(x: f64, k: f64, c: f64, m: f64) -> f64 {
    let w = 0.5 + 1.5 * x;
    1.0 / ((k - m * w * w).powi(2) + (c * w).powi(2)).sqrt()
}

/// `shared/benchmarks`: under `CEILFARM_SHARED` if set, else the first
/// `shared/benchmarks` found above this crate.
pub fn benchmarks_dir() -> std::path::PathBuf {
    if let Ok(dir) = std::env::var("CEILFARM_SHARED") {
        return std::path::PathBuf::from(dir).join("benchmarks");
    }
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|a| a.join("shared").join("benchmarks"))
        .find(|p| p.join("README.md").is_file())
        .expect("shared/benchmarks not found above the crate; set CEILFARM_SHARED")
}

/// (x, y) columns of a benchmark CSV.
pub fn read_xy(file: &str) -> (Vec<f64>, Vec<f64>) {
    let path = benchmarks_dir().join(file);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (mut x, mut y) = (vec![], vec![]);
    for line in text.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|s| s.trim().parse().unwrap()).collect();
        x.push(f[0]);
        y.push(f[1]);
    }
    (x, y)
}

/// The oscillator at the points `x` as a calibration simulator.
pub fn simulator(x: Vec<f64>) -> impl Simulator {
    let n = x.len();
    FnSimulator::new(3, n, move |t: &[f64]| {
        Ok(x.iter().map(|&x| eta(x, t[0], t[1], t[2])).collect())
    })
}

/// Priors k U(0.5, 2.5), c U(0.1, 0.7), m U(0.5, 1.5).
pub fn prior() -> UniformBox {
    UniformBox::new(
        vec!["k".into(), "c".into(), "m".into()],
        vec![0.5, 0.1, 0.5],
        vec![2.5, 0.7, 1.5],
    )
    .unwrap()
}

/// Posterior with known noise sd 0.1 and no discrepancy.
pub fn plain_posterior(file: &str) -> Posterior<impl Likelihood> {
    let (x, y) = read_xy(file);
    let lik = GaussianLikelihood::new(simulator(x), y, Hyper::Fixed(0.1)).unwrap();
    Posterior::new(prior(), lik).unwrap()
}

/// KOH posterior with fixed discrepancy s = 0.1, l = 0.3 and noise sd 0.1.
pub fn koh_posterior(file: &str) -> Posterior<impl Likelihood> {
    let (x, y) = read_xy(file);
    let pts = x.iter().map(|&v| vec![v]).collect();
    let settings = KohSettings {
        alpha: Hyper::Fixed(1.0),
        noise_sd: Hyper::Fixed(0.1),
        disc_sd: Hyper::Fixed(0.1),
        disc_length: Hyper::Fixed(0.3),
    };
    Posterior::new(prior(), KohLikelihood::new(simulator(x), pts, y, settings).unwrap()).unwrap()
}

/// Exact posterior moments in physical units: mean (3), sd (3), correlation (3x3).
pub struct Exact {
    pub mean: [f64; 3],
    pub sd: [f64; 3],
    pub corr: [[f64; 3]; 3],
}

/// Moments of p(theta | y) ∝ L(theta) (uniform prior) by the midpoint rule on
/// an n³ grid over centre ± half_width (inside the prior box).
pub fn quadrature<L: Likelihood>(
    lik: &L,
    centre: [f64; 3],
    half_width: [f64; 3],
    n: usize,
) -> Exact {
    let mut pts = Vec::with_capacity(n * n * n);
    let axis = |j: usize, i: usize| {
        centre[j] - half_width[j] + (i as f64 + 0.5) * 2.0 * half_width[j] / n as f64
    };
    for a in 0..n {
        for b in 0..n {
            for c in 0..n {
                let t = [axis(0, a), axis(1, b), axis(2, c)];
                pts.push((t, lik.log_likelihood(&t).unwrap()));
            }
        }
    }
    let lmax = pts.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = pts.iter().map(|p| (p.1 - lmax).exp()).collect();
    let z: f64 = w.iter().sum();
    let mut mean = [0.0; 3];
    for (p, w) in pts.iter().zip(&w) {
        (0..3).for_each(|j| mean[j] += w * p.0[j] / z);
    }
    let mut cov = [[0.0; 3]; 3];
    for (p, w) in pts.iter().zip(&w) {
        for a in 0..3 {
            for b in 0..3 {
                cov[a][b] += w * (p.0[a] - mean[a]) * (p.0[b] - mean[b]) / z;
            }
        }
    }
    let sd = [cov[0][0].sqrt(), cov[1][1].sqrt(), cov[2][2].sqrt()];
    let mut corr = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            corr[a][b] = cov[a][b] / (sd[a] * sd[b]);
        }
    }
    Exact { mean, sd, corr }
}
