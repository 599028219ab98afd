//! Step-size rules for stochastic gradient ascent on lambda.
//!
//! Robbins–Monro rho_t = eta (tau + t)^−kappa (kappa in (0.5, 1]); AdaGrad
//! rho_t = eta / sqrt(sum of squared gradients) as Ranganath et al. use;
//! Adam (Kingma & Ba 2015) with the rate decaying as lr (1 + t/decay)^−kappa
//! (kappa in (0.5, 1] meets the Robbins–Monro conditions).

/// How gradients become steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepRule {
    /// rho_t = eta (tau + t)^−kappa, the same for every component.
    RobbinsMonro {
        /// Scale eta.
        eta: f64,
        /// Delay tau ≥ 0.
        tau: f64,
        /// Forgetting rate kappa in (0.5, 1].
        kappa: f64,
    },
    /// Per-component eta / sqrt(1 + sum g²).
    AdaGrad {
        /// Scale eta.
        eta: f64,
    },
    /// Adam with bias correction.
    Adam {
        /// Learning rate.
        lr: f64,
        /// First-moment decay.
        beta1: f64,
        /// Second-moment decay.
        beta2: f64,
        /// Time scale of the decay lr (1 + t/decay)^−kappa (infinite: none).
        decay: f64,
        /// Decay exponent kappa.
        kappa: f64,
    },
}

/// Running moments a rule keeps between steps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StepState {
    /// First moment (Adam).
    pub m: Vec<f64>,
    /// Second moment (Adam) or squared-gradient sum (AdaGrad).
    pub v: Vec<f64>,
    /// Steps taken.
    pub t: u64,
}

impl StepRule {
    /// Adam with lr 0.05 and the usual betas, decaying as (1 + t/200)^−0.75.
    pub fn adam_default() -> Self {
        StepRule::Adam { lr: 0.05, beta1: 0.9, beta2: 0.999, decay: 200.0, kappa: 0.75 }
    }

    /// Ascends: lambda += step(grad); updates `st`.
    pub fn apply(&self, lambda: &mut [f64], grad: &[f64], st: &mut StepState) {
        if st.m.len() != grad.len() {
            *st = StepState { m: vec![0.0; grad.len()], v: vec![0.0; grad.len()], t: 0 };
        }
        st.t += 1;
        let t = st.t as f64;
        match *self {
            StepRule::RobbinsMonro { eta, tau, kappa } => {
                let rho = eta * (tau + t).powf(-kappa);
                lambda.iter_mut().zip(grad).for_each(|(l, g)| *l += rho * g);
            }
            StepRule::AdaGrad { eta } => {
                for j in 0..grad.len() {
                    st.v[j] += grad[j] * grad[j];
                    lambda[j] += eta * grad[j] / (1.0 + st.v[j]).sqrt();
                }
            }
            StepRule::Adam { lr, beta1, beta2, decay, kappa } => {
                let rate = lr * (1.0 + t / decay).powf(-kappa);
                for j in 0..grad.len() {
                    st.m[j] = beta1 * st.m[j] + (1.0 - beta1) * grad[j];
                    st.v[j] = beta2 * st.v[j] + (1.0 - beta2) * grad[j] * grad[j];
                    let mh = st.m[j] / (1.0 - beta1.powf(t));
                    let vh = st.v[j] / (1.0 - beta2.powf(t));
                    lambda[j] += rate * mh / (vh.sqrt() + 1e-8);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_rule_climbs_a_concave_quadratic() {
        let rules = [
            StepRule::RobbinsMonro { eta: 0.5, tau: 1.0, kappa: 0.7 },
            StepRule::AdaGrad { eta: 0.5 },
            StepRule::adam_default(),
        ];
        for rule in rules {
            let (mut x, mut st) = (vec![5.0], StepState::default());
            for _ in 0..3000 {
                let g = vec![-(x[0] - 1.0)];
                rule.apply(&mut x, &g, &mut st);
            }
            assert!((x[0] - 1.0).abs() < 1e-2, "{rule:?}: {}", x[0]);
        }
    }
}
