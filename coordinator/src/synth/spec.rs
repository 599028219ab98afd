//! The synthetic-campaign file (`ceilfarm synth SPEC.toml`): the specimen
//! and sensors as a bundle states them, the runs to simulate, the true
//! parameter values, an optional hidden effect with its strength, and the
//! sensor imperfections (noise, offsets, missing readings).

use crate::bundle::{InputUnits, RunRole, Sensor, Structure};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A whole synthetic campaign.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SynthSpec {
    /// Bundle name, `[A-Za-z0-9_.-]+`.
    pub name: String,
    /// Free text copied to the bundle.
    #[serde(default)]
    pub description: Option<String>,
    /// Seed of every random draw (noise, white-noise inputs, missing readings).
    #[serde(default)]
    pub seed: u64,
    /// The specimen.
    pub structure: Structure,
    /// Sensors, as in `bundle.toml`.
    pub sensors: Vec<Sensor>,
    /// Runs to simulate.
    pub runs: Vec<SynthRun>,
    /// True parameter values.
    #[serde(default)]
    pub truth: Truth,
    /// Hidden effect (default: none).
    #[serde(default)]
    pub hidden: Hidden,
    /// Sensor imperfections.
    #[serde(default)]
    pub noise: Noise,
    /// `modal.csv` to write (omitted when absent).
    #[serde(default)]
    pub modal: Option<ModalOut>,
}

/// Kind of base input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Excitation {
    /// Exponential sine sweep (seed: 6 → 0.8 Hz), cosine ramps.
    SineSweep,
    /// Gaussian white noise, band-limited.
    WhiteNoise,
    /// A record file: header, then `t,a` rows (units `record_units`).
    Record,
}

/// Shaking direction (x, y or the same input in both).
pub use worker::ceiling::excitation::Shaking;

/// One run to simulate.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SynthRun {
    /// Run id.
    pub id: String,
    /// Input kind.
    pub excitation: Excitation,
    /// Direction.
    pub direction: Shaking,
    /// Peak input acceleration (g); a record is scaled to it when given.
    #[serde(default)]
    pub pga_g: Option<f64>,
    /// Duration (s) of a sweep or white noise.
    #[serde(default = "thirty")]
    pub duration_s: f64,
    /// Sampling rate (Hz).
    #[serde(default = "two_hundred")]
    pub sample_rate_hz: f64,
    /// Sweep start frequency (Hz).
    #[serde(default = "six")]
    pub f_start_hz: f64,
    /// Sweep end frequency (Hz).
    #[serde(default = "zero_eight")]
    pub f_end_hz: f64,
    /// White-noise band (Hz).
    #[serde(default = "band")]
    pub band_hz: [f64; 2],
    /// Record file (relative to the spec file).
    #[serde(default)]
    pub record: Option<PathBuf>,
    /// Units of the record's acceleration column.
    #[serde(default = "g_units")]
    pub record_units: InputUnits,
    /// Units the bundle writes the input in.
    #[serde(default = "g_units")]
    pub input_units: InputUnits,
    /// Role in the bundle.
    #[serde(default)]
    pub role: Option<RunRole>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
}

fn thirty() -> f64 {
    30.0
}
fn two_hundred() -> f64 {
    200.0
}
fn six() -> f64 {
    6.0
}
fn zero_eight() -> f64 {
    0.8
}
fn band() -> [f64; 2] {
    [0.5, 20.0]
}
fn g_units() -> InputUnits {
    InputUnits::G
}

/// True parameter values: Table 6.1 names (else prior mid-points) and damping.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Truth {
    /// Rayleigh damping ratio on the first x and y modes.
    #[serde(default = "five_percent")]
    pub damping_ratio: f64,
    /// The damping's share on the mass term (Rayleigh α and β scaled by
    /// 2·share and 2·(1 − share); 0.5: the pair on the first x and y modes).
    #[serde(default = "even_share")]
    pub damping_mass_share: f64,
    /// Parameter values by name.
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
}

impl Default for Truth {
    fn default() -> Self {
        Truth { damping_ratio: 0.05, damping_mass_share: even_share(), parameters: BTreeMap::new() }
    }
}

fn five_percent() -> f64 {
    0.05
}

fn even_share() -> f64 {
    crate::diagnose::damping_share::SEED_PAIR_SHARE
}

/// Strength of a hidden effect, set from the baseline's own demand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Strength {
    /// Barely reached in the strongest run.
    Weak,
    /// Clearly present in the strongest run.
    #[default]
    Moderate,
    /// Dominant.
    Strong,
}

/// The hidden effect.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Hidden {
    /// `none`, `perimeter-pounding`, `perimeter-friction`, `connection-hysteresis`.
    #[serde(default)]
    pub effect: Option<String>,
    /// Strength preset (ignored for parameters given explicitly).
    #[serde(default)]
    pub strength: Strength,
    /// Explicit values of the effect's parameters (e.g. `gap_ratio`).
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
}

/// Sensor imperfections.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Noise {
    /// White noise on accelerations, RMS (m/s²).
    #[serde(default)]
    pub accel_rms_m_s2: f64,
    /// White noise on displacements, RMS (mm).
    #[serde(default)]
    pub disp_rms_mm: f64,
    /// Standard deviation of a constant offset per sensor and run (m/s²).
    #[serde(default)]
    pub accel_offset_m_s2: f64,
    /// Standard deviation of a constant offset per sensor and run (mm).
    #[serde(default)]
    pub disp_offset_mm: f64,
    /// Fraction of sensor readings left empty.
    #[serde(default)]
    pub missing_fraction: f64,
}

impl Default for Noise {
    fn default() -> Self {
        Noise {
            accel_rms_m_s2: 0.0,
            disp_rms_mm: 0.0,
            accel_offset_m_s2: 0.0,
            disp_offset_mm: 0.0,
            missing_fraction: 0.0,
        }
    }
}

/// `modal.csv` contents: the true model's lowest modes with noise.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModalOut {
    /// Modes written.
    pub modes: usize,
    /// One-sigma noise added to each frequency and written as std_hz (Hz).
    #[serde(default)]
    pub std_hz: f64,
}

/// Why a synthetic-campaign file is refused.
#[derive(Debug, thiserror::Error)]
pub enum SynthSpecError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// TOML syntax, an unknown key, or a value of the wrong type.
    #[error("{path}: {message}")]
    Toml {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A value out of range.
    #[error("{path}: {key} = {value}: {expected}")]
    Value {
        /// The file.
        path: PathBuf,
        /// The key.
        key: String,
        /// The value as written.
        value: String,
        /// What was expected.
        expected: String,
    },
}

impl SynthSpec {
    /// Reads and checks a campaign file.
    pub fn from_file(path: &Path) -> Result<Self, SynthSpecError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| SynthSpecError::Io { path: path.into(), source })?;
        let spec: SynthSpec = toml::from_str(&text)
            .map_err(|e| SynthSpecError::Toml { path: path.into(), message: e.to_string() })?;
        spec.check(path)?;
        Ok(spec)
    }

    fn check(&self, path: &Path) -> Result<(), SynthSpecError> {
        let bad = |key: String, value: String, expected: &str| SynthSpecError::Value {
            path: path.into(),
            key,
            value,
            expected: expected.into(),
        };
        if self.runs.is_empty() {
            return Err(bad("runs".into(), "[]".into(), "at least one [[runs]] table"));
        }
        if self.sensors.is_empty() {
            return Err(bad("sensors".into(), "[]".into(), "at least one [[sensors]] table"));
        }
        for r in &self.runs {
            let k = |name: &str| format!("runs.{}.{name}", r.id);
            if !(r.duration_s > 0.0 && r.duration_s <= 3600.0) {
                return Err(bad(k("duration_s"), r.duration_s.to_string(), "0 < duration <= 3600"));
            }
            if !(r.sample_rate_hz >= 10.0 && r.sample_rate_hz <= 5000.0) {
                let v = r.sample_rate_hz.to_string();
                return Err(bad(k("sample_rate_hz"), v, "10 to 5000 Hz"));
            }
            if let Some(p) = r.pga_g {
                if !(p > 0.0 && p <= 3.0) {
                    return Err(bad(k("pga_g"), p.to_string(), "0 < pga <= 3 g"));
                }
            }
            if r.excitation != Excitation::Record && r.pga_g.is_none() {
                return Err(bad(k("pga_g"), "missing".into(), "a peak acceleration in g"));
            }
            if r.excitation == Excitation::Record && r.record.is_none() {
                return Err(bad(k("record"), "missing".into(), "a record file for a record run"));
            }
            if !(r.band_hz[0] > 0.0 && r.band_hz[1] > r.band_hz[0]) {
                let v = format!("{:?}", r.band_hz);
                return Err(bad(k("band_hz"), v, "[low, high] with 0 < low < high"));
            }
        }
        let n = &self.noise;
        if !(0.0..0.5).contains(&n.missing_fraction) {
            let v = n.missing_fraction.to_string();
            return Err(bad("noise.missing_fraction".into(), v, "0 <= fraction < 0.5"));
        }
        if !(self.truth.damping_ratio > 0.0 && self.truth.damping_ratio < 0.5) {
            let v = self.truth.damping_ratio.to_string();
            return Err(bad("truth.damping_ratio".into(), v, "0 < ratio < 0.5"));
        }
        if !(0.0..=1.0).contains(&self.truth.damping_mass_share) {
            let v = self.truth.damping_mass_share.to_string();
            return Err(bad("truth.damping_mass_share".into(), v, "0 <= share <= 1"));
        }
        Ok(())
    }
}
