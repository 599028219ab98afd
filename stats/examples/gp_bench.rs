//! Fit a GP to a benchmark CSV and report fit time and test error.
//!
//! `gp_bench borehole FILE RESTARTS [KERNEL] [MEAN]`: test RMSE and NLPD on
//! 2000 fresh uniform points from the formula (seed 2026; a seventh
//! argument K adds K − 1 further test sets, seeds 2027, ...).
//! `gp_bench modal13 FILE RESTARTS [KERNEL] [MEAN]`: 5-fold CV RMSE and NLPD
//! of the noisy f1 column (the last column).
//! `gp_bench holdout FILE RESTARTS KERNEL MEAN NOISE_LO TEST`: RMSE and NLPD
//! on the rows of the CSV file TEST (same columns as FILE).
//! Prints one line: `case restarts wall_s cpu_s rmse nlpd lml ...`.
//! Optional sixth argument: lower bound of the noise variance.
//! Environment `GP_WARP=0` turns the input warping off.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use stats::gp::{fit, GpSettings, InputScaling, KernelKind, MeanKind};
use stats::sobol::functions;
use std::time::Instant;

fn read_csv(path: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).expect("read csv");
    let mut lines = text.lines();
    let head = lines.next().expect("header").split(',').map(|s| s.trim().to_string()).collect();
    let rows = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(|v| v.trim().parse().expect("number")).collect())
        .collect();
    (head, rows)
}

/// CPU seconds (user + system, all threads) of this process so far.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after.split_whitespace().map(|v| v.parse().unwrap_or(0.0)).collect();
    if f.len() > 12 {
        (f[11] + f[12]) / 100.0
    } else {
        f64::NAN
    }
}

fn metrics(mean: &[f64], sd: &[f64], y: &[f64]) -> (f64, f64) {
    let n = y.len() as f64;
    let rmse = (mean.iter().zip(y).map(|(m, t)| (m - t).powi(2)).sum::<f64>() / n).sqrt();
    let nlpd = mean
        .iter()
        .zip(sd)
        .zip(y)
        .map(|((m, s), t)| {
            0.5 * (2.0 * std::f64::consts::PI * s * s).ln() + 0.5 * ((t - m) / s).powi(2)
        })
        .sum::<f64>()
        / n;
    (rmse, nlpd)
}

const MODAL13_BOUNDS: [(f64, f64); 13] = [
    (30.0, 36.0),
    (1.9e5, 2.3e5),
    (7.4e4, 8.2e4),
    (4000.0, 4700.0),
    (650.0, 750.0),
    (0.5, 3.0),
    (15.0, 25.0),
    (750.0, 850.0),
    (75.0, 125.0),
    (10.0, 35.0),
    (35.0, 42.0),
    (7250.0, 7800.0),
    (1400.0, 1600.0),
];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args[1].as_str();
    let (_, rows) = read_csv(&args[2]);
    let restarts: usize = args[3].parse().expect("restarts");
    let kernel =
        args.get(4).and_then(|k| KernelKind::parse(k)).unwrap_or(KernelKind::SquaredExponential);
    let mean = args.get(5).and_then(|m| MeanKind::parse(m)).unwrap_or(MeanKind::Constant);
    let noise_lo: f64 = args.get(6).map(|v| v.parse().expect("noise floor")).unwrap_or(1e-10);
    let warp = std::env::var("GP_WARP").map_or(true, |v| v != "0");
    let set = GpSettings {
        kernel,
        mean,
        restarts,
        noise_bounds: (noise_lo, 10.0),
        warp,
        ..Default::default()
    };
    let d = rows[0].len() - 1;
    let x: Vec<f64> = rows.iter().flat_map(|r| r[..d].to_vec()).collect();
    let y: Vec<f64> = rows.iter().map(|r| r[d]).collect();
    let bounds = if d == 8 {
        functions::problem("borehole").unwrap().bounds
    } else {
        MODAL13_BOUNDS.to_vec()
    };
    let scaling = InputScaling {
        lo: bounds.iter().map(|b| b.0).collect(),
        hi: bounds.iter().map(|b| b.1).collect(),
    };
    let t0 = Instant::now();
    let gp = fit(&x, d, &y, Some(scaling.clone()), &set).expect("fit");
    let fit_s = t0.elapsed().as_secs_f64();
    let cpu_s = cpu_seconds();
    let (rmse, nlpd) = if case == "holdout" {
        let (_, test) = read_csv(&args[7]);
        let xt: Vec<f64> = test.iter().flat_map(|r| r[..d].to_vec()).collect();
        let yt: Vec<f64> = test.iter().map(|r| r[d]).collect();
        let p = gp.predict(&xt, true).expect("predict");
        metrics(&p.mean, &p.sd, &yt)
    } else if case == "borehole" {
        // Seventh argument: number of independent test sets (seeds 2026, 2027, ...).
        let sets: u64 = args.get(7).map(|v| v.parse().expect("test sets")).unwrap_or(1);
        let mut first = None;
        for seed in 2026..2026 + sets {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let xt: Vec<f64> = (0..2000 * d)
                .map(|i| {
                    let (lo, hi) = bounds[i % d];
                    lo + rng.random::<f64>() * (hi - lo)
                })
                .collect();
            let yt: Vec<f64> = xt.chunks(d).map(functions::borehole).collect();
            let p = gp.predict(&xt, true).expect("predict");
            let m = metrics(&p.mean, &p.sd, &yt);
            if sets > 1 {
                println!("test set seed {seed}: rmse {:.5} nlpd {:.3}", m.0, m.1);
            }
            first.get_or_insert(m);
        }
        first.expect("one test set")
    } else {
        // 5-fold CV at the fitted hyperparameters' family, refitting each fold.
        let n = y.len();
        let (mut mean, mut sd) = (vec![0.0; n], vec![0.0; n]);
        for fold in 0..5 {
            let tr: Vec<usize> = (0..n).filter(|i| i % 5 != fold).collect();
            let te: Vec<usize> = (0..n).filter(|i| i % 5 == fold).collect();
            let xtr: Vec<f64> = tr.iter().flat_map(|&i| x[i * d..(i + 1) * d].to_vec()).collect();
            let ytr: Vec<f64> = tr.iter().map(|&i| y[i]).collect();
            let g = fit(&xtr, d, &ytr, Some(scaling.clone()), &set).expect("fold fit");
            let xte: Vec<f64> = te.iter().flat_map(|&i| x[i * d..(i + 1) * d].to_vec()).collect();
            let p = g.predict(&xte, true).expect("predict");
            for (k, &i) in te.iter().enumerate() {
                mean[i] = p.mean[k];
                sd[i] = p.sd[k];
            }
        }
        metrics(&mean, &sd, &y)
    };
    println!(
        "{case} {restarts} {fit_s:.3} {cpu_s:.3} {rmse:.5} {nlpd:.3} {:.3} evals={} jitter={:.1e} lengths={:?} noise={:.3e} warp={:?}",
        gp.model.report.lml,
        gp.model.report.evaluations,
        gp.model.report.jitter,
        gp.model.kernel.lengths.iter().map(|l| format!("{l:.3}")).collect::<Vec<_>>(),
        gp.model.noise_var,
        gp.model
            .warp
            .inputs
            .iter()
            .map(|w| w.map_or("-".to_string(), |w| format!("{:.3}", w.lambda)))
            .collect::<Vec<_>>()
    );
}
