//! The must-show GP accuracy on the shared benchmark files
//! (../shared/benchmarks/README.md §1). Thresholds are scikit-learn's
//! reference numbers. The borehole test runs in about 25 s in the dev
//! profile; the modal13 one (five fits) is slow there: run it with
//! `cargo test --release -p ceilfarm-stats --test it gp_benchmarks:: -- --ignored`.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use stats::gp::{fit, GpSettings, InputScaling, KernelKind};
use stats::sobol::functions;
use stats::validation::validate;

use crate::calib_common;

fn read_csv(file: &str) -> Vec<Vec<f64>> {
    let path = calib_common::benchmarks_dir().join(file);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect()
}

fn split(rows: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>, usize) {
    let d = rows[0].len() - 1;
    (rows.iter().flat_map(|r| r[..d].to_vec()).collect(), rows.iter().map(|r| r[d]).collect(), d)
}

fn scaling(bounds: &[(f64, f64)]) -> InputScaling {
    InputScaling {
        lo: bounds.iter().map(|b| b.0).collect(),
        hi: bounds.iter().map(|b| b.1).collect(),
    }
}

/// Borehole n = 1000, kernel chosen by LML among SE and RQ, inputs
/// power-warped (the default); test RMSE and NLPD on 2000 fresh uniform
/// points (seed 2026) from the formula.
#[test]
fn borehole_1000_beats_reference_rmse_and_nlpd() {
    let (x, y, d) = split(&read_csv("borehole_train_1000.csv"));
    let bounds = functions::problem("borehole").unwrap().bounds;
    let gp = [KernelKind::SquaredExponential, KernelKind::RationalQuadratic]
        .into_iter()
        .map(|kernel| {
            fit(&x, d, &y, Some(scaling(&bounds)), &GpSettings { kernel, ..Default::default() })
                .unwrap()
        })
        .max_by(|a, b| a.model.report.lml.total_cmp(&b.model.report.lml))
        .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let xt: Vec<f64> = (0..2000 * d)
        .map(|i| bounds[i % d].0 + rng.random::<f64>() * (bounds[i % d].1 - bounds[i % d].0))
        .collect();
    let yt: Vec<f64> = xt.chunks(d).map(functions::borehole).collect();
    let p = gp.predict(&xt, true).unwrap();
    let v = validate(&p.mean, &p.sd, &yt).unwrap();
    println!("kernel {:?}: RMSE {:.5}, NLPD {:.3}", gp.model.kernel.kind, v.rmse, v.nlpd);
    assert!(v.nlpd <= -2.9, "NLPD {}", v.nlpd);
    assert!(v.rmse <= 0.0171, "RMSE {} (kernel {:?})", v.rmse, gp.model.kernel.kind);
}

/// modal13 f1 (n = 700, noisy): 5-fold cross-validated RMSE.
#[test]
#[ignore = "five GP fits of 560 points in 13 inputs: slow in the dev profile"]
fn modal13_f1_cross_validated_rmse() {
    let (x, y, d) = split(&read_csv("modal13_train_700.csv"));
    let bounds = [
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
    let n = y.len();
    let (mut mean, mut sd) = (vec![0.0; n], vec![0.0; n]);
    for fold in 0..5 {
        let tr: Vec<usize> = (0..n).filter(|i| i % 5 != fold).collect();
        let te: Vec<usize> = (0..n).filter(|i| i % 5 == fold).collect();
        let pick = |idx: &[usize]| -> Vec<f64> {
            idx.iter().flat_map(|&i| x[i * d..(i + 1) * d].to_vec()).collect()
        };
        let ytr: Vec<f64> = tr.iter().map(|&i| y[i]).collect();
        let gp = fit(&pick(&tr), d, &ytr, Some(scaling(&bounds)), &GpSettings::default()).unwrap();
        let p = gp.predict(&pick(&te), true).unwrap();
        for (k, &i) in te.iter().enumerate() {
            mean[i] = p.mean[k];
            sd[i] = p.sd[k];
        }
    }
    let v = validate(&mean, &sd, &y).unwrap();
    assert!(v.rmse <= 0.0216, "CV RMSE {}", v.rmse);
    assert!(v.coverage95 > 0.9, "coverage {}", v.coverage95);
}
