//! Information criteria of a fitted model; `nll` is −log L(theta-hat) with
//! all constants, k the number of free parameters, n the number of
//! observations.
//!
//! AIC = 2 nll + 2k (Akaike 1974); BIC = 2 nll + k ln n (Schwarz 1978);
//! DIC = D̄ + p_D, p_D = D̄ − D(θ̄), D = −2 log L (Spiegelhalter et al. 2002);
//! ICOMP = 2 nll + 2 C1(F⁻¹), C1(S) = (k/2) ln(tr S / k) − ½ ln det S, F the
//! total Fisher information at theta-hat (Bozdogan 1988); MDL (FIA, seed
//! eq. 3.63) = nll + (k/2) ln(n / 2π) + ln ∫ sqrt(det I1(θ)) dθ.

use nalgebra::DMatrix;
use std::f64::consts::PI;

/// Every criterion for one candidate (lower is better except Gr %).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CandidateScore {
    /// Candidate name.
    pub name: String,
    /// Free parameters.
    pub free_parameters: Vec<String>,
    /// theta-hat of the free parameters (physical units).
    pub theta_hat: Vec<f64>,
    /// −log L(theta-hat).
    pub neg_log_likelihood: f64,
    /// Akaike information criterion.
    pub aic: f64,
    /// Bayesian information criterion.
    pub bic: f64,
    /// Deviance information criterion.
    pub dic: f64,
    /// Effective number of parameters p_D of the DIC.
    pub p_d: f64,
    /// Bozdogan's ICOMP (IFIM form).
    pub icomp: f64,
    /// Minimum description length (Fisher-information approximation).
    pub mdl: f64,
    /// ln ∫ sqrt(det I1) over the prior box.
    pub log_fisher_integral: f64,
    /// Standard error of `log_fisher_integral` (QMC replicates).
    pub log_fisher_integral_se: f64,
    /// Generalisability Gr % (seed eq. 6.12), if the truth is known.
    pub gr_percent: Option<f64>,
    /// False when k exceeds the number of observations: I1 is then singular
    /// everywhere, and MDL, ICOMP and the Fisher integral are undefined (NaN).
    pub identifiable: bool,
}

/// AIC = 2 nll + 2k.
pub fn aic(nll: f64, k: usize) -> f64 {
    2.0 * nll + 2.0 * k as f64
}

/// BIC = 2 nll + k ln n.
pub fn bic(nll: f64, k: usize, n: usize) -> f64 {
    2.0 * nll + k as f64 * (n as f64).ln()
}

/// (DIC, p_D) from deviances −2 log L of posterior draws and the deviance at the posterior mean.
pub fn dic(deviance_draws: &[f64], deviance_at_mean: f64) -> (f64, f64) {
    let dbar = deviance_draws.iter().sum::<f64>() / deviance_draws.len() as f64;
    let p_d = dbar - deviance_at_mean;
    (dbar + p_d, p_d)
}

/// ICOMP = 2 nll + 2 C1(F⁻¹) for total Fisher information `fisher` (k, k); None if singular.
pub fn icomp(nll: f64, fisher: &DMatrix<f64>) -> Option<f64> {
    let k = fisher.nrows() as f64;
    let cov = fisher.clone().try_inverse()?;
    let det = cov.determinant();
    (det > 0.0).then(|| 2.0 * nll + 2.0 * (0.5 * k * (cov.trace() / k).ln() - 0.5 * det.ln()))
}

/// MDL = nll + (k/2) ln(n / 2π) + ln ∫ sqrt(det I1).
pub fn mdl(nll: f64, k: usize, n: usize, log_fisher_integral: f64) -> f64 {
    nll + 0.5 * k as f64 * (n as f64 / (2.0 * PI)).ln() + log_fisher_integral
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icomp_of_isotropic_information_has_no_penalty() {
        // C1 vanishes when the covariance is a multiple of the identity.
        let f = DMatrix::identity(3, 3) * 4.0;
        assert!((icomp(5.0, &f).unwrap() - 10.0).abs() < 1e-12);
    }

    #[test]
    fn dic_of_constant_deviance_has_no_penalty() {
        assert_eq!(dic(&[3.0, 3.0], 3.0), (3.0, 0.0));
    }

    #[test]
    fn mdl_matches_benchmark_arithmetic() {
        // Benchmark §4: FIA 1.947 for (k, c, m) with ln ∫ = 10.006, n = 20.
        let nll = 1.947 - 1.5 * (20.0 / (2.0 * PI)).ln() - 10.006;
        assert!((mdl(nll, 3, 20, 10.006) - 1.947).abs() < 1e-12);
    }
}
