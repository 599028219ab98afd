//! The transient `analysis` block of a `ceiling-fe-model` v1 file
//! (`MODEL_FORMAT.md`, "Transient"), parsed into typed fields.
//!
//! Units: time s, acceleration mm/s² (the record CSV values times `scale`).

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::TransientError;
use crate::model::{Analysis, Model};

/// The uniform base excitation of the analysis block.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct ExcitationSpec {
    /// "uniform_base_acceleration".
    #[serde(rename = "type")]
    pub kind: String,
    /// Global DOF 1..6 of the ground acceleration.
    pub dof: u8,
    /// Record CSV, relative to the model file's folder.
    pub record_csv: String,
    /// Sample interval of the record (s).
    #[serde(rename = "dt")]
    pub dt_s: f64,
    /// Number of samples in the record.
    pub npts: usize,
    /// Factor on the CSV values.
    #[serde(default = "one")]
    pub scale: f64,
    /// SHA-256 of the record file, checked when present.
    #[serde(default)]
    pub sha256: Option<String>,
}

fn one() -> f64 {
    1.0
}

fn output_every_default() -> usize {
    1
}

/// Newmark parameters.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct IntegratorSpec {
    /// "Newmark".
    #[serde(rename = "type")]
    pub kind: IntegratorKind,
    /// γ.
    pub gamma: f64,
    /// β.
    pub beta: f64,
}

/// Integrators of format v1.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub enum IntegratorKind {
    /// Newmark-β.
    Newmark,
}

/// One recorder as the file writes it (absent fields are left out when
/// written).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct RecorderSpec {
    /// Column name (generated when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Node id (node recorders).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node: Option<u64>,
    /// Global DOF 1..6 (node recorders).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dof: Option<u8>,
    /// Spring id (element recorders).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element: Option<u64>,
    /// `disp`, `vel`, `accel_abs`, `deformation` or `force`.
    pub response: String,
}

/// A parsed transient analysis block.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct TransientSpec {
    /// Base excitation.
    pub excitation: ExcitationSpec,
    /// Time integrator.
    pub integrator: IntegratorSpec,
    /// Analysis step (s).
    #[serde(rename = "dt")]
    pub dt_s: f64,
    /// Number of steps.
    pub n_steps: usize,
    /// Recorded channels.
    #[serde(default)]
    pub recorders: Vec<RecorderSpec>,
    /// One output row every this many steps.
    #[serde(default = "output_every_default")]
    pub output_every_n_steps: usize,
}

impl TransientSpec {
    /// Parses the keys of a transient analysis block.
    pub fn from_map(map: &Map<String, Value>) -> Result<Self, TransientError> {
        let spec: TransientSpec = serde_json::from_value(Value::Object(map.clone()))
            .map_err(|e| TransientError::Spec { message: e.to_string() })?;
        spec.check()?;
        Ok(spec)
    }

    /// The transient block of a model.
    pub fn from_model(model: &Model) -> Result<Self, TransientError> {
        match &model.analysis {
            Some(Analysis::Transient(map)) => Self::from_map(map),
            _ => {
                Err(TransientError::Spec { message: "the model has no transient analysis".into() })
            }
        }
    }

    #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the check
    fn check(&self) -> Result<(), TransientError> {
        let bad = |what: &str, v: f64| {
            Err(TransientError::Spec { message: format!("{what} = {v} is out of range") })
        };
        if !(self.dt_s > 0.0 && self.dt_s.is_finite()) {
            return bad("dt", self.dt_s);
        }
        if !(self.excitation.dt_s > 0.0) {
            return bad("excitation.dt", self.excitation.dt_s);
        }
        if !(1..=6).contains(&self.excitation.dof) {
            return bad("excitation.dof", f64::from(self.excitation.dof));
        }
        if self.excitation.kind != "uniform_base_acceleration" {
            return Err(TransientError::Spec {
                message: format!(
                    "excitation type {:?}: expected uniform_base_acceleration",
                    self.excitation.kind
                ),
            });
        }
        let (g, b) = (self.integrator.gamma, self.integrator.beta);
        if !(g > 0.0 && b > 0.0) {
            return bad("integrator beta", b);
        }
        if self.output_every_n_steps == 0 {
            return bad("output_every_n_steps", 0.0);
        }
        Ok(())
    }
}
