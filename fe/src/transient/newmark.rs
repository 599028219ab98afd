//! Newmark-β constants and the per-DOF state update (Newmark 1959; Chopra,
//! *Dynamics of Structures*, Table 5.4.2), displacement form: the unknown
//! of each step is u₁, and
//!
//! a₁ = (u₁ − u₀)/(β Δt²) − v₀/(β Δt) − (1/(2β) − 1) a₀,
//! v₁ = v₀ + Δt ((1 − γ) a₀ + γ a₁).
//!
//! Units: mm, mm/s, mm/s², s.

/// The constants of one step size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewmarkConstants {
    /// γ.
    pub gamma: f64,
    /// β.
    pub beta: f64,
    /// Step (s).
    pub dt_s: f64,
    /// ∂a₁/∂u₁ = 1/(β Δt²) (1/s²); the mass factor of the effective tangent.
    pub c_mass: f64,
    /// ∂v₁/∂u₁ = γ/(β Δt) (1/s); the damping factor of the effective tangent.
    pub c_damp: f64,
}

impl NewmarkConstants {
    /// Constants for γ, β and step Δt.
    pub fn new(gamma: f64, beta: f64, dt_s: f64) -> Self {
        NewmarkConstants {
            gamma,
            beta,
            dt_s,
            c_mass: 1.0 / (beta * dt_s * dt_s),
            c_damp: gamma / (beta * dt_s),
        }
    }

    /// (v₁, a₁) of one DOF from the trial u₁ and the committed (u₀, v₀, a₀).
    #[inline]
    pub fn update(&self, u1: f64, u0: f64, v0: f64, a0: f64) -> (f64, f64) {
        let (b, g, h) = (self.beta, self.gamma, self.dt_s);
        let a1 = (u1 - u0) / (b * h * h) - v0 / (b * h) - (0.5 / b - 1.0) * a0;
        let v1 = v0 + h * ((1.0 - g) * a0 + g * a1);
        (v1, a1)
    }

    /// Updates whole vectors: `v1`, `a1` from `u1` and the committed state.
    pub fn update_all(
        &self,
        u1: &[f64],
        u0: &[f64],
        v0: &[f64],
        a0: &[f64],
        v1: &mut [f64],
        a1: &mut [f64],
    ) {
        for k in 0..u1.len() {
            let (v, a) = self.update(u1[k], u0[k], v0[k], a0[k]);
            v1[k] = v;
            a1[k] = a;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Average acceleration integrates a constant acceleration exactly:
        /// u = u0 + v0 t + a t²/2 gives back v0 + a t and a.
        #[test]
        fn constant_acceleration_is_exact(u0 in -10.0..10.0f64, v0 in -10.0..10.0f64,
                                          a in -100.0..100.0f64, dt in 1e-4..0.1f64) {
            let c = NewmarkConstants::new(0.5, 0.25, dt);
            let u1 = u0 + v0 * dt + 0.5 * a * dt * dt;
            let (v1, a1) = c.update(u1, u0, v0, a);
            prop_assert!((a1 - a).abs() < 1e-6 * (1.0 + a.abs()) / dt);
            prop_assert!((v1 - (v0 + a * dt)).abs() < 1e-6 * (1.0 + v0.abs() + a.abs()));
        }

        /// The effective-tangent factors are the derivatives of the update.
        #[test]
        fn factors_are_derivatives(g in 0.5..0.8f64, b in 0.2..0.4f64, dt in 1e-3..0.05f64) {
            let c = NewmarkConstants::new(g, b, dt);
            let (v0, a0) = c.update(0.0, 0.0, 1.0, 2.0);
            let (v1, a1) = c.update(1.0, 0.0, 1.0, 2.0);
            prop_assert!(((a1 - a0) - c.c_mass).abs() < 1e-9 * c.c_mass);
            prop_assert!(((v1 - v0) - c.c_damp).abs() < 1e-9 * c.c_damp);
        }
    }

    /// Undamped SDOF, ω = 2π: average acceleration conserves the energy
    /// ½ m v² + ½ k u² exactly (Chopra §5.5).
    #[test]
    fn average_acceleration_conserves_energy() {
        let (m, k, dt) = (1.0, 4.0 * std::f64::consts::PI.powi(2), 0.05);
        let c = NewmarkConstants::new(0.5, 0.25, dt);
        let (mut u, mut v, mut a) = (1.0, 0.0, -k);
        let e0 = 0.5 * k;
        for _ in 0..1000 {
            // Linear: (k + m c_mass) u1 = m (c_mass u0 + v0/(β dt) + (1/(2β)-1) a0).
            let rhs = m * (c.c_mass * u + v / (0.25 * dt) + a);
            let u1 = rhs / (k + m * c.c_mass);
            let (v1, a1) = c.update(u1, u, v, a);
            (u, v, a) = (u1, v1, a1);
        }
        let e = 0.5 * m * v * v + 0.5 * k * u * u;
        assert!((e - e0).abs() < 1e-9 * e0, "{e} vs {e0}");
    }
}
