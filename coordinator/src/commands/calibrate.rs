//! `ceilfarm calibrate CALIB.toml --out DIR`: Bayesian calibration of a
//! registered model kind, or of GP emulators from a `gp fit` model file
//! (`kind = "gp"`; their predictive variance enters the likelihood),
//! against a data file (KOH discrepancy optional) by BBVI or MCMC; writes
//! `posterior.json`, `samples.csv`, `elbo.csv` (BBVI) and `predictive.csv`
//! (posterior predictive of the simulator).
//!
//! The `[simulator]`, `[data]` and `[[parameters]]` sections are shared with
//! `ceilfarm select`. Relative data paths are resolved against the config
//! file's directory, then each of its parent directories in turn (so
//! `../shared/benchmarks/...` works from a checkout next to `shared/`).

use anyhow::Context;
use serde::Deserialize;
use stats::calibration::{
    calibrate, CalibError, GaussianLikelihood, Hyper, KohLikelihood, KohSettings, Likelihood,
    Method, Posterior, Prediction, RunSettings, Simulator, UniformBox,
};
use std::path::{Path, PathBuf};

/// Arguments of `ceilfarm calibrate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Calibration config (TOML).
    pub config: PathBuf,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
}

/// A configuration value that is wrong: file, key, value and what was expected.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {key} = {value}: expected {expected}")]
pub struct ConfigError {
    /// Config or data file.
    pub file: String,
    /// Offending key (or column).
    pub key: String,
    /// Its value.
    pub value: String,
    /// What was expected.
    pub expected: String,
}

/// `[simulator]`: a model kind of the worker registry, or `gp` emulators.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulatorSection {
    /// Registry kind, e.g. `oscillator`, or `gp`.
    pub kind: String,
    /// Kind-specific options.
    #[serde(default)]
    pub options: toml::Table,
    /// Option that receives the data's x column (one input column only).
    pub x_option: Option<String>,
    /// `gp`: the model file of `ceilfarm gp fit` (or a pipeline's emulators.json).
    pub file: Option<PathBuf>,
    /// `gp`: the emulated output predicting each data row, in row order.
    #[serde(default)]
    pub outputs: Vec<String>,
}

/// `[data]`: observations in a CSV file with a header row.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataSection {
    /// CSV path (relative: see the module doc).
    pub file: PathBuf,
    /// Input columns (the discrepancy's x).
    pub x: Vec<String>,
    /// Observation column.
    pub y: String,
    /// Column of true responses, for Gr % in `select`.
    pub truth: Option<String>,
}

/// `[[parameters]]`: a calibration parameter with its uniform prior.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterSection {
    /// Name passed to the model.
    pub name: String,
    /// Lower bound of the uniform prior.
    pub low: f64,
    /// Upper bound of the uniform prior.
    pub high: f64,
    /// Value used when the parameter is not free (`select`; default: box centre).
    pub nominal: Option<f64>,
}

/// `[noise]`: known sd, a data column of sds, or inferred over a range.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct NoiseSection {
    sd: Option<f64>,
    sd_column: Option<String>,
    infer: Option<[f64; 2]>,
}

/// `[discrepancy]`: none, fixed (sd, length) or inferred over ranges.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DiscrepancySection {
    kind: String,
    /// Prior range of the scale alpha on the simulator (seed eq. 6.4); absent: alpha = 1.
    alpha_range: Option<[f64; 2]>,
    sd: Option<f64>,
    length: Option<f64>,
    sd_range: Option<[f64; 2]>,
    length_range: Option<[f64; 2]>,
}

/// `[method]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MethodSection {
    kind: String,
    #[serde(default = "default_seed")]
    seed: u64,
    #[serde(default = "default_draws")]
    draws: usize,
}

fn default_seed() -> u64 {
    1
}
fn default_draws() -> usize {
    4000
}

/// The whole `calibrate` config.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CalibConfig {
    simulator: SimulatorSection,
    data: DataSection,
    parameters: Vec<ParameterSection>,
    noise: NoiseSection,
    discrepancy: Option<DiscrepancySection>,
    method: MethodSection,
}

/// Reads and parses a TOML file into `T`, naming the file in errors.
pub fn read_toml<T: serde::de::DeserializeOwned>(path: &Path) -> anyhow::Result<T> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Resolves a relative data path against the config's directory and its parents.
pub fn resolve(config: &Path, file: &Path) -> anyhow::Result<PathBuf> {
    if file.is_absolute() {
        return Ok(file.to_path_buf());
    }
    let dir = config.parent().unwrap_or(Path::new("."));
    let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
    let dir = dir.canonicalize().unwrap_or(dir.to_path_buf());
    dir.ancestors()
        .map(|a| a.join(file))
        .find(|p| p.is_file())
        .map(|p| p.canonicalize().unwrap_or(p))
        .ok_or_else(|| {
            ConfigError {
                file: config.display().to_string(),
                key: "data.file".into(),
                value: file.display().to_string(),
                expected: format!("a file relative to {} or one of its parents", dir.display()),
            }
            .into()
        })
}

/// Named columns of a CSV file with a header row, as numbers.
pub fn read_columns(path: &Path, names: &[&str]) -> anyhow::Result<Vec<Vec<f64>>> {
    let mut rdr =
        csv::Reader::from_path(path).with_context(|| format!("{}: cannot open", path.display()))?;
    let header =
        rdr.headers().with_context(|| format!("{}: no header row", path.display()))?.clone();
    let idx: Vec<usize> = names
        .iter()
        .map(|n| {
            header.iter().position(|h| h.trim() == *n).ok_or_else(|| ConfigError {
                file: path.display().to_string(),
                key: "column".into(),
                value: n.to_string(),
                expected: format!(
                    "one of the header's columns ({})",
                    header.iter().collect::<Vec<_>>().join(", ")
                ),
            })
        })
        .collect::<Result<_, _>>()?;
    let mut cols = vec![Vec::new(); names.len()];
    for (line, rec) in rdr.records().enumerate() {
        let rec = rec.with_context(|| format!("{}:{}", path.display(), line + 2))?;
        for (c, &i) in idx.iter().enumerate() {
            let s = rec.get(i).unwrap_or("").trim();
            let v: f64 =
                s.parse().ok().filter(|v: &f64| v.is_finite()).ok_or_else(|| ConfigError {
                    file: format!("{}:{}", path.display(), line + 2),
                    key: names[c].into(),
                    value: format!("{s:?}"),
                    expected: "a finite number".into(),
                })?;
            cols[c].push(v);
        }
    }
    Ok(cols)
}

/// A registry model seen as a calibration simulator: outputs in model order,
/// one per data row.
pub struct ModelSimulator {
    model: Box<dyn worker::Model>,
    names: Vec<String>,
    n_outputs: usize,
}

impl Simulator for ModelSimulator {
    fn n_params(&self) -> usize {
        self.names.len()
    }
    fn n_outputs(&self) -> usize {
        self.n_outputs
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        let fail = |message: String| CalibError::Simulator { theta: theta.to_vec(), message };
        let p = worker::ParamSet::new(&self.names, theta).map_err(|e| fail(e.to_string()))?;
        let out =
            self.model.run(&p, &worker::RunContext::default()).map_err(|e| fail(e.to_string()))?;
        let mean: Vec<f64> = out.scalars.iter().map(|(_, v)| *v).collect();
        CalibError::check_len("model outputs", mean.len(), self.n_outputs)?;
        Ok(Prediction { mean, variance: None })
    }
}

/// The data and simulator of a config: x (n, D), y (n), optional truth, the simulator.
pub struct Problem {
    /// Inputs, one row per observation.
    pub x: Vec<Vec<f64>>,
    /// Observations.
    pub y: Vec<f64>,
    /// True responses (if `data.truth` is set).
    pub truth: Option<Vec<f64>>,
    /// The simulator over every `[[parameters]]` entry.
    pub sim: Box<dyn Simulator>,
    /// The prior box of those parameters.
    pub prior: UniformBox,
}

/// Loads the data and builds the model for `[simulator]`, `[data]`, `[[parameters]]`.
pub fn load_problem(
    config: &Path,
    sim: &SimulatorSection,
    data: &DataSection,
    params: &[ParameterSection],
) -> anyhow::Result<Problem> {
    let (path, cols) = read_data(config, data)?;
    let d = data.x.len();
    let n = cols[d].len();
    let x: Vec<Vec<f64>> = (0..n).map(|i| (0..d).map(|j| cols[j][i]).collect()).collect();
    let prior = prior_box(config, params)?;
    let simulator: Box<dyn Simulator> = if sim.kind == "gp" {
        Box::new(gp_simulator(config, sim, params, n)?)
    } else {
        Box::new(model_simulator(config, sim, params, &cols[..d], n, &path)?)
    };
    Ok(Problem {
        x,
        y: cols[d].clone(),
        truth: data.truth.as_ref().map(|_| cols[d + 1].clone()),
        sim: simulator,
        prior,
    })
}

/// The resolved data path and its columns: the x columns, then y, then truth (if set).
fn read_data(config: &Path, data: &DataSection) -> anyhow::Result<(PathBuf, Vec<Vec<f64>>)> {
    let path = resolve(config, &data.file)?;
    let mut names: Vec<&str> = data.x.iter().map(String::as_str).collect();
    names.push(&data.y);
    if let Some(t) = &data.truth {
        names.push(t);
    }
    let cols = read_columns(&path, &names)?;
    Ok((path, cols))
}

/// The uniform prior box of the `[[parameters]]`, in their order.
fn prior_box(config: &Path, params: &[ParameterSection]) -> anyhow::Result<UniformBox> {
    UniformBox::new(
        params.iter().map(|p| p.name.clone()).collect(),
        params.iter().map(|p| p.low).collect(),
        params.iter().map(|p| p.high).collect(),
    )
    .map_err(|e| anyhow::anyhow!("{}: [[parameters]]: {e}", config.display()))
}

/// The registry model of `[simulator]`, checked to give one output per data row (`n_rows`).
fn model_simulator(
    config: &Path,
    sim: &SimulatorSection,
    params: &[ParameterSection],
    x_cols: &[Vec<f64>],
    n_rows: usize,
    data_path: &Path,
) -> anyhow::Result<ModelSimulator> {
    let file = config.display().to_string();
    let options = model_options(&file, sim, x_cols)?;
    let param_names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
    let spec = protocol::ModelSpec {
        kind: sim.kind.clone(),
        options_json: options.to_string(),
        param_names: param_names.clone(),
        outputs: vec![],
    };
    let model =
        worker::registry::build(&spec).map_err(|e| anyhow::anyhow!("{file}: [simulator]: {e}"))?;
    let n_out = model.output_names().len();
    if n_out != n_rows {
        return Err(ConfigError {
            file,
            key: "simulator".into(),
            value: format!("{n_out} outputs"),
            expected: format!("one output per data row ({n_rows} rows in {})", data_path.display()),
        }
        .into());
    }
    Ok(ModelSimulator { model, names: param_names, n_outputs: n_out })
}

/// `simulator.options` as JSON, with the single x column (`x_cols`) under `x_option` if set.
fn model_options(
    file: &str,
    sim: &SimulatorSection,
    x_cols: &[Vec<f64>],
) -> anyhow::Result<serde_json::Value> {
    let mut options = serde_json::to_value(&sim.options)?;
    if let Some(key) = &sim.x_option {
        if x_cols.len() != 1 {
            return Err(ConfigError {
                file: file.to_string(),
                key: "simulator.x_option".into(),
                value: key.clone(),
                expected: "exactly one data.x column".into(),
            }
            .into());
        }
        options[key] = serde_json::json!(x_cols[0]);
    }
    Ok(options)
}

/// GP emulators seen as a simulator over the `[[parameters]]` in their order.
struct GpFileSimulator {
    emulator: stats::calibration::GpEmulator,
    /// For each emulator input, its index among the parameters.
    from_param: Vec<usize>,
}

impl Simulator for GpFileSimulator {
    fn n_params(&self) -> usize {
        self.from_param.len()
    }
    fn n_outputs(&self) -> usize {
        self.emulator.n_outputs()
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        CalibError::check_len("parameters", theta.len(), self.from_param.len())?;
        let x: Vec<f64> = self.from_param.iter().map(|&k| theta[k]).collect();
        self.emulator.predict(&x)
    }
}

/// The `gp` simulator: the model file's outputs for the data rows; every
/// emulator input must be a `[[parameters]]` entry and vice versa.
fn gp_simulator(
    config: &Path,
    sim: &SimulatorSection,
    params: &[ParameterSection],
    n_rows: usize,
) -> anyhow::Result<GpFileSimulator> {
    let file = config.display().to_string();
    let path = sim.file.as_ref().ok_or_else(|| {
        bad(&file, "simulator.file", "(missing)", "the GP model file for kind = \"gp\"")
    })?;
    let model = crate::commands::gp::read_model_file(&resolve(config, path)?)?;
    if sim.outputs.len() != n_rows {
        return Err(bad(
            &file,
            "simulator.outputs",
            &sim.outputs,
            &format!("one emulated output per data row ({n_rows} rows)"),
        ));
    }
    let known: Vec<&str> = model.outputs.iter().map(|o| o.name.as_str()).collect();
    let chosen = sim
        .outputs
        .iter()
        .map(|name| {
            let o = model.outputs.iter().find(|o| &o.name == name).ok_or_else(|| {
                bad(&file, "simulator.outputs", name, &format!("one of {}", known.join(", ")))
            })?;
            stats::gp::Gp::from_model(o.gp.clone())
                .with_context(|| format!("{}: output {name}", path.display()))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
    let from_param = model
        .inputs
        .iter()
        .map(|input| {
            names.iter().position(|n| n == input).ok_or_else(|| {
                bad(
                    &file,
                    "[[parameters]]",
                    &names,
                    &format!("an entry for emulator input {input}"),
                )
            })
        })
        .collect::<anyhow::Result<Vec<usize>>>()?;
    if params.len() != model.inputs.len() {
        return Err(bad(
            &file,
            "[[parameters]]",
            &names,
            &format!("exactly the emulator inputs {}", model.inputs.join(", ")),
        ));
    }
    let emulator = stats::calibration::GpEmulator::new(chosen, true)?;
    Ok(GpFileSimulator { emulator, from_param })
}

fn bad(file: &str, key: &str, value: impl std::fmt::Debug, expected: &str) -> anyhow::Error {
    ConfigError {
        file: file.into(),
        key: key.into(),
        value: format!("{value:?}"),
        expected: expected.into(),
    }
    .into()
}

/// (Hyper, optional prior range) of the noise section; a `sd_column` is a
/// fixed unit sd scaled per row (see [`noise_scale`]).
fn noise_hyper(file: &str, n: &NoiseSection) -> anyhow::Result<(Hyper, Option<[f64; 2]>)> {
    match (n.sd, &n.sd_column, n.infer) {
        (Some(sd), None, None) if sd > 0.0 && sd.is_finite() => Ok((Hyper::Fixed(sd), None)),
        (None, Some(_), None) => Ok((Hyper::Fixed(1.0), None)),
        (None, None, Some(r)) => Ok((Hyper::Inferred, Some(r))),
        _ => Err(bad(
            file,
            "noise",
            (n.sd, &n.sd_column, n.infer),
            "one of sd = <value > 0>, sd_column = \"<data column>\" or infer = [low, high]",
        )),
    }
}

/// Per-row noise sds from `[noise] sd_column` (ones without it).
fn noise_scale(
    config: &Path,
    data: &DataSection,
    n: &NoiseSection,
    rows: usize,
) -> anyhow::Result<Vec<f64>> {
    let Some(col) = &n.sd_column else {
        return Ok(vec![1.0; rows]);
    };
    let path = resolve(config, &data.file)?;
    let sd = read_columns(&path, &[col.as_str()])?.remove(0);
    if let Some(v) = sd.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(bad(&path.display().to_string(), col, v, "finite sds > 0"));
    }
    Ok(sd)
}

/// KOH settings and prior ranges of the inferred hyperparameters, in likelihood order.
fn koh_settings(
    file: &str,
    noise: Hyper,
    d: &DiscrepancySection,
) -> anyhow::Result<(KohSettings, Vec<[f64; 2]>)> {
    let base = KohSettings {
        alpha: if d.alpha_range.is_some() { Hyper::Inferred } else { Hyper::Fixed(1.0) },
        noise_sd: noise,
        disc_sd: Hyper::Fixed(0.0),
        disc_length: Hyper::Fixed(1.0),
    };
    match d.kind.as_str() {
        "fixed" => match (d.sd, d.length) {
            (Some(sd), Some(l)) => Ok((
                KohSettings { disc_sd: Hyper::Fixed(sd), disc_length: Hyper::Fixed(l), ..base },
                vec![],
            )),
            _ => Err(bad(
                file,
                "discrepancy",
                (d.sd, d.length),
                "sd and length for kind = \"fixed\"",
            )),
        },
        "inferred" => match (d.sd_range, d.length_range) {
            (Some(s), Some(l)) => Ok((
                KohSettings { disc_sd: Hyper::Inferred, disc_length: Hyper::Inferred, ..base },
                vec![s, l],
            )),
            _ => Err(bad(
                file,
                "discrepancy",
                (d.sd_range, d.length_range),
                "sd_range and length_range for kind = \"inferred\"",
            )),
        },
        other => Err(bad(file, "discrepancy.kind", other, "\"none\", \"fixed\" or \"inferred\"")),
    }
}

/// Runs `ceilfarm calibrate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let cfg: CalibConfig = read_toml(&args.config)?;
    let file = args.config.display().to_string();
    let method = Method::from_name(&cfg.method.kind, cfg.method.seed).ok_or_else(|| {
        bad(&file, "method.kind", &cfg.method.kind, &format!("one of {}", Method::NAMES.join(", ")))
    })?;
    let p = load_problem(&args.config, &cfg.simulator, &cfg.data, &cfg.parameters)?;
    let (noise, noise_range) = noise_hyper(&file, &cfg.noise)?;
    let scale = noise_scale(&args.config, &cfg.data, &cfg.noise, p.y.len())?;
    let settings = RunSettings {
        method,
        draws: cfg.method.draws.max(10),
        map_starts: 8,
        seed: cfg.method.seed,
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("{}: cannot create", args.out.display()))?;
    let disc = cfg.discrepancy.as_ref().filter(|d| d.kind != "none");
    match disc {
        None => {
            let lik = GaussianLikelihood::new(&p.sim, p.y.clone(), noise)
                .and_then(|l| l.with_noise_scale(scale))
                .map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
            finish(&args, &cfg.method.kind, &p, lik, noise_range.into_iter().collect(), &settings)
        }
        Some(d) => {
            let (koh, mut ranges) = koh_settings(&file, noise, d)?;
            if let Some(r) = noise_range {
                ranges.insert(0, r);
            }
            if let Some(r) = d.alpha_range {
                ranges.insert(0, r);
            }
            let lik = KohLikelihood::new(&p.sim, p.x.clone(), p.y.clone(), koh)
                .and_then(|l| l.with_noise_scale(scale))
                .map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
            finish(&args, &cfg.method.kind, &p, lik, ranges, &settings)
        }
    }
}

/// Builds the posterior with the extra ranges, runs it and writes the outputs.
fn finish<L: Likelihood>(
    args: &Args,
    method: &str,
    p: &Problem,
    lik: L,
    extra: Vec<[f64; 2]>,
    s: &RunSettings,
) -> anyhow::Result<()> {
    let file = args.config.display().to_string();
    let mut names = p.prior.names.clone();
    let (mut lo, mut hi) = (p.prior.lower.clone(), p.prior.upper.clone());
    for (name, r) in lik.extra_names().into_iter().zip(extra) {
        names.push(name);
        lo.push(r[0]);
        hi.push(r[1]);
    }
    let prior = UniformBox::new(names, lo, hi).map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
    let post = Posterior::new(prior, lik).map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
    let res = calibrate(&post, s, &mut [])?;
    write_outputs(&args.out, method, p, &post, &res)
}

/// posterior.json, samples.csv, elbo.csv, predictive.csv.
fn write_outputs<L: Likelihood>(
    out: &Path,
    method: &str,
    p: &Problem,
    post: &Posterior<L>,
    res: &stats::calibration::CalibrationResult,
) -> anyhow::Result<()> {
    let s = &res.summary;
    let params: serde_json::Map<String, serde_json::Value> = s
        .names
        .iter()
        .zip(&s.marginals)
        .map(|(n, m)| (n.clone(), serde_json::to_value(m).unwrap_or_default()))
        .collect();
    write_posterior(out, method, params, res, serde_json::Map::new())?;
    write(out, "predictive.csv", &predictive(p, post, res)?)
}

/// posterior.json (`parameters` as given, the correlation, method, ELBO,
/// diagnostics, then `extra` fields), samples.csv and, for BBVI, elbo.csv.
pub fn write_posterior(
    out: &Path,
    method: &str,
    parameters: serde_json::Map<String, serde_json::Value>,
    res: &stats::calibration::CalibrationResult,
    extra: serde_json::Map<String, serde_json::Value>,
) -> anyhow::Result<()> {
    let s = &res.summary;
    let d = s.names.len();
    let matrix: Vec<Vec<f64>> =
        (0..d).map(|i| (0..d).map(|j| s.correlation[(i, j)]).collect()).collect();
    let mut json = serde_json::json!({
        "parameters": parameters,
        "correlation": { "names": s.names, "matrix": matrix },
        "method": method,
        "elbo": res.elbo,
        "diagnostics": res.diagnostics,
    });
    if let Some(obj) = json.as_object_mut() {
        obj.extend(extra);
    }
    write(out, "posterior.json", &(serde_json::to_string_pretty(&json)? + "\n"))?;
    let mut text = s.names.join(",") + "\n";
    for d in &res.draws {
        text += &(d.iter().map(|v| format!("{v:.10e}")).collect::<Vec<_>>().join(",") + "\n");
    }
    write(out, "samples.csv", &text)?;
    if !res.elbo_trace.is_empty() {
        let text: String = std::iter::once("iteration,elbo\n".to_string())
            .chain(res.elbo_trace.iter().enumerate().map(|(i, e)| format!("{},{e}\n", i + 1)))
            .collect();
        write(out, "elbo.csv", &text)?;
    }
    Ok(())
}

fn write(out: &Path, name: &str, text: &str) -> anyhow::Result<()> {
    let path = out.join(name);
    std::fs::write(&path, text).with_context(|| format!("{}: cannot write", path.display()))
}

/// Posterior predictive of the simulator at the data points (up to 500 draws):
/// x columns, y, eta_mean, eta_q05, eta_q95.
fn predictive<L: Likelihood>(
    p: &Problem,
    post: &Posterior<L>,
    res: &stats::calibration::CalibrationResult,
) -> anyhow::Result<String> {
    let k = post.prior().dim() - post.likelihood().extra_names().len();
    let step = (res.draws.len() / 500).max(1);
    let preds: Vec<Vec<f64>> = res
        .draws
        .iter()
        .step_by(step)
        .map(|t| p.sim.predict(&t[..k]).map(|pr| pr.mean))
        .collect::<Result<_, _>>()?;
    let d = p.x.first().map_or(0, Vec::len);
    let mut text = (0..d)
        .map(|j| format!("x{}", j + 1))
        .chain(["y", "eta_mean", "eta_q05", "eta_q95"].map(String::from))
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    for i in 0..p.y.len() {
        let mut v: Vec<f64> = preds.iter().map(|r| r[i]).collect();
        v.sort_by(f64::total_cmp);
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let q = |x| stats::calibration::summary::quantile_sorted(&v, x);
        let xs: Vec<String> = p.x[i].iter().map(|v| v.to_string()).collect();
        text += &format!("{},{},{mean},{},{}\n", xs.join(","), p.y[i], q(0.05), q(0.95));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/calibration").join(name)
    }

    /// The shipped benchmark config reproduces the exact posterior
    /// (k 1.1924 ± 0.0326, c 0.3023 ± 0.0070, m 1.0073 ± 0.0294).
    #[test]
    fn nodisc_config_writes_the_exact_posterior() {
        let out = tempfile::tempdir().unwrap();
        run(Args { config: config("oscillator-nodisc.toml"), out: out.path().into() }).unwrap();
        let text = std::fs::read_to_string(out.path().join("posterior.json")).unwrap();
        let j: serde_json::Value = serde_json::from_str(&text).unwrap();
        for (name, mean, sd) in
            [("k", 1.1924, 0.0326), ("c", 0.3023, 0.0070), ("m", 1.0073, 0.0294)]
        {
            let p = &j["parameters"][name];
            let (m, s) = (p["mean"].as_f64().unwrap(), p["sd"].as_f64().unwrap());
            assert!((m - mean).abs() < 0.2 * sd && (s / sd - 1.0).abs() < 0.1, "{name}: {m} ± {s}");
            assert!(p["q05"].as_f64().unwrap() < p["q50"].as_f64().unwrap());
        }
        assert_eq!(j["correlation"]["names"][2], "m");
        assert_eq!(j["method"], "bbvi-fullrank");
        assert!(
            j["elbo"].as_f64().unwrap().is_finite()
                && j["diagnostics"]["psis_k_hat"].as_f64().unwrap() < 0.7
        );
        let samples = std::fs::read_to_string(out.path().join("samples.csv")).unwrap();
        assert_eq!(samples.lines().next(), Some("k,c,m"));
        assert_eq!(samples.lines().count(), 4001);
    }

    /// With `alpha_range` the scale is inferred after the model parameters.
    /// alpha is confounded with k and m, and the posterior is far from
    /// Gaussian: the MCMC reference gives alpha 1.19 +- 0.24 (the data's
    /// alpha = 1 inside its 5..95 % interval), full-rank BBVI a too narrow
    /// 1.24 +- 0.10, and BBVI says so with a PSIS k-hat above 0.7.
    #[test]
    fn alpha_range_infers_the_scale() {
        let dir = tempfile::tempdir().unwrap();
        let text = std::fs::read_to_string(config("oscillator-disc.toml")).unwrap();
        let rel = "../shared/benchmarks/calib_disc.csv";
        let data = resolve(&config("oscillator-disc.toml"), Path::new(rel)).unwrap();
        let text = text
            .replace("kind = \"fixed\"", "kind = \"fixed\"\nalpha_range = [0.5, 1.5]")
            .replace(rel, &data.display().to_string());
        let alpha = |method: &str| {
            let cfg = dir.path().join(format!("{method}.toml"));
            let t = text.replace("kind = \"bbvi-fullrank\"", &format!("kind = \"{method}\""));
            std::fs::write(&cfg, t).unwrap();
            let out = dir.path().join(method);
            run(Args { config: cfg, out: out.clone() }).unwrap();
            let post = std::fs::read_to_string(out.join("posterior.json")).unwrap();
            let j: serde_json::Value = serde_json::from_str(&post).unwrap();
            assert_eq!(j["correlation"]["names"][3], "alpha");
            let a = &j["parameters"]["alpha"];
            let k_hat = j["diagnostics"]["psis_k_hat"].as_f64();
            let q = |key: &str| a[key].as_f64().unwrap();
            (q("q05"), q("q95"), q("sd"), k_hat)
        };
        let (_, _, vs, k_hat) = alpha("bbvi-fullrank");
        let (lo, hi, ms, _) = alpha("mcmc");
        assert!(lo < 1.0 && 1.0 < hi, "MCMC alpha 5..95 %: {lo}..{hi}");
        assert!(vs < ms && k_hat.unwrap() > 0.7, "BBVI sd {vs} (MCMC {ms}), k-hat {k_hat:?}");
    }

    #[test]
    fn unknown_key_names_file_and_key() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        let text = std::fs::read_to_string(config("oscillator-nodisc.toml"))
            .unwrap()
            .replace("[noise]", "[noise]\nsigma = 2");
        std::fs::write(&path, text).unwrap();
        let e = run(Args { config: path.clone(), out: dir.path().into() }).unwrap_err().to_string();
        assert!(
            e.contains("bad.toml") && e.contains("unknown field `sigma`") && e.contains("expected"),
            "{e}"
        );
    }

    #[test]
    fn bad_discrepancy_kind_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = config("oscillator-disc.toml");
        let data = resolve(&path, Path::new("../shared/benchmarks/calib_disc.csv")).unwrap();
        let text = std::fs::read_to_string(&path)
            .unwrap()
            .replace("kind = \"fixed\"", "kind = \"gp\"")
            .replace("../shared/benchmarks/calib_disc.csv", &data.display().to_string());
        let copy = dir.path().join("disc.toml");
        std::fs::write(&copy, text).unwrap();
        let e = run(Args { config: copy, out: dir.path().into() }).unwrap_err().to_string();
        assert!(
            e.contains("discrepancy.kind = \"gp\": expected \"none\", \"fixed\" or \"inferred\""),
            "{e}"
        );
    }

    #[test]
    fn missing_data_file_is_named() {
        let e = resolve(&config("oscillator-nodisc.toml"), Path::new("nope/none.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("data.file = nope/none.csv"), "{e}");
    }
}
