//! Stage 2: one GP emulator per observed output (seed 6.5, Algorithm 6.1):
//! the runs are split at random into training, validation and test sets;
//! each kernel is fitted on the training set and the one with the lowest
//! validation RMSE is kept; its accuracy on the untouched test set is
//! reported. Inputs are scaled by the design bounds.

use super::config::EmulatorSection;
use crate::commands::gp::{ModelFile, OutputModel, MODEL_FORMAT};
use anyhow::{bail, Context, Result};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use serde::Serialize;
use stats::gp::{fit, Gp, GpSettings, InputScaling, KernelKind};
use stats::validation::{validate, Validation};

/// The sweep's runs as inputs (n, d) row-major and the outputs, column-wise.
pub struct Dataset {
    /// Parameter names, in design order.
    pub inputs: Vec<String>,
    /// Design bounds of each parameter.
    pub scaling: InputScaling,
    /// Inputs of the complete runs, (n, d) row-major.
    pub x: Vec<f64>,
    /// Output names.
    pub outputs: Vec<String>,
    /// One column per output, (n) each.
    pub y: Vec<Vec<f64>>,
}

/// The store's complete runs: `inputs` (design bounds `bounds`) and `outputs`.
pub fn dataset(
    store: &std::path::Path,
    inputs: &[String],
    bounds: &[(f64, f64)],
    outputs: &[String],
) -> Result<Dataset> {
    let table = crate::commands::gp::store_table(store)?;
    let x_all = table.select(inputs, store)?;
    let y_all = outputs
        .iter()
        .map(|o| table.select(std::slice::from_ref(o), store))
        .collect::<Result<Vec<_>>>()?;
    let d = inputs.len();
    let complete = |i: &usize| {
        y_all.iter().all(|y| y[*i].is_finite())
            && x_all[i * d..(i + 1) * d].iter().all(|v| v.is_finite())
    };
    let idx: Vec<usize> = (0..table.rows.len()).filter(complete).collect();
    Ok(Dataset {
        inputs: inputs.to_vec(),
        scaling: InputScaling {
            lo: bounds.iter().map(|b| b.0).collect(),
            hi: bounds.iter().map(|b| b.1).collect(),
        },
        x: rows(&x_all, d, &idx),
        outputs: outputs.to_vec(),
        y: y_all.iter().map(|y| idx.iter().map(|&i| y[i]).collect()).collect(),
    })
}

/// Accuracy of one kernel or of the chosen emulator.
#[derive(Debug, Clone, Serialize)]
pub struct KernelTrial {
    /// Kernel name.
    pub kernel: String,
    /// Maximised log marginal likelihood on the training set.
    pub lml: Option<f64>,
    /// RMSE on the validation set (output units).
    pub validation_rmse: Option<f64>,
}

/// The chosen emulator of one output.
#[derive(Debug, Clone, Serialize)]
pub struct EmulatorReport {
    /// Output name.
    pub output: String,
    /// Every kernel tried.
    pub trials: Vec<KernelTrial>,
    /// The kernel kept.
    pub kernel: String,
    /// Accuracy on the test set.
    pub test: Validation,
    /// The seed's "accuracy": 100 (1 − Σ|error| / Σ|y − mean y|) on the test set.
    pub test_accuracy_percent: f64,
}

/// Sizes of the three sets.
#[derive(Debug, Clone, Serialize)]
pub struct Split {
    /// Training runs.
    pub train: usize,
    /// Validation runs.
    pub validation: usize,
    /// Test runs.
    pub test: usize,
    /// SHA-256 of the training inputs and first output (model file).
    #[serde(skip)]
    pub training_sha256: String,
}

/// Random split of `n` rows by the fractions (train, validation, test).
pub fn split(n: usize, fractions: [f64; 3], seed: u64) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let mut idx: Vec<usize> = (0..n).collect();
    idx.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
    let n_train = (fractions[0] * n as f64).round() as usize;
    let n_val = ((fractions[1] * n as f64).round() as usize).min(n - n_train);
    let test = idx.split_off(n_train + n_val);
    let val = idx.split_off(n_train);
    (idx, val, test)
}

fn rows(x: &[f64], d: usize, idx: &[usize]) -> Vec<f64> {
    idx.iter().flat_map(|&i| x[i * d..(i + 1) * d].iter().copied()).collect()
}

/// Percentage accuracy as the seed reports it (mean absolute error relative
/// to the mean absolute deviation of the test values).
pub fn accuracy_percent(mean: &[f64], y: &[f64]) -> f64 {
    let ybar = y.iter().sum::<f64>() / y.len() as f64;
    let err: f64 = mean.iter().zip(y).map(|(m, v)| (m - v).abs()).sum();
    let dev: f64 = y.iter().map(|v| (v - ybar).abs()).sum();
    100.0 * (1.0 - err / dev)
}

/// Fits, chooses and tests the emulator of output `k`.
fn emulate(
    data: &Dataset,
    k: usize,
    sets: &(Vec<usize>, Vec<usize>, Vec<usize>),
    cfg: &EmulatorSection,
) -> Result<(Gp, EmulatorReport)> {
    let d = data.inputs.len();
    let y = &data.y[k];
    let pick = |idx: &[usize]| idx.iter().map(|&i| y[i]).collect::<Vec<f64>>();
    let (xt, xv, xs) =
        (rows(&data.x, d, &sets.0), rows(&data.x, d, &sets.1), rows(&data.x, d, &sets.2));
    let (yt, yv, ys) = (pick(&sets.0), pick(&sets.1), pick(&sets.2));
    let mut best: Option<(f64, Gp)> = None;
    let mut trials = Vec::new();
    for name in &cfg.kernels {
        let kind = KernelKind::parse(name).context("kernel checked on load")?;
        let set = GpSettings {
            kernel: kind,
            restarts: cfg.restarts,
            warp: cfg.warp,
            seed: cfg.seed as u32,
            threads: 1,
            ..Default::default()
        };
        match fit(&xt, d, &yt, Some(data.scaling.clone()), &set) {
            Ok(gp) => {
                let pred = gp.predict_mean(&xv)?;
                let rmse = (pred.iter().zip(&yv).map(|(p, v)| (p - v).powi(2)).sum::<f64>()
                    / yv.len() as f64)
                    .sqrt();
                trials.push(KernelTrial {
                    kernel: name.clone(),
                    lml: Some(gp.model.report.lml),
                    validation_rmse: Some(rmse),
                });
                if best.as_ref().is_none_or(|(r, _)| rmse < *r) {
                    best = Some((rmse, gp));
                }
            }
            Err(e) => {
                tracing::warn!("{}: kernel {name}: {e}", data.outputs[k]);
                trials.push(KernelTrial { kernel: name.clone(), lml: None, validation_rmse: None });
            }
        }
    }
    let Some((_, gp)) = best else {
        bail!("output {}: no kernel could be fitted", data.outputs[k]);
    };
    let p = gp.predict(&xs, true)?;
    let test = validate(&p.mean, &p.sd, &ys).context("empty test set")?;
    let report = EmulatorReport {
        output: data.outputs[k].clone(),
        trials,
        kernel: gp.model.kernel.kind.name().to_string(),
        test_accuracy_percent: accuracy_percent(&p.mean, &ys),
        test,
    };
    Ok((gp, report))
}

/// One output's fitted emulator and report, filled in by a worker thread.
type EmulatorSlot = std::sync::Mutex<Option<Result<(Gp, EmulatorReport)>>>;

/// Emulators of every output, fitted in parallel threads.
pub fn fit_all(
    data: &Dataset,
    cfg: &EmulatorSection,
) -> Result<(Vec<Gp>, Vec<EmulatorReport>, Split)> {
    let n = data.x.len() / data.inputs.len();
    let sets = split(n, cfg.split, cfg.seed);
    if sets.0.len() < 2 || sets.1.is_empty() || sets.2.is_empty() {
        bail!("{n} complete runs: too few for a {:?} split", cfg.split);
    }
    let d = data.inputs.len();
    let y0: Vec<f64> = sets.0.iter().map(|&i| data.y[0][i]).collect();
    let sizes = Split {
        train: sets.0.len(),
        validation: sets.1.len(),
        test: sets.2.len(),
        training_sha256: crate::commands::gp::sha256(&rows(&data.x, d, &sets.0), &y0),
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let next = std::sync::atomic::AtomicUsize::new(0);
    let slots: Vec<EmulatorSlot> =
        (0..data.outputs.len()).map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|s| {
        for _ in 0..threads.min(data.outputs.len()) {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                if k >= data.outputs.len() {
                    break;
                }
                let r = emulate(data, k, &sets, cfg);
                if let Ok(mut slot) = slots[k].lock() {
                    *slot = Some(r);
                }
            });
        }
    });
    let mut gps = Vec::new();
    let mut reports = Vec::new();
    for slot in slots {
        let (gp, rep) = slot
            .into_inner()
            .map_err(|_| anyhow::anyhow!("an emulator thread panicked"))?
            .context("an emulator was not fitted")??;
        gps.push(gp);
        reports.push(rep);
    }
    Ok((gps, reports, sizes))
}

/// The emulators as a `gp fit` model file (usable by `ceilfarm gp predict`).
pub fn model_file(
    data: &Dataset,
    gps: &[Gp],
    reports: &[EmulatorReport],
    split: &Split,
    source: &str,
) -> ModelFile {
    ModelFile {
        format: MODEL_FORMAT.into(),
        inputs: data.inputs.clone(),
        source: source.into(),
        training_sha256: split.training_sha256.clone(),
        n_train: gps.first().map_or(0, Gp::n_train),
        outputs: gps
            .iter()
            .zip(reports)
            .map(|(g, r)| OutputModel {
                name: r.output.clone(),
                kernel_lml: r.trials.iter().map(|t| (t.kernel.clone(), t.lml)).collect(),
                gp: g.model.clone(),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_is_a_seeded_partition() {
        let (a, b, c) = split(100, [0.7, 0.2, 0.1], 3);
        assert_eq!((a.len(), b.len(), c.len()), (70, 20, 10));
        let mut all: Vec<usize> = a.iter().chain(&b).chain(&c).copied().collect();
        all.sort();
        assert_eq!(all, (0..100).collect::<Vec<_>>());
        assert_eq!(split(100, [0.7, 0.2, 0.1], 3).0, a);
        assert_ne!(split(100, [0.7, 0.2, 0.1], 4).0, a);
    }

    #[test]
    fn accuracy_of_a_perfect_and_of_a_mean_prediction() {
        let y = [1.0, 2.0, 3.0, 6.0];
        assert_eq!(accuracy_percent(&y, &y), 100.0);
        assert!(accuracy_percent(&[3.0; 4], &y).abs() < 1e-12);
    }
}
