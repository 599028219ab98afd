//! Measured-data bundles, format `ceiling-measured/1`: how shaking-table
//! measurements reach ceilfarm (spec: `shared/spec/measured-bundle.md`).
//!
//! [`read_bundle`] checks `bundle.toml`, every run file and `modal.csv`, and
//! converts units on read: accelerations to m/s², displacements to mm.
//! Every refusal names the file, the line or key, and what was expected;
//! hostile input (huge files or lines, NUL bytes) stops with an error within
//! fixed memory bounds ([`Limits`]).

mod error;
mod files;
mod manifest;
mod modal;
mod ranges;
mod runfile;
mod write;

pub use error::BundleError;
pub use manifest::{
    Boundary, Direction, InputUnits, Manifest, RunMeta, RunRole, Sensor, SensorKind, SensorUnits,
    Structure,
};
pub use modal::ModalEntry;
pub use runfile::{read_run, RunData};
pub use write::write_bundle;

use std::path::{Path, PathBuf};

/// Format string every bundle declares.
pub const FORMAT: &str = "ceiling-measured/1";

/// Default [`Limits::max_values`]: 32 Mi numbers, 256 MiB of samples.
pub const MAX_VALUES: u64 = 32 << 20;

/// Size limits that keep a hostile bundle from exhausting memory.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Largest accepted file (bytes).
    pub max_file_bytes: u64,
    /// Longest accepted line (bytes).
    pub max_line_bytes: usize,
    /// Most fields on one line.
    pub max_fields: usize,
    /// Most data rows in one run file.
    pub max_rows: usize,
    /// Most numbers held from all run files of one bundle together (8
    /// bytes each), counted per run, so one large file named by many runs
    /// is bounded too.
    pub max_values: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_file_bytes: 2 << 30,
            max_line_bytes: 1 << 20,
            max_fields: 4096,
            max_rows: 20_000_000,
            max_values: MAX_VALUES,
        }
    }
}

/// A checked bundle: the manifest, every run's data, and the modal table.
#[derive(Debug, Clone)]
pub struct Bundle {
    /// Directory it was read from.
    pub dir: PathBuf,
    /// `bundle.toml`, checked.
    pub manifest: Manifest,
    /// Run data in manifest order.
    pub runs: Vec<RunData>,
    /// `modal.csv`, if present.
    pub modal: Option<Vec<ModalEntry>>,
    /// The specimen's linear form as a diagnosis's linear stage identified
    /// it (FE parameter or solver option, value), held by every evaluation
    /// after that stage; empty as read (the generator's defaults).
    pub linear_form: Vec<(&'static str, f64)>,
}

/// Reads and checks a whole bundle directory.
pub fn read_bundle(dir: &Path) -> Result<Bundle, BundleError> {
    read_bundle_with(dir, &Limits::default())
}

/// As [`read_bundle`], with explicit limits.
pub fn read_bundle_with(dir: &Path, limits: &Limits) -> Result<Bundle, BundleError> {
    let manifest = manifest::read_manifest(dir, limits)?;
    let mut left = *limits;
    let mut runs = Vec::with_capacity(manifest.runs.len());
    for r in &manifest.runs {
        let run = read_run(dir, &manifest, r, &left)?;
        left.max_values = left.max_values.saturating_sub(run.n_values());
        runs.push(run);
    }
    let modal_path = dir.join("modal.csv");
    let modal = if std::fs::symlink_metadata(&modal_path).is_ok() {
        let path = files::confined(dir, "modal.csv")
            .map_err(|message| BundleError::File { path: modal_path, message })?;
        Some(modal::read_modal(&path, limits)?)
    } else {
        None
    };
    Ok(Bundle { dir: dir.to_path_buf(), manifest, runs, modal, linear_form: Vec::new() })
}

impl Bundle {
    /// A short human summary: specimen, sensors, runs with durations.
    pub fn summary(&self) -> String {
        let m = &self.manifest;
        let s = &m.structure;
        let mut layout = String::new();
        if s.wall_members {
            layout += ", members on the wall lines";
        }
        if s.hanger_offset_m > 0.0 {
            layout += &format!(", first row of rods {} m from y = 0", s.hanger_offset_m);
        }
        let mut out = format!(
            "bundle {} ({}):\n  specimen {} m x {} m, module {} m, {} layer(s), boundary {}, gap {}{}\n  {} sensors:",
            m.name,
            self.dir.display(),
            s.length_x_m,
            s.length_y_m,
            s.module_m,
            s.layers,
            s.boundary.as_str(),
            s.nominal_gap_mm.map(|g| format!("{g} mm")).unwrap_or_else(|| "none".into()),
            layout,
            m.sensors.len(),
        );
        for sensor in &m.sensors {
            out += &format!(
                " {}({} {} at {}, {})",
                sensor.id,
                sensor.kind.as_str(),
                sensor.direction.as_str(),
                sensor.x_m,
                sensor.y_m
            );
        }
        out += &format!("\n  {} runs:", self.runs.len());
        for (meta, run) in m.runs.iter().zip(&self.runs) {
            out += &format!(
                "\n    {}: {} samples at {:.1} Hz, {:.2} s, {} sensor columns, role {}",
                meta.id,
                run.n_samples(),
                1.0 / run.dt_s,
                run.duration_s(),
                run.sensors.len(),
                meta.role.map(|r| r.as_str()).unwrap_or("unassigned"),
            );
        }
        if let Some(modal) = &self.modal {
            let f: Vec<String> = modal.iter().map(|e| format!("{}", e.freq_hz)).collect();
            out += &format!("\n  modal: {} Hz", f.join(", "));
        }
        out
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod tests_inputs;
