//! Takeda hysteresis on a multi-linear skeleton (Takeda, Sozen & Nielsen
//! 1970, J. Struct. Div. ASCE 96(12)) with the unloading-stiffness rule of
//! Otani (1974), the "modified Takeda":
//!
//! * skeleton: a polyline per side whose first point is the yield point
//!   (dy, Fy), elastic stiffness k0 = Fy / dy of that side;
//! * unloading from the positive side with k_u = k0 (dy / d_max)^alpha,
//!   d_max the largest positive deformation so far (at least dy); the same
//!   on the negative side with its own values. alpha = 0 unloads at k0, the
//!   simplified Takeda of SAP2000 that the seed used for main-tee splices;
//! * after the force crosses zero, reloading heads straight for the
//!   largest previous excursion on the backbone of the other side (its
//!   yield point if it never yielded), then follows the backbone;
//! * a reversal during unloading reloads along the unloading line back to
//!   where unloading began (inner loops are elastic with k_u).
//!
//! If the zero crossing lies beyond the target excursion, the target moves
//! to one yield deformation past the crossing. The reloading line is assumed
//! no steeper than the unloading line (true for the usual skeletons).
//! Units: mm, N, N/mm.

use serde::{Deserialize, Serialize};

use super::skeleton::{PeakHistory as History, Skeleton};
use super::{check_finite, MaterialError, UniaxialMaterial};

/// Takeda parameters, named as in the JSON format.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(non_snake_case)]
pub struct TakedaSpec {
    /// Positive skeleton deformations (mm), 1 to 8 points, the first at yield.
    pub ePd: Vec<f64>,
    /// Positive skeleton forces (N).
    pub ePf: Vec<f64>,
    /// Negative skeleton deformations (mm, negative numbers).
    pub eNd: Vec<f64>,
    /// Negative skeleton forces (N, negative numbers).
    pub eNf: Vec<f64>,
    /// Unloading stiffness exponent (0 <= alpha < 1); 0 (default) unloads at
    /// the initial stiffness as SAP2000's Takeda link, Otani uses 0.4 to 0.5.
    #[serde(default)]
    pub alpha: f64,
}

/// The modified Takeda material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Takeda {
    skeleton: Skeleton,
    alpha: f64,
    committed: History,
    trial: History,
}

impl Takeda {
    /// A virgin material.
    pub fn new(spec: &TakedaSpec) -> Result<Self, MaterialError> {
        let skeleton = Skeleton::new("Takeda", &spec.ePd, &spec.ePf, &spec.eNd, &spec.eNf)?;
        if !(0.0..1.0).contains(&spec.alpha) {
            return Err(MaterialError::Parameter {
                material: "Takeda",
                key: "alpha",
                value: spec.alpha,
                expected: "an exponent in [0, 1)",
            });
        }
        let virgin = History::virgin(&skeleton);
        Ok(Takeda { skeleton, alpha: spec.alpha, committed: virgin, trial: virgin })
    }

    /// The virgin state of this material.
    fn virgin(&self) -> History {
        History::virgin(&self.skeleton)
    }

    /// Unloading stiffness after an excursion to `d_peak` on side `s`.
    fn k_unload(&self, d_peak: f64, s: f64) -> f64 {
        let sk = &self.skeleton;
        sk.k0(s) * (sk.dy(s) / d_peak).abs().powf(self.alpha)
    }

    /// Reloading from the zero crossing `d0` towards the excursion `d_peak`
    /// (same sign as the direction `s`), then the skeleton.
    fn reload(&self, d: f64, d0: f64, d_peak: f64, s: f64) -> (f64, f64) {
        let dy = self.skeleton.dy(s).abs();
        let target = if s * (d_peak - d0) < dy { d0 + s * dy } else { d_peak };
        if s * (d - target) >= 0.0 {
            return self.skeleton.eval(d);
        }
        let f_target = self.skeleton.eval(target).0;
        let k = f_target / (target - d0);
        (k * (d - d0), k)
    }
}

impl UniaxialMaterial for Takeda {
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError> {
        check_finite(d)?;
        let c = self.committed;
        let dd = d - c.d;
        let mut t = History { d, ..c };
        if dd == 0.0 {
            self.trial = c;
            return Ok(());
        }
        let s = dd.signum();
        // Unloading line of the side the committed force is on.
        let (k_u, same_side) = if c.f > 0.0 || (c.f == 0.0 && s > 0.0) {
            (self.k_unload(c.d_max, 1.0), s > 0.0)
        } else {
            (self.k_unload(c.d_min, -1.0), s < 0.0)
        };
        let elastic = (c.f + k_u * dd, k_u);
        let (f, k_t) = if same_side {
            // Towards the side's own peak: elastic line, capped by reloading.
            let (d0, peak) = if s > 0.0 { (c.d0_pos, c.d_max) } else { (c.d0_neg, c.d_min) };
            let re = self.reload(d, d0, peak, s);
            if s * (elastic.0 - re.0) < 0.0 {
                elastic
            } else {
                re
            }
        } else if s * elastic.0 < 0.0 {
            elastic
        } else {
            // The force crosses zero: a new reloading line to the other side.
            let d0 = c.d - c.f / k_u;
            let peak = if s > 0.0 { c.d_max } else { c.d_min };
            if s > 0.0 {
                t.d0_pos = d0;
            } else {
                t.d0_neg = d0;
            }
            self.reload(d, d0, peak, s)
        };
        t.f = f;
        t.k_t = k_t;
        if d > t.d_max {
            t.d_max = d;
        }
        if d < t.d_min {
            t.d_min = d;
        }
        self.trial = t;
        Ok(())
    }
    fn force(&self) -> f64 {
        self.trial.f
    }
    fn tangent(&self) -> f64 {
        self.trial.k_t
    }
    /// The stiffer of the two elastic slopes.
    fn initial_tangent(&self) -> f64 {
        self.skeleton.k0(1.0).max(self.skeleton.k0(-1.0))
    }
    fn commit(&mut self) {
        self.committed = self.trial;
    }
    fn revert(&mut self) {
        self.trial = self.committed;
    }
    fn boxed_clone(&self) -> Box<dyn UniaxialMaterial> {
        Box::new(Takeda { committed: self.virgin(), trial: self.virgin(), ..*self })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bilinear: k0 = 100 N/mm, Fy = 100 N, post-yield 5 N/mm.
    fn takeda() -> Takeda {
        Takeda::new(&TakedaSpec {
            ePd: vec![1.0, 11.0],
            ePf: vec![100.0, 150.0],
            eNd: vec![-1.0, -11.0],
            eNf: vec![-100.0, -150.0],
            alpha: 0.5,
        })
        .unwrap()
    }

    fn step(m: &mut Takeda, d: f64) -> f64 {
        m.set_trial(d).unwrap();
        m.commit();
        m.force()
    }

    #[test]
    fn elastic_below_yield_in_both_directions() {
        let mut m = takeda();
        assert!((step(&mut m, 0.5) - 50.0).abs() < 1e-12);
        assert!((step(&mut m, -0.8) + 80.0).abs() < 1e-12);
        assert!((step(&mut m, 0.2) - 20.0).abs() < 1e-12);
    }

    #[test]
    fn unloads_with_otani_stiffness_and_reloads_to_the_opposite_peak() {
        let mut m = takeda();
        // yield and go to d = 4: f = 100 + 5 * 3 = 115
        assert!((step(&mut m, 4.0) - 115.0).abs() < 1e-12);
        // k_u = 100 (1/4)^0.5 = 50; zero force at d = 4 - 115/50 = 1.7
        assert!((step(&mut m, 3.0) - 65.0).abs() < 1e-12);
        assert!(step(&mut m, 1.7).abs() < 1e-9);
        // then towards (-1, -100): slope 100 / 2.7
        let f = step(&mut m, 0.35);
        assert!((f + 100.0 / 2.7 * 1.35).abs() < 1e-9, "{f}");
        // reversal on the negative side's line goes back with k0 (never yielded there)
        let f2 = step(&mut m, 0.45);
        assert!((f2 - (f + 100.0 * 0.1)).abs() < 1e-9);
        // reloading to the positive peak from a fresh crossing
        let f3 = step(&mut m, 3.9);
        assert!(f3 > 0.0 && f3 < 115.0);
        assert!((step(&mut m, 5.0) - 120.0).abs() < 1e-9);
    }
}
