//! What the ceiling model kinds share: the specimen from a `spec` file or
//! inlined `spec_toml`, and the parameter values a run starts from (the
//! variant's prior mid-points, `fixed` values, study names checked).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use fe::generator::{CeilingSpec, Parameters};

/// The specimen of exactly one of `spec` (file) or `spec_toml` (text).
pub fn read_spec(
    spec: &Option<PathBuf>,
    spec_toml: &Option<String>,
) -> Result<CeilingSpec, String> {
    let spec = match (spec, spec_toml) {
        (None, Some(text)) => CeilingSpec::from_toml_str(text, Path::new("[model] spec_toml")),
        (Some(path), None) => CeilingSpec::from_toml_file(path),
        _ => return Err("expected exactly one of `spec` (file) or `spec_toml`".into()),
    };
    spec.map_err(|e| e.to_string())
}

/// Prior mid-points of the specimen's variant with `fixed` applied; every
/// study parameter in `names` must be one the variant accepts (`hint` is
/// appended to the refusal).
pub fn base_parameters<'a>(
    spec: &CeilingSpec,
    fixed: &BTreeMap<String, f64>,
    names: impl IntoIterator<Item = &'a String>,
    hint: &str,
) -> Result<Parameters, String> {
    let mut base = Parameters::prior_midpoints_for(spec);
    for (name, value) in fixed {
        base.set(name, *value).map_err(|e| format!("fixed: {e}"))?;
    }
    for name in names {
        let mid = base.get(name);
        let mut probe = base.clone();
        probe
            .set(name, if mid.is_finite() { mid } else { 1.0 })
            .map_err(|e| format!("{e}{hint}"))?;
    }
    Ok(base)
}
