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
    /// The base excitation of a one-component run.
    #[serde(default)]
    pub excitation: Option<ExcitationSpec>,
    /// The base excitations, one per DOF, of a run with several components
    /// (a file may give `excitation` as well when there is one: the same).
    #[serde(default)]
    pub excitations: Vec<ExcitationSpec>,
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

    /// The base excitations: `excitations`, else the one `excitation`.
    pub fn components(&self) -> &[ExcitationSpec] {
        if self.excitations.is_empty() {
            self.excitation.as_slice()
        } else {
            &self.excitations
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
        self.check_excitations()?;
        let (g, b) = (self.integrator.gamma, self.integrator.beta);
        if !(g > 0.0 && b > 0.0) {
            return bad("integrator beta", b);
        }
        if self.output_every_n_steps == 0 {
            return bad("output_every_n_steps", 0.0);
        }
        Ok(())
    }

    /// At least one excitation, each a uniform base acceleration with a
    /// positive step on its own DOF 1..6; `excitation` beside
    /// `excitations` only as their single entry.
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the check
    fn check_excitations(&self) -> Result<(), TransientError> {
        let spec = |message: String| Err(TransientError::Spec { message });
        let list = self.components();
        if list.is_empty() {
            return spec("missing field `excitation` (or `excitations`)".into());
        }
        if let Some(one) = &self.excitation {
            if !self.excitations.is_empty()
                && self.excitations.as_slice() != std::slice::from_ref(one)
            {
                return spec("`excitation` and `excitations` differ: expected one of them, or `excitation` equal to the single entry of `excitations`".into());
            }
        }
        for (k, e) in list.iter().enumerate() {
            let at = if self.excitations.is_empty() {
                "excitation".to_string()
            } else {
                format!("excitations[{k}]")
            };
            if !(e.dt_s > 0.0) {
                return spec(format!("{at}.dt = {} is out of range", e.dt_s));
            }
            if !(1..=6).contains(&e.dof) {
                return spec(format!("{at}.dof = {} is out of range", e.dof));
            }
            if list[..k].iter().any(|o| o.dof == e.dof) {
                return spec(format!(
                    "{at}.dof = {}: expected each DOF in one excitation only",
                    e.dof
                ));
            }
            if e.kind != "uniform_base_acceleration" {
                return spec(format!("{at} type {:?}: expected uniform_base_acceleration", e.kind));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn exc(dof: u8) -> Value {
        json!({"type": "uniform_base_acceleration", "dof": dof, "record_csv": "r.csv", "dt": 0.01, "npts": 3})
    }

    /// A block with the given excitation keys.
    fn block(keys: Value) -> Map<String, Value> {
        let mut m = json!({"integrator": {"type": "Newmark", "gamma": 0.5, "beta": 0.25},
                           "dt": 0.01, "n_steps": 2});
        m.as_object_mut().unwrap().extend(keys.as_object().unwrap().clone());
        m.as_object().unwrap().clone()
    }

    fn refusal(keys: Value) -> String {
        TransientSpec::from_map(&block(keys)).unwrap_err().to_string()
    }

    #[test]
    fn one_excitation_or_a_list_of_them() {
        let one = TransientSpec::from_map(&block(json!({"excitation": exc(1)}))).unwrap();
        assert_eq!(one.components().len(), 1);
        let two =
            TransientSpec::from_map(&block(json!({"excitations": [exc(1), exc(2)]}))).unwrap();
        assert_eq!(two.components().iter().map(|e| e.dof).collect::<Vec<_>>(), [1, 2]);
        let both = json!({"excitation": exc(1), "excitations": [exc(1)]});
        assert_eq!(TransientSpec::from_map(&block(both)).unwrap().components().len(), 1);
    }

    #[test]
    fn bad_excitations_are_refused_by_key() {
        assert!(refusal(json!({})).contains("missing field `excitation` (or `excitations`)"));
        let differ = json!({"excitation": exc(1), "excitations": [exc(2)]});
        assert!(refusal(differ).contains("`excitation` and `excitations` differ"));
        let twice = json!({"excitations": [exc(1), exc(1)]});
        assert!(refusal(twice)
            .contains("excitations[1].dof = 1: expected each DOF in one excitation only"));
        let mut bad = exc(7);
        assert!(refusal(json!({"excitation": bad.clone()}))
            .contains("excitation.dof = 7 is out of range"));
        bad["dof"] = json!(1);
        bad["type"] = json!("imposed_displacement");
        let msg = refusal(json!({"excitations": [exc(2), bad]}));
        assert!(msg.contains("excitations[1] type \"imposed_displacement\""), "{msg}");
    }
}
