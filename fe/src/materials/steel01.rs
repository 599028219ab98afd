//! Bilinear kinematic-hardening law, OpenSees `Steel01` with the isotropic
//! hardening parameters at their defaults (a1..a4 = 0, 1, 0, 1), so the
//! yield surface translates without growing: the force is the elastic
//! predictor f_c + E0 (d - d_c) clipped to the band b E0 d ± Fy (1 - b).
//! The seed uses it as the perimeter friction surrogate. Units: mm, N, N/mm.

use super::{check_finite, MaterialError, UniaxialMaterial};

/// Steel01 parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steel01Params {
    /// Yield force (N, > 0).
    pub fy: f64,
    /// Initial stiffness (N/mm, > 0).
    pub e0: f64,
    /// Post-yield stiffness ratio (0 <= b < 1).
    pub b: f64,
}

/// The state that a step changes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct History {
    /// Deformation (mm).
    d: f64,
    /// Force (N).
    f: f64,
    /// Tangent (N/mm).
    k_t: f64,
}

/// OpenSees Steel01 without isotropic hardening.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steel01 {
    params: Steel01Params,
    /// Half-width of the yield band, Fy (1 - b) (N).
    band_n: f64,
    /// Hardening stiffness b E0 (N/mm).
    k_hard: f64,
    committed: History,
    trial: History,
}

impl Steel01 {
    /// A virgin material; checks Fy > 0, E0 > 0, 0 <= b < 1.
    pub fn new(params: Steel01Params) -> Result<Self, MaterialError> {
        let bad = |key, value, expected| {
            Err(MaterialError::Parameter { material: "Steel01", key, value, expected })
        };
        if !(params.fy.is_finite() && params.fy > 0.0) {
            return bad("Fy", params.fy, "a finite yield force > 0");
        }
        if !(params.e0.is_finite() && params.e0 > 0.0) {
            return bad("E0", params.e0, "a finite stiffness > 0");
        }
        if !(params.b >= 0.0 && params.b < 1.0) {
            return bad("b", params.b, "a hardening ratio in [0, 1)");
        }
        let virgin = History { d: 0.0, f: 0.0, k_t: params.e0 };
        Ok(Steel01 {
            params,
            band_n: params.fy * (1.0 - params.b),
            k_hard: params.b * params.e0,
            committed: virgin,
            trial: virgin,
        })
    }
}

impl UniaxialMaterial for Steel01 {
    #[inline]
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError> {
        check_finite(d)?;
        let c = self.committed;
        let dd = d - c.d;
        if dd.abs() <= f64::EPSILON {
            self.trial = c;
            return Ok(());
        }
        let elastic = c.f + self.params.e0 * dd;
        let centre = self.k_hard * d;
        let upper = centre + self.band_n;
        let lower = centre - self.band_n;
        let f = if elastic > upper {
            upper
        } else if elastic < lower {
            lower
        } else {
            elastic
        };
        // OpenSees' test: elastic unless the clipped force moved by >= eps.
        let k_t = if (f - elastic).abs() < f64::EPSILON { self.params.e0 } else { self.k_hard };
        self.trial = History { d, f, k_t };
        Ok(())
    }
    #[inline]
    fn force(&self) -> f64 {
        self.trial.f
    }
    #[inline]
    fn tangent(&self) -> f64 {
        self.trial.k_t
    }
    fn initial_tangent(&self) -> f64 {
        self.params.e0
    }
    #[inline]
    fn commit(&mut self) {
        self.committed = self.trial;
    }
    #[inline]
    fn revert(&mut self) {
        self.trial = self.committed;
    }
    fn boxed_clone(&self) -> Box<dyn UniaxialMaterial> {
        Box::new(Steel01::new(self.params).expect("parameters were checked"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn friction() -> Steel01 {
        Steel01::new(Steel01Params { fy: 2.0, e0: 20.0, b: 0.05 }).unwrap()
    }

    #[test]
    fn yields_at_fy_and_hardens_with_b_e0() {
        let mut m = friction();
        m.set_trial(0.1).unwrap();
        assert!((m.force() - 2.0).abs() < 1e-12);
        m.commit();
        m.set_trial(1.1).unwrap();
        // 2 + 0.05 * 20 * 1.0
        assert!((m.force() - 3.0).abs() < 1e-12);
        assert_eq!(m.tangent(), 1.0);
    }

    #[test]
    fn unloads_elastically_over_twice_the_yield_band() {
        let mut m = friction();
        m.set_trial(1.1).unwrap();
        m.commit();
        m.set_trial(1.1 - 0.2).unwrap();
        assert!((m.force() - (3.0 - 4.0)).abs() < 1e-12);
        assert_eq!(m.tangent(), 20.0);
    }

    #[test]
    fn rejects_b_of_one() {
        assert!(Steel01::new(Steel01Params { fy: 1.0, e0: 1.0, b: 1.0 }).is_err());
    }
}
