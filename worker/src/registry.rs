//! The model registry: the study's `[model] kind` → a constructor.

use crate::ceiling::Ceiling;
use crate::ceiling_campaign::CeilingCampaign;
use crate::ceiling_modal::CeilingModal;
use crate::model::{Model, ModelError};
use crate::models::analytic::{Borehole, Ishigami, Noop, SobolG};
use crate::models::costed::Costed;
use crate::models::faults::Faults;
use crate::models::oscillator::Oscillator;
use protocol::ModelSpec;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};
use std::time::Duration;

type Constructor = fn(Value, &[String]) -> Result<Box<dyn Model>, ModelError>;

/// Every registered kind with its constructor.
const KINDS: &[(&str, Constructor)] = &[
    ("ishigami", |o, n| Ok(Box::new(Ishigami::new(options("ishigami", o)?, n)?))),
    ("sobol-g", |o, n| Ok(Box::new(SobolG::new(options("sobol-g", o)?, n)?))),
    ("borehole", |o, n| {
        options::<Empty>("borehole", o)?;
        Ok(Box::new(Borehole::new(n)?))
    }),
    ("oscillator", |o, n| Ok(Box::new(Oscillator::new(options("oscillator", o)?, n)?))),
    ("noop", |o, _| Ok(Box::new(options::<Noop>("noop", o)?))),
    ("test-faults", |o, n| Ok(Box::new(Faults::new(options("test-faults", o)?, n)?))),
    ("ceiling-modal", |o, n| Ok(Box::new(CeilingModal::new(options("ceiling-modal", o)?, n)?))),
    ("ceiling", |o, n| Ok(Box::new(Ceiling::new(options("ceiling", o)?, n)?))),
    ("ceiling-campaign", |o, n| {
        Ok(Box::new(CeilingCampaign::new(options("ceiling-campaign", o)?, n)?))
    }),
];

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Empty {}

fn options<T: DeserializeOwned>(kind: &str, v: Value) -> Result<T, ModelError> {
    serde_json::from_value(v).map_err(|e| ModelError::Invalid {
        kind: kind.into(),
        message: format!("[model] options: {e}"),
    })
}

/// Names of all registered model kinds.
pub fn kinds() -> Vec<&'static str> {
    KINDS.iter().map(|(k, _)| *k).collect()
}

/// Builds the model a spec names; `cost_ms` (any kind) adds an artificial cost per run.
pub fn build(spec: &ModelSpec) -> Result<Box<dyn Model>, ModelError> {
    let invalid = |message: String| ModelError::Invalid { kind: spec.kind.clone(), message };
    let mut opts: Map<String, Value> = if spec.options_json.trim().is_empty() {
        Map::new()
    } else {
        serde_json::from_str(&spec.options_json).map_err(|e| invalid(format!("options: {e}")))?
    };
    let cost_ms = match opts.remove("cost_ms") {
        None => 0.0,
        Some(v) => v.as_f64().filter(|c| c.is_finite() && *c >= 0.0).ok_or_else(|| {
            invalid(format!("cost_ms = {v}: expected a number of milliseconds >= 0"))
        })?,
    };
    let (_, ctor) = KINDS.iter().find(|(k, _)| *k == spec.kind).ok_or_else(|| {
        ModelError::UnknownKind { kind: spec.kind.clone(), known: kinds().join(", ") }
    })?;
    let model = ctor(Value::Object(opts), &spec.param_names)?;
    Ok(if cost_ms > 0.0 {
        Box::new(Costed { inner: model, cost: Duration::from_secs_f64(cost_ms / 1000.0) })
    } else {
        model
    })
}

/// Option keys that name a file on the machine that reads them (a
/// specimen's `spec`, a record's `file`); the coordinator sends their
/// contents inline (`spec_toml`, `csv`).
const FILE_KEYS: [&str; 2] = ["spec", "file"];

/// Builds the model of a spec that came from another process: one whose
/// options name a local file (a [`FILE_KEYS`] key at any depth) is refused,
/// so no remote message makes this worker read a path of its choosing
/// (`/dev/zero`, a FIFO, `/etc/passwd`).
pub fn build_remote(spec: &ModelSpec) -> Result<Box<dyn Model>, ModelError> {
    let text = spec.options_json.trim();
    if !text.is_empty() {
        let opts: Value = serde_json::from_str(text).map_err(|e| ModelError::Invalid {
            kind: spec.kind.clone(),
            message: format!("options: {e}"),
        })?;
        if let Some(key) = file_key(&opts, "model") {
            return Err(ModelError::Invalid {
                kind: spec.kind.clone(),
                message: format!(
                    "{key}: a remote worker reads no local file (the coordinator sends its \
                     contents inline)"
                ),
            });
        }
    }
    build(spec)
}

/// The dotted name of the first option that names a file, if any.
fn file_key(v: &Value, at: &str) -> Option<String> {
    match v {
        Value::Object(map) => map.iter().find_map(|(k, v)| {
            let here = format!("{at}.{k}");
            match FILE_KEYS.contains(&k.as_str()) && !v.is_null() {
                true => Some(here),
                false => file_key(v, &here),
            }
        }),
        Value::Array(items) => {
            items.iter().enumerate().find_map(|(i, v)| file_key(v, &format!("{at}[{i}]")))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn remote_spec(kind: &str, options_json: &str) -> ModelSpec {
        ModelSpec {
            kind: kind.into(),
            options_json: options_json.into(),
            param_names: vec![],
            outputs: vec![],
        }
    }

    /// Regression (issue 56): a fake Welcome naming `spec = "/dev/zero"`
    /// made workers read until out of memory.
    #[test]
    fn a_remote_spec_naming_a_local_file_is_refused_unread() {
        let fifo = remote_spec("ceiling", r#"{"spec": "/dev/zero", "excitation": {}}"#);
        let err = build_remote(&fifo).err().expect("refused");
        assert!(err.to_string().contains("model.spec: a remote worker reads no local file"));
        let record =
            r#"{"spec_toml": "x", "excitation": {"kind": "record", "file": "/etc/passwd"}}"#;
        let err = build_remote(&remote_spec("ceiling", record)).err().expect("refused");
        assert!(err.to_string().contains("model.excitation.file"), "{err}");
        assert!(build_remote(&remote_spec("noop", "{}")).is_ok());
        assert!(build_remote(&remote_spec("noop", "")).is_ok());
    }

    fn spec(kind: &str, opts: &str, names: &[&str]) -> ModelSpec {
        ModelSpec {
            kind: kind.into(),
            options_json: opts.into(),
            param_names: names.iter().map(|s| s.to_string()).collect(),
            outputs: vec![],
        }
    }

    #[test]
    fn unknown_kind_lists_the_known_ones() {
        let err = build(&spec("nope", "{}", &[])).err().unwrap().to_string();
        assert!(err.contains("unknown model kind `nope`") && err.contains("borehole"), "{err}");
    }

    #[test]
    fn unknown_option_is_named() {
        let err = build(&spec("ishigami", r#"{"aa": 1}"#, &["x1", "x2", "x3"]))
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("unknown field `aa`"), "{err}");
    }

    #[test]
    fn missing_parameter_is_named() {
        let err = build(&spec("ishigami", "{}", &["x1", "x2"])).err().unwrap().to_string();
        assert!(err.contains("`x3`"), "{err}");
    }

    #[test]
    fn negative_cost_is_refused() {
        let err = build(&spec("noop", r#"{"cost_ms": -1}"#, &[])).err().unwrap().to_string();
        assert!(err.contains("cost_ms"), "{err}");
    }
}
