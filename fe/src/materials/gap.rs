//! Compression-only gap of seed eq. 5.4: f = k (d + gap) when d + gap <= 0,
//! else 0. It is OpenSees `ElasticPPGap` with an unreachable yield force
//! (elastic in contact, no memory); contact starts at d = -gap inclusive,
//! where the tangent is already k. Units: mm, N, N/mm.

use super::{check_finite, MaterialError, UniaxialMaterial};

/// Compression-only gap spring without memory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gap {
    /// Contact stiffness (N/mm).
    k: f64,
    /// Deformation at which contact starts (mm, = -gap <= 0).
    d_contact: f64,
    /// Trial deformation (mm).
    trial_d: f64,
    /// Committed deformation (mm).
    committed_d: f64,
}

impl Gap {
    /// A gap of stiffness `k` (N/mm, >= 0) and opening `gap_mm` (>= 0).
    pub fn new(k: f64, gap_mm: f64) -> Result<Self, MaterialError> {
        if !(k.is_finite() && k >= 0.0) {
            return Err(MaterialError::Parameter {
                material: "Gap",
                key: "k",
                value: k,
                expected: "a finite stiffness >= 0",
            });
        }
        if !(gap_mm.is_finite() && gap_mm >= 0.0) {
            return Err(MaterialError::Parameter {
                material: "Gap",
                key: "gap",
                value: gap_mm,
                expected: "a finite opening >= 0 mm",
            });
        }
        Ok(Gap { k, d_contact: -gap_mm, trial_d: 0.0, committed_d: 0.0 })
    }

    /// True when the trial deformation closes the gap.
    #[inline]
    fn in_contact(&self) -> bool {
        self.trial_d <= self.d_contact
    }
}

impl UniaxialMaterial for Gap {
    #[inline]
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError> {
        check_finite(d)?;
        self.trial_d = d;
        Ok(())
    }
    #[inline]
    fn force(&self) -> f64 {
        if self.in_contact() {
            self.k * (self.trial_d - self.d_contact)
        } else {
            0.0
        }
    }
    #[inline]
    fn tangent(&self) -> f64 {
        if self.in_contact() {
            self.k
        } else {
            0.0
        }
    }
    fn initial_tangent(&self) -> f64 {
        if self.d_contact < 0.0 {
            0.0
        } else {
            self.k
        }
    }
    #[inline]
    fn commit(&mut self) {
        self.committed_d = self.trial_d;
    }
    #[inline]
    fn revert(&mut self) {
        self.trial_d = self.committed_d;
    }
    fn boxed_clone(&self) -> Box<dyn UniaxialMaterial> {
        Box::new(Gap { trial_d: 0.0, committed_d: 0.0, ..*self })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn open_then_closed_per_eq_5_4() {
        let mut g = Gap::new(588.0, 19.0).unwrap();
        g.set_trial(-18.99).unwrap();
        assert_eq!((g.force(), g.tangent()), (0.0, 0.0));
        g.set_trial(-19.0).unwrap();
        assert_eq!((g.force(), g.tangent()), (0.0, 588.0));
        g.set_trial(-25.0).unwrap();
        assert!((g.force() + 3528.0).abs() < 1e-9);
        g.set_trial(5.0).unwrap();
        assert_eq!(g.force(), 0.0);
    }

    #[test]
    fn rejects_negative_gap() {
        assert!(Gap::new(1.0, -1.0).is_err());
        assert_eq!(Gap::new(5.0, 0.0).unwrap().initial_tangent(), 5.0);
    }
}
