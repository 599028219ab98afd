//! `bundle.toml`: the specimen, its sensors and its runs.

use super::files::{confined, open_regular};
use super::ranges::{check_range, Range, GAP_MM, HANGER_M, LENGTH_M, PANEL_KG, SPACING_M};
use super::{BundleError, Limits, FORMAT};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// Perimeter condition of the ceiling (seed Table 4.5, 4.2.2): the FE
/// generator's, spelled as `bundle.toml` spells it.
pub use fe::generator::Boundary;

/// The specimen as built (nominal values).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Structure {
    /// Plan length along x (cross tees), m.
    pub length_x_m: f64,
    /// Plan length along y (main tees), m.
    pub length_y_m: f64,
    /// Cross-tee spacing and panel size, m.
    pub module_m: f64,
    /// Main-tee spacing, m.
    pub main_tee_spacing_m: f64,
    /// Hanger-rod spacing on the main tees, m.
    pub hanger_spacing_m: f64,
    /// Hanger-rod length, m.
    pub hanger_length_m: f64,
    /// Mass of one lay-in panel, kg.
    pub panel_mass_kg: f64,
    /// 1 (grid only) or 2 (carrying channels above the grid).
    #[serde(default = "two")]
    pub layers: u8,
    /// Perimeter condition.
    pub boundary: Boundary,
    /// Gap from grid end to wall angle, mm (not for `fixed`).
    #[serde(default)]
    pub nominal_gap_mm: Option<f64>,
    /// Whether members lie on the wall lines: a main tee on a wall at
    /// x = 0 or x = Lx that falls on the main-tee lines (hung on rods) and
    /// cross tees along y = 0 and y = Ly; false (the default): the grid's
    /// outermost members are one module in and its ends rest on the walls.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub wall_members: bool,
    /// Distance from the wall y = 0 to the first row of hanger rods, m: a
    /// multiple of `module_m` below `hanger_spacing_m`; 0 (the default):
    /// rows on y = 0, h, 2h, … (a row on a wall left out).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub hanger_offset_m: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn two() -> u8 {
    2
}

/// What a sensor measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SensorKind {
    /// Absolute acceleration.
    Acceleration,
    /// Displacement relative to the platform.
    Displacement,
}

impl SensorKind {
    /// The spelling in `bundle.toml`.
    pub fn as_str(&self) -> &'static str {
        match self {
            SensorKind::Acceleration => "acceleration",
            SensorKind::Displacement => "displacement",
        }
    }
}

/// Horizontal direction of a reading or an input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Along the cross tees.
    X,
    /// Along the main tees.
    Y,
}

impl Direction {
    /// The spelling in `bundle.toml`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Direction::X => "x",
            Direction::Y => "y",
        }
    }
}

/// Units of a sensor column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum SensorUnits {
    /// m/s².
    #[serde(rename = "m/s2")]
    MPerS2,
    /// Standard gravity, 9.80665 m/s².
    #[serde(rename = "g")]
    G,
    /// Metres.
    #[serde(rename = "m")]
    M,
    /// Millimetres.
    #[serde(rename = "mm")]
    Mm,
}

impl SensorUnits {
    /// Factor to the internal unit (m/s² for accelerations, mm for displacements).
    pub fn to_internal(&self) -> f64 {
        match self {
            SensorUnits::MPerS2 => 1.0,
            SensorUnits::G => 9.80665,
            SensorUnits::M => 1000.0,
            SensorUnits::Mm => 1.0,
        }
    }
    /// The spelling in `bundle.toml`.
    pub fn as_str(&self) -> &'static str {
        match self {
            SensorUnits::MPerS2 => "m/s2",
            SensorUnits::G => "g",
            SensorUnits::M => "m",
            SensorUnits::Mm => "mm",
        }
    }
}

/// Units of the input (floor) acceleration columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum InputUnits {
    /// m/s².
    #[serde(rename = "m/s2")]
    MPerS2,
    /// Standard gravity.
    #[serde(rename = "g")]
    G,
}

impl InputUnits {
    /// Factor to m/s².
    pub fn to_m_s2(&self) -> f64 {
        match self {
            InputUnits::MPerS2 => 1.0,
            InputUnits::G => 9.80665,
        }
    }
}

/// Whether a run calibrates the model or checks it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RunRole {
    /// Used to calibrate.
    Calibration,
    /// Held out to validate.
    Validation,
}

impl RunRole {
    /// The spelling in `bundle.toml`.
    pub fn as_str(&self) -> &'static str {
        match self {
            RunRole::Calibration => "calibration",
            RunRole::Validation => "validation",
        }
    }
}

/// One sensor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sensor {
    /// Unique id, also its column name in run files.
    pub id: String,
    /// What it measures.
    pub kind: SensorKind,
    /// Position along x, m.
    pub x_m: f64,
    /// Position along y, m.
    pub y_m: f64,
    /// Direction of the reading.
    pub direction: Direction,
    /// Units of its column.
    pub units: SensorUnits,
}

/// One shaking-table run as `bundle.toml` lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunMeta {
    /// Unique id.
    pub id: String,
    /// CSV file, relative to the bundle directory.
    pub file: String,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Column with the floor acceleration in x.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input_x: Option<String>,
    /// Column with the floor acceleration in y.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input_y: Option<String>,
    /// Units of the input columns.
    pub input_units: InputUnits,
    /// Calibration or validation, if the lab chose.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub role: Option<RunRole>,
}

/// `bundle.toml`, checked.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Must be `ceiling-measured/1`.
    pub format: String,
    /// Bundle name.
    pub name: String,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// The specimen.
    pub structure: Structure,
    /// Sensors (at least one).
    pub sensors: Vec<Sensor>,
    /// Runs (at least one).
    pub runs: Vec<RunMeta>,
}

/// Reads a regular text file with a size limit, refusing NUL bytes and bad UTF-8.
pub(super) fn read_text(path: &Path, max_bytes: u64) -> Result<String, BundleError> {
    use std::io::Read;
    let file = open_regular(path, max_bytes)?;
    let mut bytes = Vec::new();
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|source| BundleError::Io { path: path.to_path_buf(), source })?;
    if bytes.len() as u64 > max_bytes {
        return Err(BundleError::File {
            path: path.to_path_buf(),
            message: format!("larger than the limit of {max_bytes} bytes"),
        });
    }
    if let Some(pos) = bytes.iter().position(|&b| b == 0) {
        let line = bytes[..pos].iter().filter(|&&b| b == b'\n').count() + 1;
        return Err(BundleError::Line {
            path: path.to_path_buf(),
            line,
            message: "NUL byte: expected plain text".into(),
        });
    }
    String::from_utf8(bytes).map_err(|e| BundleError::File {
        path: path.to_path_buf(),
        message: format!("not UTF-8 text ({e})"),
    })
}

/// Reads and checks `DIR/bundle.toml`.
pub(super) fn read_manifest(dir: &Path, limits: &Limits) -> Result<Manifest, BundleError> {
    let path = dir.join("bundle.toml");
    if std::fs::symlink_metadata(&path).is_err() {
        return Err(BundleError::Missing { path, what: "every bundle needs bundle.toml".into() });
    }
    confined(dir, "bundle.toml")
        .map_err(|message| BundleError::File { path: path.clone(), message })?;
    let text = read_text(&path, limits.max_file_bytes.min(16 << 20))?;
    let manifest: Manifest = toml::from_str(&text).map_err(|e| BundleError::File {
        path: path.clone(),
        message: e.to_string().trim_end().to_string(),
    })?;
    check_manifest(&manifest, dir, &path)?;
    Ok(manifest)
}

fn key_err(path: &Path, key: impl Into<String>, message: impl Into<String>) -> BundleError {
    BundleError::Key { path: path.to_path_buf(), key: key.into(), message: message.into() }
}

fn valid_id(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 128
        && s.chars().all(|c| c.is_ascii_alphanumeric() || "_.-".contains(c))
}

fn is_multiple(value: f64, of: f64) -> bool {
    let q = value / of;
    (q - q.round()).abs() < 1e-6 && q.round() >= 1.0
}

fn check_manifest(m: &Manifest, dir: &Path, path: &Path) -> Result<(), BundleError> {
    if m.format != FORMAT {
        return Err(key_err(
            path,
            "format",
            format!("{:?}: expected exactly {FORMAT:?}", m.format),
        ));
    }
    if !valid_id(&m.name) {
        return Err(key_err(path, "name", format!("{:?}: expected [A-Za-z0-9_.-]+", m.name)));
    }
    check_structure(&m.structure, path)?;
    check_sensors(m, path)?;
    check_runs(m, dir, path)
}

/// The accepted range of a positive `[structure]` key.
fn structure_range(key: &str) -> Range {
    match key {
        "length_x_m" | "length_y_m" => LENGTH_M,
        "hanger_length_m" => HANGER_M,
        "panel_mass_kg" => PANEL_KG,
        _ => SPACING_M,
    }
}

fn check_structure(s: &Structure, path: &Path) -> Result<(), BundleError> {
    let positive = [
        ("length_x_m", s.length_x_m),
        ("length_y_m", s.length_y_m),
        ("module_m", s.module_m),
        ("main_tee_spacing_m", s.main_tee_spacing_m),
        ("hanger_spacing_m", s.hanger_spacing_m),
        ("hanger_length_m", s.hanger_length_m),
        ("panel_mass_kg", s.panel_mass_kg),
    ];
    for (key, v) in positive {
        if !(v.is_finite() && v > 0.0) {
            return Err(key_err(
                path,
                format!("structure.{key}"),
                format!("{v}: expected a number > 0"),
            ));
        }
        check_range(&structure_range(key), v)
            .map_err(|m| key_err(path, format!("structure.{key}"), m))?;
    }
    for (key, v, of, of_name) in [
        ("length_x_m", s.length_x_m, s.module_m, "module_m"),
        ("length_y_m", s.length_y_m, s.module_m, "module_m"),
        ("main_tee_spacing_m", s.main_tee_spacing_m, s.module_m, "module_m"),
    ] {
        if !is_multiple(v, of) {
            return Err(key_err(
                path,
                format!("structure.{key}"),
                format!("{v}: expected a multiple of {of_name} = {of}"),
            ));
        }
    }
    let offset = s.hanger_offset_m;
    let on_module = offset == 0.0 || is_multiple(offset, s.module_m);
    if !(offset >= 0.0 && offset < s.hanger_spacing_m && on_module) {
        return Err(key_err(
            path,
            "structure.hanger_offset_m",
            format!(
                "{offset}: expected a multiple of module_m = {} from 0 to below hanger_spacing_m = {}",
                s.module_m, s.hanger_spacing_m
            ),
        ));
    }
    if !(s.layers == 1 || s.layers == 2) {
        return Err(key_err(path, "structure.layers", format!("{}: expected 1 or 2", s.layers)));
    }
    match (s.boundary, s.nominal_gap_mm) {
        (Boundary::Fixed, _) => Ok(()),
        (b, None) => Err(key_err(
            path,
            "structure.nominal_gap_mm",
            format!("missing: required when boundary = {:?}", b.as_str()),
        )),
        (_, Some(g)) if !(g.is_finite() && g >= 0.0) => {
            Err(key_err(path, "structure.nominal_gap_mm", format!("{g}: expected a gap >= 0 mm")))
        }
        (_, Some(g)) => {
            check_range(&GAP_MM, g).map_err(|m| key_err(path, "structure.nominal_gap_mm", m))
        }
    }
}

fn check_sensors(m: &Manifest, path: &Path) -> Result<(), BundleError> {
    if m.sensors.is_empty() {
        return Err(key_err(path, "sensors", "expected at least one [[sensors]] table"));
    }
    let (lx, ly) = (m.structure.length_x_m, m.structure.length_y_m);
    let mut seen = HashSet::new();
    for (i, s) in m.sensors.iter().enumerate() {
        let at = |k: &str| format!("sensors[{i}].{k}");
        if !valid_id(&s.id) {
            return Err(key_err(path, at("id"), format!("{:?}: expected [A-Za-z0-9_.-]+", s.id)));
        }
        if s.id == "t" {
            return Err(key_err(path, at("id"), "\"t\" is the time column; choose another id"));
        }
        if !seen.insert(s.id.as_str()) {
            return Err(key_err(path, at("id"), format!("{:?} is used twice", s.id)));
        }
        if !(s.x_m.is_finite() && (0.0..=lx).contains(&s.x_m)) {
            return Err(key_err(
                path,
                at("x_m"),
                format!("x = {} m lies outside the ceiling (0 to {lx} m)", s.x_m),
            ));
        }
        if !(s.y_m.is_finite() && (0.0..=ly).contains(&s.y_m)) {
            return Err(key_err(
                path,
                at("y_m"),
                format!("y = {} m lies outside the ceiling (0 to {ly} m)", s.y_m),
            ));
        }
        let ok = match s.kind {
            SensorKind::Acceleration => matches!(s.units, SensorUnits::MPerS2 | SensorUnits::G),
            SensorKind::Displacement => matches!(s.units, SensorUnits::M | SensorUnits::Mm),
        };
        if !ok {
            let want = if s.kind == SensorKind::Acceleration {
                "\"m/s2\" or \"g\""
            } else {
                "\"m\" or \"mm\""
            };
            return Err(key_err(
                path,
                at("units"),
                format!("{:?} for a {} sensor: expected {want}", s.units.as_str(), s.kind.as_str()),
            ));
        }
    }
    Ok(())
}

fn check_runs(m: &Manifest, dir: &Path, path: &Path) -> Result<(), BundleError> {
    if m.runs.is_empty() {
        return Err(key_err(path, "runs", "expected at least one [[runs]] table"));
    }
    let mut seen = HashSet::new();
    for (i, r) in m.runs.iter().enumerate() {
        let at = |k: &str| format!("runs[{i}].{k}");
        if !valid_id(&r.id) {
            return Err(key_err(path, at("id"), format!("{:?}: expected [A-Za-z0-9_.-]+", r.id)));
        }
        if !seen.insert(r.id.as_str()) {
            return Err(key_err(path, at("id"), format!("{:?} is used twice", r.id)));
        }
        if r.input_x.is_none() && r.input_y.is_none() {
            return Err(key_err(
                path,
                at("input_x"),
                "missing: a run needs input_x, input_y or both",
            ));
        }
        for (k, col) in [("input_x", &r.input_x), ("input_y", &r.input_y)] {
            if let Some(c) = col {
                if c == "t" || m.sensors.iter().any(|s| &s.id == c) || c.is_empty() {
                    return Err(key_err(
                        path,
                        at(k),
                        format!("{c:?}: expected a column name other than t and the sensor ids"),
                    ));
                }
            }
        }
        if r.input_x.is_some() && r.input_x == r.input_y {
            return Err(key_err(path, at("input_y"), "names the same column as input_x"));
        }
        run_path(dir, &r.file)
            .map_err(|msg| key_err(path, at("file"), format!("{:?}: {msg}", r.file)))?;
    }
    Ok(())
}

/// Resolves a run file inside the bundle; refuses absolute paths, `..`,
/// missing files, links out of the bundle and anything but a regular file.
pub(super) fn run_path(dir: &Path, file: &str) -> Result<PathBuf, String> {
    confined(dir, file)
}
