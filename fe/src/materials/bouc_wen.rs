//! Wen plastic link (Bouc 1967, Wen 1976) as SAP2000/ETABS define their
//! "Plastic (Wen)" link: f = r k d + (1 - r) Fy z with k = Fy / dy and
//! dz/dd = (1/dy) (1 - |z|^n) when dd z > 0, else 1/dy.
//!
//! The seed uses it for perimeter friction (r = 0: rigid-plastic with a
//! smooth corner). Each step is integrated implicitly (backward Euler in the
//! deformation increment from the committed state); the loading equation
//! is solved by a safeguarded Newton iteration and the tangent is the
//! consistent (algorithmic) one. Units: mm, N, N/mm.

use super::{check_finite, MaterialError, UniaxialMaterial};

/// Wen link parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoucWenParams {
    /// Yield force (N, > 0).
    pub fy: f64,
    /// Yield deformation (mm, > 0).
    pub dy: f64,
    /// Yield exponent n (>= 1).
    pub exponent: f64,
    /// Post-yield stiffness ratio r (0 <= r < 1).
    pub ratio: f64,
}

/// The state a step changes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct History {
    /// Deformation (mm).
    d: f64,
    /// Hysteretic variable z (|z| <= 1).
    z: f64,
    /// Force (N).
    f: f64,
    /// Consistent tangent (N/mm).
    k_t: f64,
}

/// The Wen plastic link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoucWen {
    params: BoucWenParams,
    committed: History,
    trial: History,
}

impl BoucWen {
    /// A virgin link (z = 0).
    pub fn new(params: BoucWenParams) -> Result<Self, MaterialError> {
        let bad = |key, value, expected| {
            Err(MaterialError::Parameter { material: "BoucWen", key, value, expected })
        };
        if !(params.fy.is_finite() && params.fy > 0.0) {
            return bad("Fy", params.fy, "a finite yield force > 0");
        }
        if !(params.dy.is_finite() && params.dy > 0.0) {
            return bad("dy", params.dy, "a finite yield deformation > 0");
        }
        if !(params.exponent.is_finite() && params.exponent >= 1.0) {
            return bad("exponent", params.exponent, "a finite exponent >= 1");
        }
        if !(params.ratio >= 0.0 && params.ratio < 1.0) {
            return bad("ratio", params.ratio, "a post-yield ratio in [0, 1)");
        }
        let virgin = History { d: 0.0, z: 0.0, f: 0.0, k_t: params.fy / params.dy };
        Ok(BoucWen { params, committed: virgin, trial: virgin })
    }

    /// z at the end of an increment `dd` from `z0`, and dz/dd.
    fn integrate(&self, z0: f64, dd: f64, d: f64) -> Result<(f64, f64), MaterialError> {
        let p = &self.params;
        let z_elastic = z0 + dd / p.dy;
        if dd * z_elastic <= 0.0 {
            return Ok((z_elastic, 1.0 / p.dy));
        }
        // Loading: w = s z in (0, 1] solves g(w) = w - s z0 - a (1 - w^n) = 0.
        let s = dd.signum();
        let a = dd.abs() / p.dy;
        let n = p.exponent;
        let g = |w: f64| w - s * z0 - a * (1.0 - w.powf(n));
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        let mut w = (s * z_elastic).clamp(0.0, 1.0);
        for _ in 0..100 {
            let gw = g(w);
            if gw.abs() <= 1e-15 {
                break;
            }
            if gw > 0.0 {
                hi = w;
            } else {
                lo = w;
            }
            let slope = 1.0 + a * n * w.powf(n - 1.0);
            let mut next = w - gw / slope;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if (next - w).abs() <= 1e-16 {
                w = next;
                break;
            }
            w = next;
        }
        if g(w).abs() > 1e-10 {
            return Err(MaterialError::NoConvergence { material: "BoucWen", d_mm: d });
        }
        let dz = (1.0 - w.powf(n)) / (p.dy * (1.0 + a * n * w.powf(n - 1.0)));
        Ok((s * w, dz))
    }
}

impl UniaxialMaterial for BoucWen {
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError> {
        check_finite(d)?;
        let c = self.committed;
        let dd = d - c.d;
        if dd == 0.0 {
            self.trial = c;
            return Ok(());
        }
        let (z, dz) = self.integrate(c.z, dd, d)?;
        let p = &self.params;
        let k = p.fy / p.dy;
        let f = p.ratio * k * d + (1.0 - p.ratio) * p.fy * z;
        let k_t = p.ratio * k + (1.0 - p.ratio) * p.fy * dz;
        self.trial = History { d, z, f, k_t };
        Ok(())
    }
    fn force(&self) -> f64 {
        self.trial.f
    }
    fn tangent(&self) -> f64 {
        self.trial.k_t
    }
    fn initial_tangent(&self) -> f64 {
        self.params.fy / self.params.dy
    }
    fn commit(&mut self) {
        self.committed = self.trial;
    }
    fn revert(&mut self) {
        self.trial = self.committed;
    }
    fn boxed_clone(&self) -> Box<dyn UniaxialMaterial> {
        Box::new(BoucWen::new(self.params).expect("parameters were checked"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn link(n: f64) -> BoucWen {
        BoucWen::new(BoucWenParams { fy: 2.0, dy: 0.1, exponent: n, ratio: 0.0 }).unwrap()
    }

    #[test]
    fn saturates_at_the_yield_force() {
        let mut m = link(2.0);
        for i in 1..=200 {
            m.set_trial(0.01 * i as f64).unwrap();
            m.commit();
        }
        assert!((m.force() - 2.0).abs() < 1e-6, "{}", m.force());
        assert!(m.tangent().abs() < 1e-4);
    }

    #[test]
    fn n_equal_one_has_the_closed_form_of_backward_euler() {
        // n = 1, one step from z = 0: w = a (1 - w) -> w = a / (1 + a).
        let mut m = link(1.0);
        m.set_trial(0.05).unwrap();
        let a = 0.5;
        assert!((m.force() - 2.0 * a / (1.0 + a)).abs() < 1e-12);
    }

    /// Monotonic loading from z = 0 has closed forms in x = d / dy:
    /// n = 1: z = 1 - exp(-x); n = 2: z = tanh(x). Backward Euler with
    /// steps of dy / 1000 is first-order accurate, error about 1e-4.
    #[test]
    fn monotonic_loading_matches_the_closed_forms() {
        for (n, exact) in [(1.0, (|x: f64| 1.0 - (-x).exp()) as fn(f64) -> f64), (2.0, f64::tanh)] {
            let mut m = link(n);
            for i in 1..=3000 {
                let d = 0.1 * i as f64 / 1000.0;
                m.set_trial(d).unwrap();
                m.commit();
                if i % 500 == 0 {
                    let z = m.force() / 2.0;
                    assert!((z - exact(d / 0.1)).abs() < 2e-4, "n {n} d {d}: z {z}");
                }
            }
        }
    }

    #[test]
    fn unloads_with_the_elastic_stiffness() {
        let mut m = link(20.0);
        m.set_trial(1.0).unwrap();
        m.commit();
        let f0 = m.force();
        m.set_trial(0.99).unwrap();
        assert!((m.force() - (f0 - 0.01 * 20.0)).abs() < 1e-9);
        assert_eq!(m.tangent(), 20.0);
    }
}
