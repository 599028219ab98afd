//! `ceiling-modal`: the ceiling grid generated from a specimen file, its
//! lowest modes for each parameter set. Parameters are the names of seed
//! Table 6.1 (`fe::generator::PARAMETERS`, units mm², MPa, mm⁴, N/mm); those
//! not in the study sit at their prior mid-points unless `fixed` sets them.
//!
//! Outputs: `f1_hz .. fk_hz` and `dir1 .. dirk`, the direction of each
//! mode's largest effective mass (1 = x, 2 = y, 3 = z).

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::specimen::{base_parameters, read_spec};
use fe::eigen::{modal_analysis, LanczosSettings};
use fe::generator::{generate, CeilingSpec, Parameters};
use protocol::Outputs;
use serde::Deserialize;

use crate::model::{Model, ModelError, ParamSet, RunContext, RunError};

const KIND: &str = "ceiling-modal";

/// `[model]` options of `ceiling-modal`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CeilingModalOptions {
    /// The specimen TOML file (`[structure]` table), read by this worker.
    #[serde(default)]
    pub spec: Option<PathBuf>,
    /// The specimen TOML text itself (the coordinator inlines `spec` files
    /// so that workers on other machines need no copy).
    #[serde(default)]
    pub spec_toml: Option<String>,
    /// Number of modes reported (default 6).
    #[serde(default = "six")]
    pub n_modes: usize,
    /// Values for Table 6.1 parameters that are not study parameters.
    #[serde(default)]
    pub fixed: BTreeMap<String, f64>,
}

fn six() -> usize {
    6
}

/// The `ceiling-modal` model kind.
pub struct CeilingModal {
    spec: CeilingSpec,
    base: Parameters,
    n_modes: usize,
}

impl CeilingModal {
    /// Reads the specimen and checks every parameter name against Table 6.1.
    pub fn new(opts: CeilingModalOptions, names: &[String]) -> Result<Self, ModelError> {
        let invalid = |message: String| ModelError::Invalid { kind: KIND.into(), message };
        let spec = read_spec(&opts.spec, &opts.spec_toml).map_err(invalid)?;
        let base = base_parameters(&spec, &opts.fixed, names, "").map_err(invalid)?;
        if opts.n_modes == 0 {
            return Err(invalid("n_modes = 0: expected at least 1".into()));
        }
        Ok(Self { spec, base, n_modes: opts.n_modes })
    }
}

impl Model for CeilingModal {
    fn output_names(&self) -> Vec<String> {
        let f = (1..=self.n_modes).map(|k| format!("f{k}_hz"));
        f.chain((1..=self.n_modes).map(|k| format!("dir{k}"))).collect()
    }

    fn run(&self, params: &ParamSet<'_>, ctx: &RunContext) -> Result<Outputs, RunError> {
        let mut p = self.base.clone();
        for (name, value) in params.iter() {
            p.set(name, value).map_err(|e| RunError::Input(e.to_string()))?;
        }
        if ctx.cancelled() {
            return Err(RunError::Cancelled);
        }
        let model = generate(&self.spec, &p).map_err(|e| RunError::Failed(e.to_string()))?;
        let (_, res) = modal_analysis(&model, self.n_modes, &LanczosSettings::default())
            .map_err(|e| RunError::Failed(e.to_string()))?;
        let names = self.output_names();
        let dirs = (0..self.n_modes).map(|k| match res.dominant(k) {
            'x' => 1.0,
            'y' => 2.0,
            _ => 3.0,
        });
        let values: Vec<f64> = res.freq_hz.iter().copied().chain(dirs).collect();
        Ok(Outputs { scalars: names.into_iter().zip(values).collect(), histories: vec![] })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts() -> CeilingModalOptions {
        let spec =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../configs/specimens/type-c.toml");
        CeilingModalOptions {
            spec: Some(spec),
            spec_toml: None,
            n_modes: 2,
            fixed: BTreeMap::new(),
        }
    }

    #[test]
    fn stiffer_friction_raises_the_first_frequency() {
        let names = vec!["K_friction".to_string()];
        let m = CeilingModal::new(opts(), &names).unwrap();
        let run = |k: f64| {
            let v = [k];
            let out = m.run(&ParamSet::new(&names, &v).unwrap(), &RunContext::default()).unwrap();
            out.scalar("f1_hz").unwrap()
        };
        let (soft, stiff) = (run(15.0), run(25.0));
        assert!(stiff > soft && soft > 5.0, "{soft} {stiff}");
        assert_eq!(m.output_names(), ["f1_hz", "f2_hz", "dir1", "dir2"]);
    }

    #[test]
    fn unmodelled_parameter_is_refused_at_build() {
        let names = vec!["K_cc1".to_string()];
        let e = CeilingModal::new(opts(), &names).err().unwrap();
        assert!(e.to_string().contains("K_cc1"), "{e}");
    }
}
