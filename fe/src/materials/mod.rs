//! Uniaxial force-deformation materials (deformation mm, force N) with the
//! OpenSees life cycle: trial deformation, then commit or revert.
//!
//! [`MaterialSpec`] is the JSON object of the `ceiling-fe-model` format's
//! `materials` list (without its `id`); [`UniaxialMaterial`] is the law in
//! use, with its state.

use serde::{Deserialize, Serialize};

mod bouc_wen;
pub mod driver;
mod elastic;
mod gap;
mod impact;
mod pinching4;
mod pinching4_path;
mod pivot;
mod skeleton;
mod steel01;
mod takeda;

pub use bouc_wen::{BoucWen, BoucWenParams};
pub use driver::{drive, read_protocol, write_response, DriverError};
pub use elastic::Elastic;
pub use gap::Gap;
pub use impact::{Impact, ImpactParams};
pub use pinching4::{Backbone, DamageRule, DamageType, Pinching4, PinchingSide};
pub use pivot::{Pivot, PivotSpec};
pub use skeleton::MAX_POINTS as SKELETON_MAX_POINTS;
pub use steel01::{Steel01, Steel01Params};
pub use takeda::{Takeda, TakedaSpec};

/// Why a material cannot be built or stepped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// A parameter is out of its valid range.
    #[error("{material}: {key} = {value}: {expected}")]
    Parameter {
        /// Material type name.
        material: &'static str,
        /// Offending key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// What was expected.
        expected: &'static str,
    },
    /// A trial deformation that is not a finite number.
    #[error("non-finite trial deformation {0}")]
    NonFinite(f64),
    /// An implicit update did not converge.
    #[error("{material}: local Newton did not converge at deformation {d_mm} mm")]
    NoConvergence {
        /// Material type name.
        material: &'static str,
        /// Trial deformation (mm).
        d_mm: f64,
    },
}

/// Rejects NaN and infinite trial deformations.
#[inline]
pub(crate) fn check_finite(d: f64) -> Result<(), MaterialError> {
    if d.is_finite() {
        Ok(())
    } else {
        Err(MaterialError::NonFinite(d))
    }
}

/// The stiffer first slope of a skeleton given as JSON arrays (0 if empty).
fn skeleton_k0(e_pd: &[f64], e_pf: &[f64], e_nd: &[f64], e_nf: &[f64]) -> f64 {
    let slope = |d: &[f64], f: &[f64]| match (d.first(), f.first()) {
        (Some(d), Some(f)) => f / d,
        _ => 0.0,
    };
    slope(e_pd, e_pf).max(slope(e_nd, e_nf))
}

/// Builds the material a spec describes, in its virgin state.
pub fn build(spec: &MaterialSpec) -> Result<Box<dyn UniaxialMaterial>, MaterialError> {
    Ok(match spec {
        MaterialSpec::Elastic { k } => Box::new(Elastic::new(*k)?),
        MaterialSpec::Steel01 { fy, e0, b } => {
            Box::new(Steel01::new(Steel01Params { fy: *fy, e0: *e0, b: *b })?)
        }
        MaterialSpec::Gap { k, gap } => Box::new(Gap::new(*k, *gap)?),
        MaterialSpec::Impact { k1, k2, dy, gap } => {
            Box::new(Impact::new(ImpactParams { k1: *k1, k2: *k2, dy: *dy, gap: *gap })?)
        }
        MaterialSpec::Pinching4(p) => Box::new(Pinching4::new(p)?),
        MaterialSpec::BoucWen { fy, dy, exponent, ratio } => {
            Box::new(BoucWen::new(BoucWenParams {
                fy: *fy,
                dy: *dy,
                exponent: *exponent,
                ratio: *ratio,
            })?)
        }
        MaterialSpec::Takeda(p) => Box::new(Takeda::new(p)?),
        MaterialSpec::Pivot(p) => Box::new(Pivot::new(p)?),
    })
}

/// One-dimensional force-deformation law with memory (OpenSees `UniaxialMaterial`).
pub trait UniaxialMaterial: Send {
    /// Sets the trial deformation (mm); committed history is untouched.
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError>;
    /// Sets the trial deformation and returns (force N, tangent N/mm).
    fn trial(&mut self, d: f64) -> Result<(f64, f64), MaterialError> {
        self.set_trial(d)?;
        Ok((self.force(), self.tangent()))
    }
    /// Force (N) at the trial state.
    fn force(&self) -> f64;
    /// Tangent stiffness (N/mm) at the trial state.
    fn tangent(&self) -> f64;
    /// Stiffness (N/mm) of the virgin material at zero deformation.
    fn initial_tangent(&self) -> f64;
    /// Makes the trial state the committed state.
    fn commit(&mut self);
    /// Discards the trial state, returning to the last committed one.
    fn revert(&mut self);
    /// A fresh copy in the virgin state, with the same parameters.
    fn boxed_clone(&self) -> Box<dyn UniaxialMaterial>;
}

/// A material definition as the JSON model format writes it (`"type"` tag).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type")]
pub enum MaterialSpec {
    /// f = k d.
    Elastic {
        /// Stiffness (N/mm).
        k: f64,
    },
    /// Bilinear kinematic hardening (OpenSees Steel01, no isotropic hardening).
    Steel01 {
        /// Yield force (N).
        #[serde(rename = "Fy")]
        fy: f64,
        /// Initial stiffness (N/mm).
        #[serde(rename = "E0")]
        e0: f64,
        /// Post-yield stiffness ratio.
        b: f64,
    },
    /// Compression-only gap, seed eq. 5.4: f = k (d + gap) when d + gap <= 0.
    Gap {
        /// Contact stiffness (N/mm).
        k: f64,
        /// Opening (mm, >= 0).
        gap: f64,
    },
    /// OpenSees ImpactMaterial (Muthukumar/Nielson bilinear contact).
    Impact {
        /// Initial contact stiffness (N/mm).
        #[serde(rename = "K1")]
        k1: f64,
        /// Post-yield contact stiffness (N/mm).
        #[serde(rename = "K2")]
        k2: f64,
        /// Yield deformation beyond closure (mm, > 0).
        dy: f64,
        /// Opening (mm, > 0).
        gap: f64,
    },
    /// Lowes–Altoontash Pinching4 as OpenSees implements it.
    Pinching4(Box<Pinching4Spec>),
    /// Wen plastic link (SAP2000 "Plastic (Wen)"): f = r k d + (1 - r) Fy z.
    BoucWen {
        /// Yield force (N, > 0).
        #[serde(rename = "Fy")]
        fy: f64,
        /// Yield deformation (mm, > 0); elastic stiffness k = Fy / dy.
        dy: f64,
        /// Yield exponent (>= 1; large values give a sharp corner).
        exponent: f64,
        /// Post-yield stiffness ratio r (default 0: rigid-plastic friction).
        #[serde(default)]
        ratio: f64,
    },
    /// Takeda on a multi-linear skeleton (Otani 1974 unloading rule).
    Takeda(Box<TakedaSpec>),
    /// Pivot hysteresis (Dowell, Seible & Wilson 1998; SAP2000 Pivot link).
    Pivot(Box<PivotSpec>),
}

/// Pinching4 parameters, named as in the JSON format.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(non_snake_case)]
pub struct Pinching4Spec {
    /// Positive backbone forces (N).
    pub ePf: [f64; 4],
    /// Positive backbone deformations (mm).
    pub ePd: [f64; 4],
    /// Negative backbone forces (N, negative numbers).
    pub eNf: [f64; 4],
    /// Negative backbone deformations (mm, negative numbers).
    pub eNd: [f64; 4],
    /// Reloading deformation ratio, positive side.
    pub rDispP: f64,
    /// Reloading force ratio, positive side.
    pub rForceP: f64,
    /// Unloading force ratio, positive side.
    pub uForceP: f64,
    /// Reloading deformation ratio, negative side.
    pub rDispN: f64,
    /// Reloading force ratio, negative side.
    pub rForceN: f64,
    /// Unloading force ratio, negative side.
    pub uForceN: f64,
    /// Unloading stiffness degradation coefficients.
    pub gK: [f64; 4],
    /// Unloading stiffness degradation limit.
    pub gKLim: f64,
    /// Reloading stiffness degradation coefficients.
    pub gD: [f64; 4],
    /// Reloading stiffness degradation limit.
    pub gDLim: f64,
    /// Strength degradation coefficients.
    pub gF: [f64; 4],
    /// Strength degradation limit.
    pub gFLim: f64,
    /// Energy dissipation factor.
    pub gE: f64,
    /// Damage type: `"cycle"` or `"energy"`.
    pub dmgType: String,
}

impl MaterialSpec {
    /// Type name as the JSON writes it.
    pub fn type_name(&self) -> &'static str {
        match self {
            MaterialSpec::Elastic { .. } => "Elastic",
            MaterialSpec::Steel01 { .. } => "Steel01",
            MaterialSpec::Gap { .. } => "Gap",
            MaterialSpec::Impact { .. } => "Impact",
            MaterialSpec::Pinching4(_) => "Pinching4",
            MaterialSpec::BoucWen { .. } => "BoucWen",
            MaterialSpec::Takeda(_) => "Takeda",
            MaterialSpec::Pivot(_) => "Pivot",
        }
    }

    /// Stiffness (N/mm) at zero deformation in the virgin state, as the
    /// eigen analysis of the format uses it (gaps open: 0).
    pub fn initial_tangent(&self) -> f64 {
        match self {
            MaterialSpec::Elastic { k } => *k,
            MaterialSpec::Steel01 { e0, .. } => *e0,
            MaterialSpec::Gap { k, gap } => {
                if *gap > 0.0 {
                    0.0
                } else {
                    *k
                }
            }
            MaterialSpec::Impact { .. } => 0.0,
            // OpenSees takes the stiffer of the two first backbone slopes.
            MaterialSpec::Pinching4(p) => (p.ePf[0] / p.ePd[0]).max(p.eNf[0] / p.eNd[0]),
            MaterialSpec::BoucWen { fy, dy, .. } => fy / dy,
            MaterialSpec::Takeda(p) => skeleton_k0(&p.ePd, &p.ePf, &p.eNd, &p.eNf),
            MaterialSpec::Pivot(p) => skeleton_k0(&p.ePd, &p.ePf, &p.eNd, &p.eNf),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_format_objects_with_descriptive_keys() {
        let m: MaterialSpec = serde_json::from_str(
            r#"{"type": "Steel01", "Fy": 2.0, "E0": 20.0, "b": 0.05, "note": "x"}"#,
        )
        .unwrap();
        assert_eq!(m, MaterialSpec::Steel01 { fy: 2.0, e0: 20.0, b: 0.05 });
        assert_eq!(m.initial_tangent(), 20.0);
    }

    #[test]
    fn parses_the_added_types_with_their_defaults() {
        let m: MaterialSpec = serde_json::from_str(
            r#"{"id": 3, "type": "BoucWen", "Fy": 2, "dy": 0.1, "exponent": 2}"#,
        )
        .unwrap();
        assert_eq!(m, MaterialSpec::BoucWen { fy: 2.0, dy: 0.1, exponent: 2.0, ratio: 0.0 });
        assert_eq!(m.initial_tangent(), 20.0);
        let t: MaterialSpec = serde_json::from_str(
            r#"{"type": "Takeda", "ePd": [0.5, 3], "ePf": [50, 60], "eNd": [-1], "eNf": [-40]}"#,
        )
        .unwrap();
        assert_eq!(t.type_name(), "Takeda");
        let MaterialSpec::Takeda(p) = &t else { panic!("{t:?}") };
        assert_eq!(p.alpha, 0.0);
        assert_eq!(t.initial_tangent(), 100.0);
        let v: MaterialSpec = serde_json::from_str(
            r#"{"type": "Pivot", "ePd": [0.5], "ePf": [50], "eNd": [-1], "eNf": [-40],
                "alpha1": 2, "alpha2": 3, "beta1": 0.2, "beta2": 0.4}"#,
        )
        .unwrap();
        let MaterialSpec::Pivot(p) = &v else { panic!("{v:?}") };
        assert_eq!((p.alpha2, p.beta2, p.eta), (3.0, 0.4, 0.0));
        for spec in [m, t, v] {
            let mat = build(&spec).unwrap();
            assert_eq!(mat.initial_tangent(), spec.initial_tangent());
        }
    }

    #[test]
    fn build_reports_the_offending_key() {
        let err = build(&MaterialSpec::Impact { k1: 1.0, k2: 1.0, dy: 0.1, gap: -1.0 })
            .err()
            .expect("a negative gap is rejected");
        assert!(matches!(err, MaterialError::Parameter { key: "gap", .. }), "{err}");
        let s = serde_json::to_string(&MaterialSpec::BoucWen {
            fy: 1.0,
            dy: 1.0,
            exponent: 1.0,
            ratio: 0.1,
        })
        .unwrap();
        assert!(s.contains(r#""type":"BoucWen""#) && s.contains(r#""Fy":1.0"#), "{s}");
    }
}
