//! Scores candidate parameter subsets of one Gaussian-noise calibration
//! problem and names the winner under each criterion (seed Table 6.3–6.4).

use super::criteria::{aic, bic, dic, icomp, mdl, CandidateScore};
use super::fisher::{fisher_total, jacobian, log_fisher_integral, FisherIntegral};
use super::generalisability::gr_percent;
use super::ml::fit_ml;
use crate::calibration::{
    CalibError, GaussianLikelihood, Hyper, Likelihood, Posterior, Simulator, SubsetSimulator,
    UniformBox,
};
use crate::mcmc::{AdaptiveMetropolis, McmcError, McmcSettings};
use std::collections::BTreeMap;

/// The full problem: simulator over all parameters, their prior box, data.
pub struct SelectionProblem<S> {
    /// Simulator taking every parameter of `prior`.
    pub sim: S,
    /// Prior box of every parameter.
    pub prior: UniformBox,
    /// Observations (n_obs).
    pub y: Vec<f64>,
    /// Known noise sd (units of y).
    pub noise_sd: f64,
    /// True responses at the observation points, for Gr % (optional).
    pub truth: Option<Vec<f64>>,
}

/// A candidate model: which parameters are free, and the values of the rest.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Name in tables.
    pub name: String,
    /// Free parameter names.
    pub free: Vec<String>,
    /// Values of the parameters that are not free.
    pub fixed: BTreeMap<String, f64>,
}

/// Numerical settings of the selection.
#[derive(Debug, Clone, PartialEq)]
pub struct SelectionSettings {
    /// Starts of the multi-start ML fit.
    pub starts: usize,
    /// QMC points per replicate for the Fisher integral.
    pub qmc_points: usize,
    /// QMC replicates (error estimate).
    pub qmc_replicates: usize,
    /// Posterior sampler for the DIC.
    pub mcmc: McmcSettings,
    /// Seed for starts, QMC scrambles and MCMC.
    pub seed: u64,
}

impl Default for SelectionSettings {
    fn default() -> Self {
        Self {
            starts: 16,
            qmc_points: 4096,
            qmc_replicates: 8,
            mcmc: McmcSettings { iters: 8000, warmup: 3000, ..McmcSettings::default() },
            seed: 1,
        }
    }
}

/// Scores of every candidate and the winner per criterion.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SelectionTable {
    /// One row per candidate, in input order.
    pub candidates: Vec<CandidateScore>,
    /// Criterion name → winning candidate name.
    pub selected: BTreeMap<String, String>,
}

/// Why selection failed.
#[derive(Debug, thiserror::Error)]
pub enum SelectionError {
    /// A candidate names a parameter the problem does not have.
    #[error("candidate `{candidate}`: unknown parameter `{name}` (known: {known})")]
    UnknownParameter {
        /// Candidate name.
        candidate: String,
        /// The parameter.
        name: String,
        /// Known names, comma-separated.
        known: String,
    },
    /// A parameter is neither free nor fixed.
    #[error("candidate `{candidate}`: parameter `{name}` is neither free nor given a fixed value")]
    MissingFixed {
        /// Candidate name.
        candidate: String,
        /// The parameter.
        name: String,
    },
    /// The model or data are invalid.
    #[error("candidate `{candidate}`: {source}")]
    Calib {
        /// Candidate name.
        candidate: String,
        /// The cause.
        source: CalibError,
    },
    /// The DIC sampler failed.
    #[error("candidate `{candidate}`: {source}")]
    Mcmc {
        /// Candidate name.
        candidate: String,
        /// The cause.
        source: McmcError,
    },
}

/// Free indices and the full base vector of a candidate.
fn layout(prior: &UniformBox, c: &Candidate) -> Result<(Vec<usize>, Vec<f64>), SelectionError> {
    let known = || prior.names.join(", ");
    let mut free = Vec::new();
    for name in &c.free {
        let i = prior.names.iter().position(|n| n == name).ok_or_else(|| {
            SelectionError::UnknownParameter {
                candidate: c.name.clone(),
                name: name.clone(),
                known: known(),
            }
        })?;
        free.push(i);
    }
    if let Some(name) = c.fixed.keys().find(|n| !prior.names.contains(n)) {
        return Err(SelectionError::UnknownParameter {
            candidate: c.name.clone(),
            name: name.clone(),
            known: known(),
        });
    }
    let mut base = Vec::new();
    for (i, name) in prior.names.iter().enumerate() {
        match c.fixed.get(name) {
            Some(v) => base.push(*v),
            None if free.contains(&i) => base.push(0.5 * (prior.lower[i] + prior.upper[i])),
            None => {
                return Err(SelectionError::MissingFixed {
                    candidate: c.name.clone(),
                    name: name.clone(),
                })
            }
        }
    }
    Ok((free, base))
}

/// Scores one candidate.
pub fn score_candidate<S: Simulator>(
    p: &SelectionProblem<S>,
    c: &Candidate,
    s: &SelectionSettings,
) -> Result<CandidateScore, SelectionError> {
    let calib = |source| SelectionError::Calib { candidate: c.name.clone(), source };
    let (free, base) = layout(&p.prior, c)?;
    let sub = SubsetSimulator::new(&p.sim, free.clone(), base).map_err(calib)?;
    let pick = |v: &[f64]| free.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    let box_ = UniformBox::new(
        free.iter().map(|&i| p.prior.names[i].clone()).collect(),
        pick(&p.prior.lower),
        pick(&p.prior.upper),
    )
    .map_err(calib)?;
    let lik =
        GaussianLikelihood::new(&sub, p.y.clone(), Hyper::Fixed(p.noise_sd)).map_err(calib)?;
    let (k, n) = (free.len(), p.y.len());
    let ml = fit_ml(&lik, &box_, s.starts, s.seed as u32);
    let width: Vec<f64> = (0..k).map(|j| box_.upper[j] - box_.lower[j]).collect();
    let fisher = fisher_total(&jacobian(&sub, &ml.theta, &width).map_err(calib)?, p.noise_sd);
    let identifiable = k <= n;
    let fi = if identifiable {
        log_fisher_integral(&sub, &box_, p.noise_sd, s.qmc_points, s.qmc_replicates, s.seed as u32)
            .map_err(calib)?
    } else {
        FisherIntegral { log_value: f64::NAN, log_se: f64::NAN, points: 0 }
    };
    let (dic_value, p_d) = dic_of(&box_, &lik, &ml.theta, &s.mcmc, &c.name)?;
    let gr = match &p.truth {
        Some(t) => Some(gr_percent(&sub.predict(&ml.theta).map_err(calib)?.mean, t)),
        None => None,
    };
    let nll = ml.neg_log_likelihood;
    Ok(CandidateScore {
        name: c.name.clone(),
        free_parameters: c.free.clone(),
        theta_hat: ml.theta,
        neg_log_likelihood: nll,
        aic: aic(nll, k),
        bic: bic(nll, k, n),
        dic: dic_value,
        p_d,
        icomp: if identifiable { icomp(nll, &fisher).unwrap_or(f64::INFINITY) } else { f64::NAN },
        mdl: mdl(nll, k, n, fi.log_value),
        log_fisher_integral: fi.log_value,
        log_fisher_integral_se: fi.log_se,
        gr_percent: gr,
        identifiable,
    })
}

/// (DIC, p_D) from an adaptive-Metropolis posterior started at theta-hat.
fn dic_of<L: Likelihood>(
    box_: &UniformBox,
    lik: &L,
    theta_hat: &[f64],
    mcmc: &McmcSettings,
    candidate: &str,
) -> Result<(f64, f64), SelectionError> {
    let post = Posterior::new(box_.clone(), lik)
        .map_err(|source| SelectionError::Calib { candidate: candidate.into(), source })?;
    let init = box_.to_unconstrained(theta_hat).unwrap_or_else(|| vec![0.0; box_.dim()]);
    let run = AdaptiveMetropolis::new(McmcSettings { init_sd: 0.01, ..mcmc.clone() })
        .run(&post, &init)
        .map_err(|source| SelectionError::Mcmc { candidate: candidate.into(), source })?;
    let draws: Vec<Vec<f64>> = run.draws().iter().map(|z| box_.to_physical(z)).collect();
    let dev = |t: &[f64]| -2.0 * lik.log_likelihood(t).unwrap_or(f64::NEG_INFINITY);
    let devs: Vec<f64> = draws.iter().map(|t| dev(t)).collect();
    let mean: Vec<f64> = (0..box_.dim())
        .map(|j| draws.iter().map(|t| t[j]).sum::<f64>() / draws.len() as f64)
        .collect();
    Ok(dic(&devs, dev(&mean)))
}

/// Scores every candidate and names the winner of each criterion.
pub fn select<S: Simulator>(
    p: &SelectionProblem<S>,
    candidates: &[Candidate],
    s: &SelectionSettings,
) -> Result<SelectionTable, SelectionError> {
    let scores: Vec<CandidateScore> =
        candidates.iter().map(|c| score_candidate(p, c, s)).collect::<Result<_, _>>()?;
    let mut selected = BTreeMap::new();
    type Criterion = (&'static str, fn(&CandidateScore) -> f64);
    let crits: [Criterion; 5] = [
        ("aic", |c| c.aic),
        ("bic", |c| c.bic),
        ("dic", |c| c.dic),
        ("icomp", |c| c.icomp),
        ("mdl", |c| c.mdl),
    ];
    for (name, f) in crits {
        let defined = scores.iter().filter(|c| !f(c).is_nan());
        if let Some(best) = defined.min_by(|a, b| f(a).total_cmp(&f(b))) {
            selected.insert(name.to_string(), best.name.clone());
        }
    }
    if scores.iter().all(|c| c.gr_percent.is_some()) {
        if let Some(best) = scores.iter().max_by(|a, b| {
            a.gr_percent.unwrap_or(f64::NAN).total_cmp(&b.gr_percent.unwrap_or(f64::NAN))
        }) {
            selected.insert("gr_percent".to_string(), best.name.clone());
        }
    }
    Ok(SelectionTable { candidates: scores, selected })
}
