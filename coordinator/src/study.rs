//! Study files (TOML): what to sweep, over which parameters, with which
//! design, on which farm. Parsed raw, then checked once into a [`Study`]
//! that reports every bad key with the file and what was expected.
//!
//! ```toml
//! [study]
//! name = "borehole"
//! [model]
//! kind = "borehole"          # plus kind-specific options; every kind takes cost_ms
//! [[parameters]]
//! name = "rw"
//! low = 0.05
//! high = 0.15
//! units = "m"
//! [design]
//! method = "maximin-lhs"     # "maximin-lhs" | "lhs" | "sobol"
//! n = 200
//! seed = 1
//! [outputs]
//! scalars = ["y"]            # empty or absent: every scalar the model gives
//! [farm]
//! workers = 2
//! transport = "in-process"  # or "iceoryx2" (processes on one host), "zenoh" (lab machines)
//! endpoint = "tcp/0.0.0.0:7447"  # zenoh: where the coordinator listens
//! task_timeout_s = 600
//! max_retries = 1
//! ```

use crate::design::maximin;
use crate::study_files::read_confined;
use protocol::ModelSpec;
use serde::Deserialize;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Why a study file was refused.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// TOML syntax or an unknown/mistyped key (the message carries line and key).
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// One or more keys hold values out of range; every problem is listed.
    #[error("{path}: {}", problems.join("\n  "))]
    Invalid {
        /// The file.
        path: PathBuf,
        /// One line per bad key: `key = value: expected ...`.
        problems: Vec<String>,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStudy {
    study: RawHeader,
    model: toml::Table,
    parameters: Vec<RawParameter>,
    design: RawDesign,
    #[serde(default)]
    outputs: RawOutputs,
    #[serde(default)]
    farm: RawFarm,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHeader {
    name: String,
    #[serde(default)]
    description: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParameter {
    name: String,
    low: f64,
    high: f64,
    #[serde(default)]
    units: String,
    #[serde(default)]
    distribution: Distribution,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDesign {
    method: DesignMethod,
    n: i64,
    seed: u64,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutputs {
    #[serde(default)]
    scalars: Vec<String>,
    #[serde(default)]
    histories: bool,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFarm {
    workers: Option<i64>,
    #[serde(default = "default_transport")]
    transport: TransportKind,
    #[serde(default = "default_timeout")]
    task_timeout_s: f64,
    #[serde(default = "default_retries")]
    max_retries: i64,
    #[serde(default)]
    endpoint: Option<String>,
}

impl Default for RawFarm {
    fn default() -> Self {
        Self {
            workers: None,
            transport: default_transport(),
            task_timeout_s: default_timeout(),
            max_retries: default_retries(),
            endpoint: None,
        }
    }
}

fn default_transport() -> TransportKind {
    TransportKind::InProcess
}
fn default_timeout() -> f64 {
    3600.0
}
fn default_retries() -> i64 {
    1
}

/// How a parameter's unit-cube coordinate maps to its physical range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Distribution {
    /// Linear between low and high.
    #[default]
    Uniform,
    /// Linear in log between low and high (both > 0).
    LogUniform,
}

/// Space-filling design family.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum DesignMethod {
    /// Latin hypercube optimised for the Morris–Mitchell phi_p criterion.
    MaximinLhs,
    /// Plain random Latin hypercube.
    Lhs,
    /// Owen-scrambled Sobol' sequence.
    Sobol,
}

/// Which transport carries tasks to the workers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum TransportKind {
    /// Worker threads in this process.
    InProcess,
    /// Worker processes on this host, over iceoryx2 shared memory.
    Iceoryx2,
    /// Worker processes on lab machines, over zenoh.
    Zenoh,
}

impl TransportKind {
    /// The spelling in study files and on the command line.
    pub fn as_str(&self) -> &'static str {
        match self {
            TransportKind::InProcess => "in-process",
            TransportKind::Iceoryx2 => "iceoryx2",
            TransportKind::Zenoh => "zenoh",
        }
    }
}

/// One uncertain parameter with its range in physical units.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Name, as the model knows it.
    pub name: String,
    /// Lower bound (physical units).
    pub low: f64,
    /// Upper bound (physical units).
    pub high: f64,
    /// Units, for people (e.g. `"mm2"`, `"N/mm"`).
    pub units: String,
    /// How the unit interval maps to the range.
    pub distribution: Distribution,
}

impl Parameter {
    /// Physical value of unit-cube coordinate `u` in [0, 1].
    pub fn from_unit(&self, u: f64) -> f64 {
        match self.distribution {
            Distribution::Uniform => self.low + u * (self.high - self.low),
            Distribution::LogUniform => {
                (self.low.ln() + u * (self.high.ln() - self.low.ln())).exp()
            }
        }
    }
}

/// The design settings.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSpec {
    /// Design family.
    pub method: DesignMethod,
    /// Number of points.
    pub n: usize,
    /// RNG seed (ChaCha8).
    pub seed: u64,
}

/// Farm settings; none of them changes results.
#[derive(Debug, Clone, PartialEq)]
pub struct FarmSpec {
    /// Worker count (default: the machine's cores).
    pub workers: usize,
    /// Transport.
    pub transport: TransportKind,
    /// Time a task may take before it is given up, in seconds.
    pub task_timeout_s: f64,
    /// How often a failed or timed-out task is tried again.
    pub max_retries: u32,
    /// Where the coordinator listens (zenoh, e.g. `tcp/0.0.0.0:7447`) or the
    /// service-name prefix (iceoryx2); `None` takes the transport's default.
    pub endpoint: Option<String>,
}

/// A validated study.
#[derive(Debug, Clone)]
pub struct Study {
    /// Where it was read from.
    pub path: PathBuf,
    /// Its name.
    pub name: String,
    /// Free text.
    pub description: String,
    /// Model kind.
    pub model_kind: String,
    /// Model options (without `kind`), as JSON.
    pub model_options: serde_json::Map<String, serde_json::Value>,
    /// Uncertain parameters, in design-column order.
    pub parameters: Vec<Parameter>,
    /// The design.
    pub design: DesignSpec,
    /// Scalars to keep (empty: all).
    pub outputs: Vec<String>,
    /// Whether time histories are stored.
    pub keep_histories: bool,
    /// Farm settings.
    pub farm: FarmSpec,
}

impl Study {
    /// Reads and validates a study file.
    pub fn load(path: &Path) -> Result<Study, StudyError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| StudyError::Io { path: path.to_path_buf(), source })?;
        Study::parse(&text, path)
    }

    /// Parses and validates study text; `path` is used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Study, StudyError> {
        let raw: RawStudy = toml::from_str(text)
            .map_err(|e| StudyError::Parse { path: path.to_path_buf(), message: e.to_string() })?;
        validate(raw, path)
    }

    /// The model spec sent to workers.
    pub fn model_spec(&self) -> ModelSpec {
        ModelSpec {
            kind: self.model_kind.clone(),
            options_json: serde_json::Value::Object(self.model_options.clone()).to_string(),
            param_names: self.parameters.iter().map(|p| p.name.clone()).collect(),
            outputs: self.outputs.clone(),
        }
    }

    /// Every key that changes results, flattened to `path -> value` text.
    /// `cost_ms`, names, descriptions and farm settings are left out.
    pub fn result_keys(&self) -> BTreeMap<String, String> {
        let mut keys = BTreeMap::new();
        keys.insert("model.kind".to_string(), self.model_kind.clone());
        for (k, v) in &self.model_options {
            if k != "cost_ms" {
                keys.insert(format!("model.{k}"), v.to_string());
            }
        }
        let names: Vec<&str> = self.parameters.iter().map(|p| p.name.as_str()).collect();
        keys.insert("parameters".into(), names.join(","));
        for p in &self.parameters {
            keys.insert(format!("parameters.{}.low", p.name), format_value(p.low));
            keys.insert(format!("parameters.{}.high", p.name), format_value(p.high));
            keys.insert(
                format!("parameters.{}.distribution", p.name),
                format!("{:?}", p.distribution),
            );
        }
        keys.insert("design.method".into(), format!("{:?}", self.design.method));
        keys.insert("design.n".into(), self.design.n.to_string());
        keys.insert("design.seed".into(), self.design.seed.to_string());
        keys.insert("outputs.scalars".into(), self.outputs.join(","));
        keys.insert("outputs.histories".into(), self.keep_histories.to_string());
        keys
    }

    /// SHA-256 (hex) of [`Study::result_keys`].
    pub fn hash(&self) -> String {
        hash_keys(&self.result_keys())
    }
}

/// SHA-256 (hex) of a flattened key map.
pub fn hash_keys(keys: &BTreeMap<String, String>) -> String {
    let mut h = Sha256::new();
    for (k, v) in keys {
        h.update(k.as_bytes());
        h.update([0]);
        h.update(v.as_bytes());
        h.update([0]);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Shortest round-trip text of a float, as stored and exported.
pub fn format_value(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || (1e-5..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

fn validate(raw: RawStudy, path: &Path) -> Result<Study, StudyError> {
    let mut problems = Vec::new();
    let name_ok = |s: &str| {
        !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || "_.-".contains(c))
    };
    if !name_ok(&raw.study.name) {
        problems.push(format!(
            "study.name = {:?}: expected letters, digits, '_', '.' or '-'",
            raw.study.name
        ));
    }
    let mut model = raw.model;
    let kind = match model.remove("kind") {
        Some(toml::Value::String(k)) => k,
        Some(v) => {
            problems.push(format!("model.kind = {v}: expected a string such as \"borehole\""));
            String::new()
        }
        None => {
            problems.push("model.kind: missing (expected e.g. \"borehole\")".into());
            String::new()
        }
    };
    let mut model_options = match serde_json::to_value(&model) {
        Ok(serde_json::Value::Object(m)) => m,
        _ => serde_json::Map::new(),
    };
    inline_file(&mut model_options, ("spec", "spec_toml", "model.spec"), path, &mut problems);
    if let Some(serde_json::Value::Object(ex)) = model_options.get_mut("excitation") {
        let keys = ("file", "csv", "model.excitation.file");
        inline_file(ex, keys, path, &mut problems);
    }
    let d = raw.parameters.len();
    let parameters = check_parameters(raw.parameters, &mut problems);
    let design = check_design(raw.design, d, &mut problems);
    let farm = check_farm(raw.farm, &mut problems);
    if !problems.is_empty() {
        return Err(StudyError::Invalid { path: path.to_path_buf(), problems });
    }
    let study = Study {
        path: path.to_path_buf(),
        name: raw.study.name,
        description: raw.study.description,
        model_kind: kind,
        model_options,
        parameters,
        design,
        outputs: raw.outputs.scalars,
        keep_histories: raw.outputs.histories,
        farm,
    };
    check_model(&study)
        .map_err(|p| StudyError::Invalid { path: path.to_path_buf(), problems: vec![p] })?;
    Ok(study)
}

fn check_parameters(raw: Vec<RawParameter>, problems: &mut Vec<String>) -> Vec<Parameter> {
    if raw.is_empty() {
        problems.push("parameters: expected at least one [[parameters]] table".into());
    }
    let mut seen = std::collections::HashSet::new();
    for (i, p) in raw.iter().enumerate() {
        let at = format!("parameters[{i}] ({})", p.name);
        if !seen.insert(p.name.clone()) {
            problems.push(format!("{at}: name used twice"));
        }
        if !(p.low.is_finite() && p.high.is_finite() && p.low < p.high) {
            problems.push(format!(
                "{at}: low = {}, high = {}: expected finite low < high",
                p.low, p.high
            ));
        }
        if p.distribution == Distribution::LogUniform && p.low <= 0.0 {
            problems.push(format!("{at}: low = {}: log-uniform needs low > 0", p.low));
        }
    }
    raw.into_iter()
        .map(|p| Parameter {
            name: p.name,
            low: p.low,
            high: p.high,
            units: p.units,
            distribution: p.distribution,
        })
        .collect()
}

/// Largest design of any method in coordinates (points x parameters): 2^24
/// values, 128 MiB in the unit cube and as much in physical units.
pub const MAX_DESIGN_COORDINATES: usize = 1 << 24;

/// Checks the design's size against the memory its method needs.
fn check_design(raw: RawDesign, d: usize, problems: &mut Vec<String>) -> DesignSpec {
    let n = raw.n.max(0) as u64;
    let max_n = (MAX_DESIGN_COORDINATES / d.max(1)) as u64;
    let before = problems.len();
    if n < 2 {
        problems.push(format!("design.n = {}: expected at least 2 points", raw.n));
    } else if raw.method == DesignMethod::MaximinLhs && n > maximin::MAX_POINTS as u64 {
        let matrix = human_bytes(n as f64 * n as f64 * 8.0);
        problems.push(format!(
            "design.n = {n}: maximin-lhs keeps an n x n distance matrix ({matrix} at this n); \
             expected 2 to {} points, or method = \"lhs\" or \"sobol\" beyond",
            maximin::MAX_POINTS
        ));
    } else if n > max_n {
        problems.push(format!(
            "design.n = {n}: {d} parameters x {n} points exceed {MAX_DESIGN_COORDINATES} \
             coordinates ({}); expected 2 to {max_n} points",
            human_bytes(MAX_DESIGN_COORDINATES as f64 * 8.0)
        ));
    }
    let n = if problems.len() == before { n as usize } else { 0 };
    DesignSpec { method: raw.method, n, seed: raw.seed }
}

/// A byte count in the largest binary unit that keeps it at least 1.
fn human_bytes(bytes: f64) -> String {
    let units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut value = bytes;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < units.len() {
        value /= 1024.0;
        unit += 1;
    }
    format!("{value:.0} {}", units[unit])
}

fn check_farm(raw: RawFarm, problems: &mut Vec<String>) -> FarmSpec {
    let workers = match raw.workers {
        None => default_workers(),
        Some(w) if (1..=4096).contains(&w) => w as usize,
        Some(w) => {
            problems.push(format!("farm.workers = {w}: expected 1 to 4096"));
            1
        }
    };
    if !(raw.task_timeout_s.is_finite() && raw.task_timeout_s > 0.0) {
        problems
            .push(format!("farm.task_timeout_s = {}: expected seconds > 0", raw.task_timeout_s));
    }
    if !(0..=100).contains(&raw.max_retries) {
        problems.push(format!("farm.max_retries = {}: expected 0 to 100", raw.max_retries));
    }
    FarmSpec {
        workers,
        transport: raw.transport,
        task_timeout_s: raw.task_timeout_s,
        max_retries: raw.max_retries.clamp(0, 100) as u32,
        endpoint: raw.endpoint,
    }
}

/// The machine's core count, the default number of workers.
pub fn default_workers() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

/// Builds the model once to check its options and parameter names.
fn check_model(study: &Study) -> Result<(), String> {
    let model = worker::registry::build(&study.model_spec()).map_err(|e| e.to_string())?;
    let names = model.output_names();
    for o in &study.outputs {
        if !names.contains(o) {
            return Err(format!(
                "outputs.scalars: `{o}` is not an output of `{}` (it gives: {})",
                study.model_kind,
                names.join(", ")
            ));
        }
    }
    Ok(())
}

/// Replaces `map[key] = "FILE"` (inside the study file's folder, see
/// [`crate::study_files`]) by the file's text as `map[into]`, so that
/// workers on other machines need no copy and the study hash covers the
/// file itself; `label` names the key in a problem. Used for `[model] spec`
/// (a specimen TOML, as `spec_toml`) and `[model.excitation] file` (a
/// record CSV, as `csv`).
fn inline_file(
    map: &mut serde_json::Map<String, serde_json::Value>,
    (key, into, label): (&str, &str, &str),
    study_path: &Path,
    problems: &mut Vec<String>,
) {
    let Some(serde_json::Value::String(file)) = map.get(key).cloned() else { return };
    let folder = match study_path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match read_confined(folder, &file) {
        Ok(text) => {
            map.remove(key);
            map.insert(into.into(), serde_json::Value::String(text));
        }
        Err(e) => problems.push(format!("{label} = {file:?}: {e}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[study]
name = "t"
[model]
kind = "ishigami"
[[parameters]]
name = "x1"
low = -3.14
high = 3.14
[[parameters]]
name = "x2"
low = -3.14
high = 3.14
[[parameters]]
name = "x3"
low = -3.14
high = 3.14
[design]
method = "lhs"
n = 10
seed = 1
"#;

    fn err(text: &str) -> String {
        Study::parse(text, Path::new("s.toml")).unwrap_err().to_string()
    }

    #[test]
    fn good_study_parses() {
        let s = Study::parse(GOOD, Path::new("s.toml")).unwrap();
        assert_eq!(s.parameters.len(), 3);
        assert_eq!(s.design.n, 10);
    }

    #[test]
    fn unknown_key_names_the_key_and_file() {
        let e = err(&GOOD.replace("seed = 1", "seed = 1\nsed = 2"));
        assert!(e.starts_with("s.toml:") && e.contains("unknown field `sed`"), "{e}");
    }

    #[test]
    fn every_bad_value_is_reported() {
        let bad = GOOD
            .replace(
                "low = -3.14\nhigh = 3.14\n[[parameters]]\nname = \"x2\"",
                "low = 3\nhigh = 1\n[[parameters]]\nname = \"x2\"",
            )
            .replace("n = 10", "n = 1");
        let e = err(&bad);
        assert!(
            e.contains("parameters[0] (x1): low = 3, high = 1") && e.contains("design.n = 1"),
            "{e}"
        );
    }

    /// Regression (issue 56): maximin with n = 10 000 000 aborted on an
    /// allocation of its n x n distance matrix (800 TB).
    #[test]
    fn a_maximin_design_beyond_its_memory_bound_is_refused() {
        let big = GOOD.replace("\"lhs\"", "\"maximin-lhs\"").replace("n = 10", "n = 10000000");
        let e = err(&big);
        let expected = "design.n = 10000000: maximin-lhs keeps an n x n distance matrix \
            (728 TiB at this n); expected 2 to 4096 points, or method = \"lhs\" or \"sobol\" beyond";
        assert!(e.contains(expected), "{e}");
        let at_bound = GOOD.replace("\"lhs\"", "\"maximin-lhs\"").replace("n = 10", "n = 4096");
        assert_eq!(Study::parse(&at_bound, Path::new("s.toml")).unwrap().design.n, 4096);
    }

    #[test]
    fn a_design_beyond_the_coordinate_bound_is_refused() {
        let e = err(&GOOD.replace("n = 10", "n = 10000000"));
        let expected = "design.n = 10000000: 3 parameters x 10000000 points exceed 16777216 \
            coordinates (128 MiB); expected 2 to 5592405 points";
        assert!(e.contains(expected), "{e}");
    }

    #[test]
    fn wrong_method_says_what_is_expected() {
        let e = err(&GOOD.replace("\"lhs\"", "\"grid\""));
        assert!(e.contains("grid") && e.contains("maximin-lhs"), "{e}");
    }

    #[test]
    fn model_option_errors_surface() {
        let e = err(&GOOD.replace("kind = \"ishigami\"", "kind = \"ishigami\"\nbogus = 1"));
        assert!(e.contains("unknown field `bogus`"), "{e}");
    }

    #[test]
    fn cost_and_farm_do_not_change_the_hash() {
        let a = Study::parse(GOOD, Path::new("a")).unwrap();
        let b = Study::parse(
            &GOOD.replace("kind = \"ishigami\"", "kind = \"ishigami\"\ncost_ms = 5"),
            Path::new("b"),
        )
        .unwrap();
        assert_eq!(a.hash(), b.hash());
        let c = Study::parse(&GOOD.replace("seed = 1", "seed = 2"), Path::new("c")).unwrap();
        assert_ne!(a.hash(), c.hash());
    }

    #[test]
    fn ceiling_record_and_specimen_files_are_inlined() {
        let dir = tempfile::tempdir().unwrap();
        let specimen =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/specimens/small-3p6.toml");
        std::fs::copy(specimen, dir.path().join("spec.toml")).unwrap();
        let record = "t_s,ag_g\n0,0\n0.01,0.01\n0.02,0\n";
        std::fs::write(dir.path().join("rec.csv"), record).unwrap();
        let text = r#"
[study]
name = "c"
[model]
kind = "ceiling"
spec = "spec.toml"
excitation = { type = "record", file = "rec.csv", units = "g", direction = "x" }
[[parameters]]
name = "K_friction"
low = 15.0
high = 25.0
[design]
method = "lhs"
n = 4
seed = 1
"#;
        let s = Study::parse(text, &dir.path().join("s.toml")).unwrap();
        let ex = s.model_options["excitation"].as_object().unwrap();
        assert_eq!(ex.get("csv").and_then(|v| v.as_str()), Some(record));
        assert!(!ex.contains_key("file") && !s.model_options.contains_key("spec"));
        let e = err(&text.replace("rec.csv", "nope.csv"));
        assert!(e.contains("model.excitation.file = \"nope.csv\""), "{e}");
    }

    /// A study in a fresh folder naming `spec = SPEC`; the error it gets.
    fn spec_error(dir: &Path, spec: &str) -> String {
        let text =
            GOOD.replace("kind = \"ishigami\"", &format!("kind = \"ishigami\"\nspec = {spec:?}"));
        Study::parse(&text, &dir.join("s.toml")).unwrap_err().to_string()
    }

    /// Regression (issue 56): `spec = "../../../../etc/passwd"` was read
    /// and its first line echoed.
    #[test]
    fn a_spec_outside_the_study_folder_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let outside = dir.path().join("outside.toml");
        std::fs::write(&outside, "secret").unwrap();
        std::fs::create_dir(dir.path().join("study")).unwrap();
        let e = spec_error(&dir.path().join("study"), "../outside.toml");
        assert!(
            e.contains("model.spec = \"../outside.toml\": resolves to")
                && e.contains("outside the study's folder"),
            "{e}"
        );
        assert!(!e.contains("secret"), "{e}");
        let e = spec_error(&dir.path().join("study"), s(&outside));
        assert!(e.contains("outside the study's folder"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_out_of_the_study_folder_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        std::os::unix::fs::symlink("/dev/zero", dir.path().join("spec.toml")).unwrap();
        let e = spec_error(dir.path(), "spec.toml");
        let expected =
            "model.spec = \"spec.toml\": resolves to /dev/zero, outside the study's folder";
        assert!(e.contains(expected), "{e}");
    }

    /// Regression (issue 56): a FIFO named as `spec` hung the coordinator.
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_opening_it() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("spec.toml");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        let e = spec_error(dir.path(), "spec.toml");
        let expected =
            "model.spec = \"spec.toml\": a FIFO, not a regular file; expected a regular file";
        assert!(e.contains(expected), "{e}");
    }

    #[test]
    fn a_spec_larger_than_the_bound_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let big = std::fs::File::create(dir.path().join("spec.toml")).unwrap();
        big.set_len(crate::study_files::MAX_STUDY_FILE_BYTES + 1).unwrap();
        let e = spec_error(dir.path(), "spec.toml");
        assert!(
            e.contains(
                "model.spec = \"spec.toml\": 16777217 bytes; expected at most 16777216 bytes"
            ),
            "{e}"
        );
    }

    fn s(p: &Path) -> &str {
        p.to_str().unwrap()
    }

    #[test]
    fn log_uniform_maps_geometrically() {
        let p = Parameter {
            name: "r".into(),
            low: 1.0,
            high: 100.0,
            units: String::new(),
            distribution: Distribution::LogUniform,
        };
        assert!((p.from_unit(0.5) - 10.0).abs() < 1e-12);
    }
}
