//! Linear elastic spring f = k d (OpenSees `ElasticMaterial` without damping).
//! Units: deformation mm, force N, stiffness N/mm.

use super::{check_finite, MaterialError, UniaxialMaterial};

/// Linear elastic law; it has no history beyond its deformation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastic {
    /// Stiffness (N/mm).
    k: f64,
    /// Trial deformation (mm).
    trial_d: f64,
    /// Committed deformation (mm).
    committed_d: f64,
}

impl Elastic {
    /// A virgin spring of stiffness `k` (N/mm, finite).
    pub fn new(k: f64) -> Result<Self, MaterialError> {
        if !k.is_finite() {
            return Err(MaterialError::Parameter {
                material: "Elastic",
                key: "k",
                value: k,
                expected: "a finite stiffness",
            });
        }
        Ok(Elastic { k, trial_d: 0.0, committed_d: 0.0 })
    }
}

impl UniaxialMaterial for Elastic {
    #[inline]
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError> {
        check_finite(d)?;
        self.trial_d = d;
        Ok(())
    }
    #[inline]
    fn force(&self) -> f64 {
        self.k * self.trial_d
    }
    #[inline]
    fn tangent(&self) -> f64 {
        self.k
    }
    fn initial_tangent(&self) -> f64 {
        self.k
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
        Box::new(Elastic::new(self.k).expect("parameters were checked"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_is_stiffness_times_deformation() {
        let mut m = Elastic::new(12.5).unwrap();
        m.set_trial(-2.0).unwrap();
        assert_eq!(m.force(), -25.0);
        assert_eq!(m.tangent(), 12.5);
        m.revert();
        assert_eq!(m.force(), 0.0);
    }

    #[test]
    fn rejects_nan_stiffness_and_deformation() {
        assert!(Elastic::new(f64::NAN).is_err());
        let mut m = Elastic::new(1.0).unwrap();
        assert_eq!(m.set_trial(f64::INFINITY), Err(MaterialError::NonFinite(f64::INFINITY)));
    }
}
