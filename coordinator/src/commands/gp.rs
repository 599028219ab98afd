//! `ceilfarm gp fit` and `ceilfarm gp predict`: Gaussian-process emulators
//! of a dataset (CSV or a sweep store), one GP per output fitted in
//! parallel, saved as a self-describing JSON model file (kernel,
//! hyperparameters, scaling, training data and its SHA-256).

use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use stats::gp::{fit, Gp, GpModel, GpSettings, KernelKind, MeanKind};
use std::path::{Path, PathBuf};

/// Model-file format tag.
pub const MODEL_FORMAT: &str = "ceilfarm-gp/2";

/// Older format still read: the same without input warps (identity).
const MODEL_FORMAT_V1: &str = "ceilfarm-gp/1";

/// `ceilfarm gp ...` subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum GpCommand {
    /// Fit one GP per output to a CSV file or a sweep store; write model.json.
    Fit(FitArgs),
    /// Predict means and sds at the points of a CSV file.
    Predict(PredictArgs),
}

/// Arguments of `ceilfarm gp fit`.
#[derive(clap::Args, Debug)]
pub struct FitArgs {
    /// Training data (CSV with a header); or use --store.
    pub train: Option<PathBuf>,
    /// A sweep store: the done runs' inputs and scalar outputs.
    #[arg(long, conflicts_with = "train")]
    pub store: Option<PathBuf>,
    /// Input columns, comma-separated (default with --store: all parameters).
    #[arg(long, value_delimiter = ',')]
    pub inputs: Vec<String>,
    /// Output columns, comma-separated.
    #[arg(long, value_delimiter = ',', required = true)]
    pub outputs: Vec<String>,
    /// Model file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Kernel: se, matern32, matern52, rq, or auto (best LML of all four).
    #[arg(long, default_value = "se")]
    pub kernel: String,
    /// Prior mean: zero, constant or linear.
    #[arg(long, default_value = "constant")]
    pub mean: String,
    /// Extra optimiser starts (space-filling) after the default start.
    #[arg(long, default_value_t = 0)]
    pub restarts: usize,
    /// Seed of the start set.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// One kernel shared by all outputs (rows complete in every output).
    #[arg(long)]
    pub shared_kernel: bool,
    /// Do not learn power warps of the inputs with a positive range.
    #[arg(long)]
    pub no_warp: bool,
}

/// Arguments of `ceilfarm gp predict`.
#[derive(clap::Args, Debug)]
pub struct PredictArgs {
    /// Model file from `gp fit`.
    pub model: PathBuf,
    /// Points (CSV with a header holding the model's input columns).
    pub points: PathBuf,
    /// Predictions CSV: inputs, then `<output>_mean,<output>_sd`.
    #[arg(long)]
    pub out: PathBuf,
    /// Add the fitted noise variance to the sd (predict an observation).
    #[arg(long)]
    pub with_noise: bool,
}

/// One fitted output in the model file.
#[derive(Debug, Serialize, Deserialize)]
pub struct OutputModel {
    /// Output column name.
    pub name: String,
    /// LML of each kernel tried (kernel name, LML or null).
    pub kernel_lml: Vec<(String, Option<f64>)>,
    /// The fitted GP.
    pub gp: GpModel,
}

/// The model file.
#[derive(Debug, Serialize, Deserialize)]
pub struct ModelFile {
    /// Format tag.
    pub format: String,
    /// Input column names, in order.
    pub inputs: Vec<String>,
    /// Where the training data came from.
    pub source: String,
    /// SHA-256 of the training inputs and outputs (little-endian f64s).
    pub training_sha256: String,
    /// Number of training rows.
    pub n_train: usize,
    /// One GP per output.
    pub outputs: Vec<OutputModel>,
}

/// Runs a `gp` subcommand.
pub fn run(cmd: GpCommand) -> anyhow::Result<()> {
    match cmd {
        GpCommand::Fit(a) => fit_cmd(a),
        GpCommand::Predict(a) => predict_cmd(a),
    }
}

/// A numeric table: column names and rows.
pub struct Table {
    /// Column names.
    pub names: Vec<String>,
    /// Rows of values.
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// Index of a named column.
    pub fn column(&self, name: &str, path: &Path) -> anyhow::Result<usize> {
        self.names.iter().position(|n| n == name).with_context(|| {
            format!("{}: no column {name:?} (columns: {})", path.display(), self.names.join(","))
        })
    }

    /// Values of the named columns, (n, k) row-major.
    pub fn select(&self, cols: &[String], path: &Path) -> anyhow::Result<Vec<f64>> {
        let idx: Vec<usize> =
            cols.iter().map(|c| self.column(c, path)).collect::<Result<_, _>>()?;
        Ok(self.rows.iter().flat_map(|r| idx.iter().map(|&i| r[i]).collect::<Vec<_>>()).collect())
    }
}

/// Read a CSV of numbers with a header; empty cells read as NaN.
pub fn read_table(path: &Path) -> anyhow::Result<Table> {
    let mut rd =
        csv::Reader::from_path(path).with_context(|| format!("{}: cannot open", path.display()))?;
    let names = rd.headers()?.iter().map(|s| s.trim().to_string()).collect();
    let mut rows = Vec::new();
    for (line, rec) in rd.records().enumerate() {
        let rec = rec.with_context(|| format!("{}:{}", path.display(), line + 2))?;
        let row = rec
            .iter()
            .map(|v| if v.trim().is_empty() { Ok(f64::NAN) } else { v.trim().parse::<f64>() })
            .collect::<Result<Vec<_>, _>>()
            .with_context(|| format!("{}:{}: expected numbers", path.display(), line + 2))?;
        rows.push(row);
    }
    Ok(Table { names, rows })
}

/// The done runs of a store as a table of parameters then scalar outputs.
pub fn store_table(path: &Path) -> anyhow::Result<Table> {
    let store = coordinator::store::Store::open_read_only(path)?;
    let params = store.parameter_names()?;
    let scalars = store.scalar_names()?;
    let rows = store
        .rows()?
        .into_iter()
        .filter(|r| matches!(r.status, Some(coordinator::store::RunStatus::Ok)))
        .map(|r| {
            let mut v = r.params.clone();
            v.extend(scalars.iter().map(|s| r.scalars.get(s).copied().unwrap_or(f64::NAN)));
            v
        })
        .collect();
    let mut names = params;
    names.extend(scalars);
    Ok(Table { names, rows })
}

/// SHA-256 of training inputs then outputs (little-endian f64s).
pub fn sha256(x: &[f64], y: &[f64]) -> String {
    let mut h = Sha256::new();
    for v in x.iter().chain(y) {
        h.update(v.to_le_bytes());
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// (kernel name, LML or `None` if the fit failed) for every kernel tried.
type KernelLmls = Vec<(String, Option<f64>)>;

/// Fit the requested kernel (or every kernel for `auto`, keeping the best LML).
fn fit_output(
    x: &[f64],
    d: usize,
    y: &[f64],
    kernel: &str,
    base: &GpSettings,
) -> anyhow::Result<(Gp, KernelLmls)> {
    let kinds: Vec<KernelKind> = if kernel == "auto" {
        KernelKind::ALL.to_vec()
    } else {
        vec![KernelKind::parse(kernel).with_context(|| {
            format!("--kernel {kernel}: expected se, matern32, matern52, rq or auto")
        })?]
    };
    let mut best: Option<Gp> = None;
    let mut report = Vec::new();
    for kind in kinds {
        let set = GpSettings { kernel: kind, ..base.clone() };
        match fit(x, d, y, None, &set) {
            Ok(gp) => {
                report.push((kind.name().to_string(), Some(gp.model.report.lml)));
                if best.as_ref().is_none_or(|b| gp.model.report.lml > b.model.report.lml) {
                    best = Some(gp);
                }
            }
            Err(e) => {
                tracing::warn!("kernel {}: {e}", kind.name());
                report.push((kind.name().to_string(), None));
            }
        }
    }
    let gp = best.context("no kernel could be fitted")?;
    Ok((gp, report))
}

/// Runs `ceilfarm gp fit`: reads the data, fits each output, writes the model file.
fn fit_cmd(a: FitArgs) -> anyhow::Result<()> {
    let (table, source) = training_table(&a)?;
    let inputs = input_columns(&a)?;
    let mean = MeanKind::parse(&a.mean)
        .with_context(|| format!("--mean {}: expected zero, constant or linear", a.mean))?;
    let d = inputs.len();
    let cols = training_columns(&table, &source, &inputs, &a.outputs, a.shared_kernel)?;
    let base = GpSettings {
        mean,
        restarts: a.restarts,
        seed: a.seed,
        warp: !a.no_warp,
        ..Default::default()
    };
    let outputs = if a.shared_kernel {
        fit_all_shared(&cols, d, &a.kernel, &base)?
    } else {
        fit_all(&cols, d, &a.kernel, &base)?
    };
    let (x0, y0) = (&cols[0].1, &cols[0].2);
    let file = ModelFile {
        format: MODEL_FORMAT.into(),
        inputs,
        source: source.display().to_string(),
        training_sha256: sha256(x0, y0),
        n_train: y0.len(),
        outputs,
    };
    for o in &file.outputs {
        log_output_fit(o);
    }
    let text = serde_json::to_string_pretty(&file)?;
    std::fs::write(&a.out, text).with_context(|| format!("{}: cannot write", a.out.display()))?;
    Ok(())
}

/// The training table (the CSV file or the store's done runs) and its path.
fn training_table(a: &FitArgs) -> anyhow::Result<(Table, PathBuf)> {
    Ok(match (&a.train, &a.store) {
        (Some(p), None) => (read_table(p)?, p.clone()),
        (None, Some(s)) => (store_table(s)?, s.clone()),
        _ => bail!("give a training CSV or --store"),
    })
}

/// The input columns: `--inputs`, or else every parameter of the store.
fn input_columns(a: &FitArgs) -> anyhow::Result<Vec<String>> {
    Ok(match (&a.store, a.inputs.is_empty()) {
        (_, false) => a.inputs.clone(),
        (Some(s), true) => coordinator::store::Store::open_read_only(s)?.parameter_names()?,
        (None, true) => bail!("--inputs is required with a CSV file"),
    })
}

/// Each output's training data over its complete rows (`shared`: complete in every output).
fn training_columns(
    table: &Table,
    source: &Path,
    inputs: &[String],
    outputs: &[String],
    shared: bool,
) -> anyhow::Result<Vec<Column>> {
    let d = inputs.len();
    let xall = table.select(inputs, source)?;
    let yalls = outputs
        .iter()
        .map(|name| table.select(std::slice::from_ref(name), source))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let n_rows = table.rows.len();
    let mut cols = Vec::new();
    for (name, yall) in outputs.iter().zip(&yalls) {
        let keep = if shared {
            complete_rows(&xall, d, n_rows, &yalls.iter().collect::<Vec<_>>())
        } else {
            complete_rows(&xall, d, n_rows, &[yall])
        };
        if keep.len() < 2 {
            bail!(
                "{}: output {name}: {} complete rows, need at least 2",
                source.display(),
                keep.len()
            );
        }
        let x: Vec<f64> = keep.iter().flat_map(|&i| xall[i * d..(i + 1) * d].to_vec()).collect();
        let y: Vec<f64> = keep.iter().map(|&i| yall[i]).collect();
        cols.push((name.clone(), x, y));
    }
    Ok(cols)
}

/// Rows (of `n_rows`) whose inputs `xall` (n, d) and every output of `outs` are finite.
fn complete_rows(xall: &[f64], d: usize, n_rows: usize, outs: &[&Vec<f64>]) -> Vec<usize> {
    let complete = |i: usize| {
        outs.iter().all(|y| y[i].is_finite())
            && xall[i * d..(i + 1) * d].iter().all(|v| v.is_finite())
    };
    (0..n_rows).filter(|&i| complete(i)).collect()
}

/// Logs a fitted output: kernel, LML, noise, lengths, warps and the optimiser's work.
fn log_output_fit(o: &OutputModel) {
    let g = &o.gp;
    let warps: Vec<String> = g
        .warp
        .inputs
        .iter()
        .map(|w| w.map_or("-".into(), |p| format!("{:.2}", p.lambda)))
        .collect();
    eprintln!(
        "{}: kernel {} lml {:.3} noise var {:.3e} lengths [{}] warp exponents [{}] ({} starts, {} evaluations)",
        o.name,
        g.kernel.kind.name(),
        g.report.lml,
        g.noise_var,
        g.kernel.lengths.iter().map(|l| format!("{l:.3}")).collect::<Vec<_>>().join(", "),
        warps.join(", "),
        g.report.starts,
        g.report.evaluations
    );
}

/// One output's training data: name, x (n, d) row-major, y (n).
type Column = (String, Vec<f64>, Vec<f64>);

/// Independent GPs, one per output, fitted in parallel threads.
fn fit_all(
    cols: &[Column],
    d: usize,
    kernel: &str,
    base: &GpSettings,
) -> anyhow::Result<Vec<OutputModel>> {
    let base = &GpSettings { threads: if cols.len() > 1 { 1 } else { 0 }, ..base.clone() };
    let fitted: Vec<anyhow::Result<OutputModel>> = std::thread::scope(|s| {
        let handles: Vec<_> = cols
            .iter()
            .map(|(name, x, y)| {
                s.spawn(move || {
                    let (gp, kernel_lml) = fit_output(x, d, y, kernel, base)
                        .with_context(|| format!("output {name}"))?;
                    Ok(OutputModel { name: name.clone(), kernel_lml, gp: gp.model })
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("fit thread")).collect()
    });
    fitted.into_iter().collect()
}

/// One kernel shared by every output (or, for `auto`, the family with the
/// highest summed LML).
fn fit_all_shared(
    cols: &[Column],
    d: usize,
    kernel: &str,
    base: &GpSettings,
) -> anyhow::Result<Vec<OutputModel>> {
    let kinds: Vec<KernelKind> = if kernel == "auto" {
        KernelKind::ALL.to_vec()
    } else {
        vec![KernelKind::parse(kernel).with_context(|| {
            format!("--kernel {kernel}: expected se, matern32, matern52, rq or auto")
        })?]
    };
    let ys: Vec<Vec<f64>> = cols.iter().map(|c| c.2.clone()).collect();
    let mut best: Option<Vec<Gp>> = None;
    let mut report = Vec::new();
    for kind in kinds {
        let set = GpSettings { kernel: kind, ..base.clone() };
        match stats::gp::fit_shared(&cols[0].1, d, &ys, None, &set) {
            Ok(gps) => {
                let lml = gps[0].model.report.lml;
                report.push((kind.name().to_string(), Some(lml)));
                if best.as_ref().is_none_or(|b| lml > b[0].model.report.lml) {
                    best = Some(gps);
                }
            }
            Err(e) => {
                tracing::warn!("kernel {}: {e}", kind.name());
                report.push((kind.name().to_string(), None));
            }
        }
    }
    let gps = best.context("no kernel could be fitted")?;
    Ok(cols
        .iter()
        .zip(gps)
        .map(|(c, g)| OutputModel { name: c.0.clone(), kernel_lml: report.clone(), gp: g.model })
        .collect())
}

/// Load a model file and factor each output's GP.
pub fn load_model(path: &Path) -> anyhow::Result<(ModelFile, Vec<Gp>)> {
    let file = read_model_file(path)?;
    let gps = file
        .outputs
        .iter()
        .map(|o| {
            Gp::from_model(o.gp.clone())
                .with_context(|| format!("{}: output {}", path.display(), o.name))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok((file, gps))
}

/// Read and check a model file without factoring its GPs.
pub fn read_model_file(path: &Path) -> anyhow::Result<ModelFile> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let file: ModelFile = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a GP model file", path.display()))?;
    if file.format != MODEL_FORMAT && file.format != MODEL_FORMAT_V1 {
        bail!(
            "{}: format {:?}, expected {MODEL_FORMAT:?} (or {MODEL_FORMAT_V1:?})",
            path.display(),
            file.format
        );
    }
    Ok(file)
}

fn predict_cmd(a: PredictArgs) -> anyhow::Result<()> {
    let (file, gps) = load_model(&a.model)?;
    let table = read_table(&a.points)?;
    let x = table.select(&file.inputs, &a.points)?;
    let d = file.inputs.len();
    let m = x.len() / d;
    let preds = gps.iter().map(|g| g.predict(&x, a.with_noise)).collect::<Result<Vec<_>, _>>()?;
    let mut w = csv::Writer::from_path(&a.out)
        .with_context(|| format!("{}: cannot write", a.out.display()))?;
    let mut head = file.inputs.clone();
    for o in &file.outputs {
        head.push(format!("{}_mean", o.name));
        head.push(format!("{}_sd", o.name));
    }
    w.write_record(&head)?;
    for i in 0..m {
        let mut rec: Vec<String> = x[i * d..(i + 1) * d].iter().map(|v| v.to_string()).collect();
        for p in &preds {
            rec.push(p.mean[i].to_string());
            rec.push(p.sd[i].to_string());
        }
        w.write_record(&rec)?;
    }
    w.flush()?;
    Ok(())
}
