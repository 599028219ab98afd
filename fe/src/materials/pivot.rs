//! Pivot hysteresis (Dowell, Seible & Wilson 1998, ACI Struct. J. 95(5)
//! 607-617) with the parameter meanings of the SAP2000 Pivot link, on a
//! multi-linear skeleton per side whose first point is the yield point
//! (dy+, Fy+) or (dy-, Fy-), with elastic stiffness k0 = Fy / dy of the side:
//!
//! * unloading from positive force follows the line through the current
//!   point and the primary pivot P1 = (-alpha1 dy+, -alpha1 Fy+) on the
//!   extension of the positive elastic line, until zero force; from negative
//!   force, P2 = (alpha2 |dy-|, alpha2 |Fy-|);
//! * from zero force, reloading towards positive force first targets the
//!   pinching pivot PP1 = (beta1 dy+, beta1 Fy+) on the elastic line, then
//!   the largest positive excursion on the skeleton, then the skeleton
//!   (negative side: PP2 = -(beta2 |dy-|, beta2 |Fy-|));
//! * a reversal during unloading goes back along the pivot line, capped by
//!   the reloading path.
//!
//! The seed's main-cross tee connections use alpha1 = 25, alpha2 = 0.05,
//! beta1 = 0.01, beta2 = 0.9, eta = 0. Not implemented: eta (softening of
//! the elastic slope with plastic deformation) must be 0.
//! Units: mm, N, N/mm.

use serde::{Deserialize, Serialize};

use super::skeleton::{PeakHistory as History, Skeleton};
use super::{check_finite, MaterialError, UniaxialMaterial};

/// Pivot parameters, named as in the JSON format.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(non_snake_case)]
pub struct PivotSpec {
    /// Positive skeleton deformations (mm), 1 to 8 points, the first at yield.
    pub ePd: Vec<f64>,
    /// Positive skeleton forces (N).
    pub ePf: Vec<f64>,
    /// Negative skeleton deformations (mm, negative numbers).
    pub eNd: Vec<f64>,
    /// Negative skeleton forces (N, negative numbers).
    pub eNf: Vec<f64>,
    /// Primary pivot for unloading from positive force (> 0).
    pub alpha1: f64,
    /// Primary pivot for unloading from negative force (> 0).
    pub alpha2: f64,
    /// Pinching pivot for reloading towards positive force (0 <= beta1 < 1).
    pub beta1: f64,
    /// Pinching pivot for reloading towards negative force (0 <= beta2 < 1).
    pub beta2: f64,
    /// Elastic softening parameter (only 0 is supported).
    #[serde(default)]
    pub eta: f64,
}

/// The Pivot material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pivot {
    skeleton: Skeleton,
    /// alpha1, alpha2.
    alpha: [f64; 2],
    /// beta1, beta2.
    beta: [f64; 2],
    committed: History,
    trial: History,
}

impl Pivot {
    /// A virgin material.
    pub fn new(spec: &PivotSpec) -> Result<Self, MaterialError> {
        let bad = |key, value, expected| {
            Err(MaterialError::Parameter { material: "Pivot", key, value, expected })
        };
        let skeleton = Skeleton::new("Pivot", &spec.ePd, &spec.ePf, &spec.eNd, &spec.eNf)?;
        for (key, v) in [("alpha1", spec.alpha1), ("alpha2", spec.alpha2)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(key, v, "a finite pivot factor > 0");
            }
        }
        for (key, v) in [("beta1", spec.beta1), ("beta2", spec.beta2)] {
            if !(0.0..1.0).contains(&v) {
                return bad(key, v, "a pinching factor in [0, 1)");
            }
        }
        if spec.eta != 0.0 {
            return bad("eta", spec.eta, "0 (elastic softening is not implemented)");
        }
        let virgin = History::virgin(&skeleton);
        Ok(Pivot {
            skeleton,
            alpha: [spec.alpha1, spec.alpha2],
            beta: [spec.beta1, spec.beta2],
            committed: virgin,
            trial: virgin,
        })
    }

    /// Index 0 for the positive side, 1 for the negative.
    fn side_index(s: f64) -> usize {
        if s > 0.0 {
            0
        } else {
            1
        }
    }

    /// Slope of the line from (d, f) to the primary pivot of the side `s`
    /// the force is on, at most that side's k0.
    fn pivot_slope(&self, d: f64, f: f64, s: f64) -> f64 {
        let a = self.alpha[Self::side_index(s)];
        let sk = &self.skeleton;
        let (pd, pf) = (-a * sk.dy(s), -a * sk.fy(s));
        let den = d - pd;
        let k = (f - pf) / den;
        let k0 = sk.k0(s);
        if s * den > 0.0 && k.is_finite() && k > 0.0 && k < k0 {
            k
        } else {
            k0
        }
    }

    /// Reloading path from the zero crossing `d0` in direction `s`: to the
    /// pinching pivot, then the peak excursion, then the skeleton.
    fn reload(&self, d: f64, d0: f64, d_peak: f64, s: f64) -> (f64, f64) {
        let sk = &self.skeleton;
        let dy = sk.dy(s);
        let target = if s * (d_peak - d0) < dy.abs() { d0 + dy } else { d_peak };
        if s * (d - target) >= 0.0 {
            return sk.eval(d);
        }
        let beta = self.beta[Self::side_index(s)];
        let (pp_d, pp_f) = (beta * dy, beta * sk.fy(s));
        let f_target = sk.eval(target).0;
        let via_pivot = s * (pp_d - d0) > 0.0 && s * (target - pp_d) > 0.0;
        if via_pivot && s * (d - pp_d) <= 0.0 {
            let k = pp_f / (pp_d - d0);
            (k * (d - d0), k)
        } else if via_pivot {
            let k = (f_target - pp_f) / (target - pp_d);
            (pp_f + k * (d - pp_d), k)
        } else {
            let k = f_target / (target - d0);
            (k * (d - d0), k)
        }
    }
}

impl UniaxialMaterial for Pivot {
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError> {
        check_finite(d)?;
        let c = self.committed;
        let dd = d - c.d;
        if dd == 0.0 {
            self.trial = c;
            return Ok(());
        }
        let mut t = History { d, ..c };
        let s = dd.signum();
        let side = if c.f > 0.0 || (c.f == 0.0 && s > 0.0) { 1.0 } else { -1.0 };
        let k_u = self.pivot_slope(c.d, c.f, side);
        let elastic = (c.f + k_u * dd, k_u);
        let (f, k_t) = if side == s {
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
            let d0 = c.d - c.f / k_u;
            if s > 0.0 {
                t.d0_pos = d0;
            } else {
                t.d0_neg = d0;
            }
            let peak = if s > 0.0 { c.d_max } else { c.d_min };
            self.reload(d, d0, peak, s)
        };
        t.f = f;
        t.k_t = k_t;
        t.d_max = t.d_max.max(d);
        t.d_min = t.d_min.min(d);
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
        let virgin = History::virgin(&self.skeleton);
        Box::new(Pivot { committed: virgin, trial: virgin, ..*self })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bilinear, symmetric: k0 = 100 N/mm, Fy = 100 N, post-yield 5 N/mm.
    fn spec() -> PivotSpec {
        PivotSpec {
            ePd: vec![1.0, 11.0],
            ePf: vec![100.0, 150.0],
            eNd: vec![-1.0, -11.0],
            eNf: vec![-100.0, -150.0],
            alpha1: 2.0,
            alpha2: 2.0,
            beta1: 0.3,
            beta2: 0.3,
            eta: 0.0,
        }
    }

    fn step(m: &mut Pivot, d: f64) -> f64 {
        m.set_trial(d).unwrap();
        m.commit();
        m.force()
    }

    #[test]
    fn unloads_towards_the_primary_pivot() {
        let mut m = Pivot::new(&spec()).unwrap();
        assert!((step(&mut m, 4.0) - 115.0).abs() < 1e-12);
        // line from (4, 115) to P1 = (-2, -200): slope 315 / 6 = 52.5
        let f = step(&mut m, 3.0);
        assert!((f - (115.0 - 52.5)).abs() < 1e-9, "{f}");
        assert_eq!(m.tangent(), 52.5);
    }

    #[test]
    fn reloads_through_the_pinching_pivot() {
        let mut m = Pivot::new(&spec()).unwrap();
        step(&mut m, 4.0);
        let d0 = 4.0 - 115.0 / 52.5;
        assert!(step(&mut m, d0).abs() < 1e-9);
        // towards PP2 = (-0.3, -30)
        let f = step(&mut m, -0.3);
        assert!((f + 30.0).abs() < 1e-9, "{f}");
        // then towards the negative yield point (-1, -100): slope 70 / 0.7
        let f = step(&mut m, -0.65);
        assert!((f + 65.0).abs() < 1e-9, "{f}");
        assert!((step(&mut m, -2.0) + 105.0).abs() < 1e-9);
    }

    #[test]
    fn asymmetric_yield_moves_the_pivots() {
        let mut s = spec();
        s.eNd = vec![-0.5];
        s.eNf = vec![-20.0];
        let mut m = Pivot::new(&s).unwrap();
        // negative side: k0 = 40 N/mm, flat at -20 N beyond -0.5 mm
        assert!((step(&mut m, -0.25) + 10.0).abs() < 1e-12);
        assert!((step(&mut m, -3.0) + 20.0).abs() < 1e-12);
        // unloading from negative force aims at P2 = (2 * 0.5, 2 * 20)
        step(&mut m, -2.9);
        assert!((m.tangent() - 60.0 / 4.0).abs() < 1e-9, "{}", m.tangent());
    }

    #[test]
    fn rejects_eta() {
        let mut s = spec();
        s.eta = 0.5;
        assert!(Pivot::new(&s).is_err());
    }
}
