//! Pivot hysteresis (Dowell, Seible & Wilson 1998, ACI Struct. J. 95(5)
//! 607-617) with the parameter meanings of the SAP2000 "Hysteretic (Pivot)"
//! link, on a symmetric bilinear backbone (k0, Fy, r k0):
//!
//! * unloading from positive force follows the line through the current
//!   point and the primary pivot P1 = (-alpha1 dy, -alpha1 Fy) on the
//!   extension of the elastic line, until zero force (from negative force,
//!   P2 = (alpha2 dy, alpha2 Fy));
//! * from zero force, reloading towards positive force first targets the
//!   pinching pivot PP1 = (beta1 dy, beta1 Fy) on the elastic line, then the
//!   largest positive excursion on the backbone, then the backbone
//!   (negative side: beta2);
//! * a reversal during unloading goes back along the pivot line, capped by
//!   the reloading path.
//!
//! Not implemented: eta (the softening of the elastic slope with plastic
//! deformation) must be 0. Units: mm, N, N/mm.

use serde::{Deserialize, Serialize};

use super::{check_finite, MaterialError, UniaxialMaterial};

/// Pivot parameters, named as in the JSON format.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PivotParams {
    /// Initial stiffness (N/mm, > 0).
    pub k0: f64,
    /// Yield force (N, > 0).
    #[serde(rename = "Fy")]
    pub fy: f64,
    /// Post-yield stiffness ratio (0 <= r < 1).
    pub r: f64,
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

/// The state a step changes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct History {
    d: f64,
    f: f64,
    k_t: f64,
    /// Largest positive deformation so far (mm, >= dy).
    d_max: f64,
    /// Largest negative deformation so far (mm, <= -dy).
    d_min: f64,
    /// Zero-force crossing of the positive reloading path (mm).
    d0_pos: f64,
    /// Zero-force crossing of the negative reloading path (mm).
    d0_neg: f64,
}

/// The Pivot material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pivot {
    params: PivotParams,
    dy: f64,
    committed: History,
    trial: History,
}

impl Pivot {
    /// A virgin material.
    pub fn new(params: PivotParams) -> Result<Self, MaterialError> {
        let bad = |key, value, expected| {
            Err(MaterialError::Parameter { material: "Pivot", key, value, expected })
        };
        let p = params;
        if !(p.k0.is_finite() && p.k0 > 0.0) {
            return bad("k0", p.k0, "a finite stiffness > 0");
        }
        if !(p.fy.is_finite() && p.fy > 0.0) {
            return bad("Fy", p.fy, "a finite yield force > 0");
        }
        if !(p.r >= 0.0 && p.r < 1.0) {
            return bad("r", p.r, "a post-yield ratio in [0, 1)");
        }
        for (key, v) in [("alpha1", p.alpha1), ("alpha2", p.alpha2)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(key, v, "a finite pivot factor > 0");
            }
        }
        for (key, v) in [("beta1", p.beta1), ("beta2", p.beta2)] {
            if !(0.0..1.0).contains(&v) {
                return bad(key, v, "a pinching factor in [0, 1)");
            }
        }
        if p.eta != 0.0 {
            return bad("eta", p.eta, "0 (elastic softening is not implemented)");
        }
        let dy = p.fy / p.k0;
        let virgin =
            History { d: 0.0, f: 0.0, k_t: p.k0, d_max: dy, d_min: -dy, d0_pos: 0.0, d0_neg: 0.0 };
        Ok(Pivot { params, dy, committed: virgin, trial: virgin })
    }

    /// Backbone force and slope at `d`.
    fn backbone(&self, d: f64) -> (f64, f64) {
        let p = &self.params;
        if d.abs() <= self.dy {
            (p.k0 * d, p.k0)
        } else {
            (d.signum() * (p.fy + p.r * p.k0 * (d.abs() - self.dy)), p.r * p.k0)
        }
    }

    /// Slope of the line from (d, f) to the pivot of the side of `f`'s sign
    /// (`s_side` = +1 for positive force), at most k0.
    fn pivot_slope(&self, d: f64, f: f64, s_side: f64) -> f64 {
        let a = if s_side > 0.0 { self.params.alpha1 } else { self.params.alpha2 };
        let (pd, pf) = (-s_side * a * self.dy, -s_side * a * self.params.fy);
        let den = d - pd;
        let k = (f - pf) / den;
        if s_side * den > 0.0 && k.is_finite() && k > 0.0 && k < self.params.k0 {
            k
        } else {
            self.params.k0
        }
    }

    /// Reloading path from the zero crossing `d0` in direction `s`: to the
    /// pinching pivot, then the peak excursion, then the backbone.
    fn reload(&self, d: f64, d0: f64, d_peak: f64, s: f64) -> (f64, f64) {
        let target = if s * (d_peak - d0) < self.dy { d0 + s * self.dy } else { d_peak };
        if s * (d - target) >= 0.0 {
            return self.backbone(d);
        }
        let beta = if s > 0.0 { self.params.beta1 } else { self.params.beta2 };
        let (pp_d, pp_f) = (s * beta * self.dy, s * beta * self.params.fy);
        let f_target = self.backbone(target).0;
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
    fn initial_tangent(&self) -> f64 {
        self.params.k0
    }
    fn commit(&mut self) {
        self.committed = self.trial;
    }
    fn revert(&mut self) {
        self.trial = self.committed;
    }
    fn boxed_clone(&self) -> Box<dyn UniaxialMaterial> {
        Box::new(Pivot::new(self.params).expect("parameters were checked"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pivot() -> Pivot {
        Pivot::new(PivotParams {
            k0: 100.0,
            fy: 100.0,
            r: 0.05,
            alpha1: 2.0,
            alpha2: 2.0,
            beta1: 0.3,
            beta2: 0.3,
            eta: 0.0,
        })
        .unwrap()
    }

    fn step(m: &mut Pivot, d: f64) -> f64 {
        m.set_trial(d).unwrap();
        m.commit();
        m.force()
    }

    #[test]
    fn unloads_towards_the_primary_pivot() {
        let mut m = pivot();
        assert!((step(&mut m, 4.0) - 115.0).abs() < 1e-12);
        // line from (4, 115) to P1 = (-2, -200): slope 315 / 6 = 52.5
        let f = step(&mut m, 3.0);
        assert!((f - (115.0 - 52.5)).abs() < 1e-9, "{f}");
        assert_eq!(m.tangent(), 52.5);
    }

    #[test]
    fn reloads_through_the_pinching_pivot() {
        let mut m = pivot();
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
    fn rejects_eta() {
        let mut p = pivot().params;
        p.eta = 0.5;
        assert!(Pivot::new(p).is_err());
    }
}
