//! OpenSees `ImpactMaterial` (Muthukumar & DesRoches 2006 bilinear
//! approximation of Hertz contact with hysteretic damping; Nielson 2005).
//!
//! Contact at d < -gap. Inside the closed range the force follows an
//! incremental rule from the last committed force, as OpenSees does:
//! loading (d decreasing) goes f_c + K1 (d - d_c), bounded below by the
//! loading line K1 (-dy) + K2 (d + gap + dy); unloading (d increasing) goes
//! f_c + K1 (d - d_c), bounded above by the unloading line K2 (d + gap).
//! The increment is taken from the committed deformation even when that was
//! outside contact, which is OpenSees' behaviour. Units: mm, N, N/mm.

use super::{check_finite, MaterialError, UniaxialMaterial};

/// ImpactMaterial parameters (positive numbers, as the JSON writes them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactParams {
    /// Initial contact stiffness (N/mm).
    pub k1: f64,
    /// Post-yield contact stiffness (N/mm).
    pub k2: f64,
    /// Yield deformation beyond closure (mm, > 0).
    pub dy: f64,
    /// Opening (mm, > 0).
    pub gap: f64,
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

/// OpenSees ImpactMaterial.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impact {
    params: ImpactParams,
    /// Closure deformation, OpenSees' negative gap (mm).
    d_gap: f64,
    /// OpenSees' negative yield deformation (mm).
    d_y: f64,
    committed: History,
    trial: History,
}

impl Impact {
    /// A virgin material; all parameters finite and > 0.
    pub fn new(params: ImpactParams) -> Result<Self, MaterialError> {
        let checks = [
            ("K1", params.k1, "a contact stiffness > 0"),
            ("K2", params.k2, "a post-yield stiffness > 0"),
            ("dy", params.dy, "a yield deformation > 0 mm"),
            ("gap", params.gap, "an opening > 0 mm"),
        ];
        for (key, value, expected) in checks {
            if !(value.is_finite() && value > 0.0) {
                return Err(MaterialError::Parameter { material: "Impact", key, value, expected });
            }
        }
        let virgin = History { d: 0.0, f: 0.0, k_t: params.k1 };
        Ok(Impact { params, d_gap: -params.gap, d_y: -params.dy, committed: virgin, trial: virgin })
    }

    /// Trial force and tangent at `d` from the committed state.
    #[inline]
    fn evaluate(&self, d: f64) -> (f64, f64) {
        let p = &self.params;
        let c = &self.committed;
        if d >= self.d_gap {
            return (0.0, 0.0);
        }
        let dd = d - c.d;
        let incremental = c.f + p.k1 * dd;
        if dd < 0.0 {
            let loading = p.k1 * self.d_y + p.k2 * (d - self.d_gap - self.d_y);
            if incremental < loading {
                (loading, p.k2)
            } else {
                (incremental, p.k1)
            }
        } else if dd > 0.0 {
            let unloading = p.k2 * (d - self.d_gap);
            if incremental > unloading {
                (unloading, p.k2)
            } else {
                (incremental, p.k1)
            }
        } else {
            (c.f, c.k_t)
        }
    }
}

impl UniaxialMaterial for Impact {
    #[inline]
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError> {
        check_finite(d)?;
        let (f, k_t) = self.evaluate(d);
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
    /// Zero: the gap is open in the virgin state (OpenSees reports K1).
    fn initial_tangent(&self) -> f64 {
        0.0
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
        Box::new(Impact::new(self.params).expect("parameters were checked"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seed() -> Impact {
        Impact::new(ImpactParams { k1: 300.0, k2: 100.0, dy: 0.1, gap: 13.3 }).unwrap()
    }

    fn step(m: &mut Impact, d: f64) -> f64 {
        m.set_trial(d).unwrap();
        m.commit();
        m.force()
    }

    #[test]
    fn loads_with_k1_then_k2_and_unloads_on_the_k2_line() {
        let mut m = seed();
        assert_eq!(step(&mut m, -13.3), 0.0);
        assert!((step(&mut m, -13.35) + 15.0).abs() < 1e-9);
        // past dy: -30 - 100 (0.1)
        assert!((step(&mut m, -13.5) + 40.0).abs() < 1e-9);
        assert_eq!(m.tangent(), 100.0);
        // unloading with K1 from -40, above the K2 line (-15)
        assert!((step(&mut m, -13.45) + 25.0).abs() < 1e-9);
        assert_eq!(m.tangent(), 300.0);
        // K1 would give -4; bounded by the K2 line K2 (d + gap) = -8
        assert!((step(&mut m, -13.38) + 8.0).abs() < 1e-9);
        assert_eq!(m.tangent(), 100.0);
    }

    #[test]
    fn increment_counts_from_an_open_committed_state() {
        let mut m = seed();
        step(&mut m, -13.29);
        // OpenSees: 0 + K1 (-0.02), not K1 (-0.01)
        assert!((step(&mut m, -13.31) + 6.0).abs() < 1e-9);
    }
}
