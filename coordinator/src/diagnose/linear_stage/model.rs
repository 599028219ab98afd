//! One point of the linear stage: the baseline's linear model with the
//! linear-form parameters at a unit-cube point, every linear run simulated
//! by modal superposition ([`fe::ceiling::simulate_linear_runs`]: one eigen
//! solution per point, milliseconds per run), judged against the measured
//! runs (the channel fits of [`Evaluation::fits`]) and `modal.csv`
//! ([`modal_fit`]).

use super::priors::line_prior_rows;
use crate::bundle::Bundle;
use crate::diagnose::cause::Prior;
use crate::diagnose::fit::{measured_sensors, neg_log_lik, ChannelFit, Evaluation, Simulated};
use crate::diagnose::modal_fit::{modal_fit, sway_modes, usable, ModalFit};
use crate::specimen::{base_input, fe_sensor, to_bundle_units};
use fe::ceiling::{damped_model, simulate_linear_runs_on, BaseInput, Sensor};

/// The modes superposed: enough that the modes left out respond
/// quasi-statically to inputs below 20 Hz on the ceilings of a lab's table
/// (the forty lowest of a 2.4 m x 3.6 m grid reach 60 Hz; `fe`'s test
/// `the_lowest_forty_modes_miss_little` measures what they leave out), at
/// most as many as the model has DOFs with mass.
pub const MODES: usize = 40;

/// Modes of the basis a search's forward differences are reanalysed on
/// (Rayleigh–Ritz, [`fe::eigen::ritz`]), per mode a point uses: 1.5. A
/// stepped point's lowest modes are then the projection's on half again as
/// many: their frequencies' first-order change exact, their shapes' change
/// exact within the basis and missing only the coupling to modes beyond it,
/// whose weight falls with the distance in frequency. The function values
/// the search compares are never reanalysed.
pub const BASIS_SHARE: f64 = 1.5;

/// The linear model of a bundle on its linear runs.
pub struct LinearModel<'a> {
    /// The bundle.
    pub bundle: &'a Bundle,
    /// The runs taken as linear (bundle indices).
    pub runs: Vec<usize>,
    /// The parameters and their priors.
    pub priors: Vec<Prior>,
}

/// What one point gives: the channel fits and residuals of the linear runs
/// and the modal fit.
#[derive(Debug, Clone)]
pub struct Judged {
    /// One fit per (run, measured sensor), in [`Evaluation::fits`] order.
    pub channels: Vec<ChannelFit>,
    /// Each channel's residual (simulated − measured; NaN where missing).
    pub residuals: Vec<Vec<f64>>,
    /// The frequencies against `modal.csv` (None: the bundle has none).
    pub modal: Option<ModalFit>,
    /// Every superposed mode's frequency (Hz), sway and vertical.
    pub modes_hz: Vec<f64>,
    /// Each superposed mode's damping ratio.
    pub modal_damping: Vec<f64>,
    /// The line factors' prior, whitened ([`super::priors::line_prior_rows`]).
    pub prior_rows: Vec<f64>,
}

impl Judged {
    /// −log L under channel weights `n_eff`, the frequencies and the line
    /// factors' prior included (the search's objective, −log posterior).
    pub fn neg_log_lik(&self, n_eff: &[f64]) -> f64 {
        let prior = 0.5 * self.prior_rows.iter().map(|r| r * r).sum::<f64>();
        neg_log_lik(&self.channels, n_eff)
            + self.modal.as_ref().map_or(0.0, |m| m.neg_log_lik)
            + prior
    }
}

impl LinearModel<'_> {
    /// The baseline's evaluation with these priors on the linear runs (its
    /// setup maps a point to FE parameters and solver options).
    pub fn evaluation(&self) -> Evaluation<'_> {
        Evaluation::baseline(self.bundle, &self.priors, &self.runs)
    }

    /// Physical values of unit-cube point `u`.
    pub fn theta(&self, u: &[f64]) -> Vec<f64> {
        u.iter().zip(&self.priors).map(|(u, p)| p.at(*u)).collect()
    }

    /// The linear runs simulated at `u` (bundle units) with the modes.
    pub fn simulate(&self, u: &[f64]) -> Result<(Vec<Simulated>, Judged), String> {
        self.simulate_on(u, None)
    }

    /// The modes at `u` that [`judge_near`](Self::judge_near) (or, with
    /// `modal_only`, [`judge_modal_near`](Self::judge_modal_near)) reanalyse
    /// points near it on: [`BASIS_SHARE`] times as many as a point
    /// superposes (or fits to `modal.csv`).
    pub fn basis(&self, u: &[f64], modal_only: bool) -> Result<Vec<Vec<f64>>, String> {
        let ev = self.evaluation();
        let theta = self.theta(u);
        if modal_only {
            return ev.modal_basis(&theta, BASIS_SHARE).ok_or("the bundle has no modal.csv")?;
        }
        let (spec, params, opts) = ev.setup(&theta)?;
        let wanted = (MODES as f64 * BASIS_SHARE).ceil() as usize;
        let dm = damped_model(&spec, &params, &opts, wanted).map_err(|e| e.to_string())?;
        Ok(dm.modal.shapes)
    }

    /// [`judge`](Self::judge) at a point near the one whose modes `basis`
    /// holds ([`basis`](Self::basis)), its modes by Rayleigh–Ritz on them.
    pub fn judge_near(&self, u: &[f64], basis: &[Vec<f64>]) -> Result<Judged, String> {
        self.simulate_on(u, Some(basis)).map(|(_, j)| j)
    }

    /// [`judge_modal`](Self::judge_modal) near the point whose modes
    /// `basis` holds, by Rayleigh–Ritz on them.
    pub fn judge_modal_near(&self, u: &[f64], basis: &[Vec<f64>]) -> Result<Judged, String> {
        self.judge_modal_on(u, Some(basis))
    }

    /// [`simulate`](Self::simulate), the modes by Rayleigh–Ritz on `basis`
    /// when given and fitting the mesh.
    fn simulate_on(
        &self,
        u: &[f64],
        basis: Option<&[Vec<f64>]>,
    ) -> Result<(Vec<Simulated>, Judged), String> {
        let ev = self.evaluation();
        let (spec, params, opts) = ev.setup(&self.theta(u))?;
        let inputs: Vec<(BaseInput, Vec<Sensor>)> = self
            .runs
            .iter()
            .map(|&k| {
                let run = &self.bundle.runs[k];
                let sensors = measured_sensors(self.bundle, run);
                (base_input(run), sensors.iter().map(fe_sensor).collect())
            })
            .collect();
        let refs: Vec<(&BaseInput, &[Sensor])> =
            inputs.iter().map(|(i, s)| (i, s.as_slice())).collect();
        let lins = simulate_linear_runs_on(&spec, &params, &refs, &opts, MODES, basis)
            .map_err(|e| format!("linear model: {e}"))?;
        let sims: Vec<Simulated> = self
            .runs
            .iter()
            .zip(&lins)
            .map(|(&k, lin)| {
                let sensors = measured_sensors(self.bundle, &self.bundle.runs[k]);
                sensors
                    .iter()
                    .zip(&lin.simulation.sensors)
                    .map(|(s, h)| {
                        let f = to_bundle_units(s.kind);
                        (s.id.clone(), h.values.iter().map(|v| v * f).collect())
                    })
                    .collect()
            })
            .collect();
        let first = lins.first().ok_or("no linear run")?;
        let (modes_hz, modal_damping) = (first.modes_hz.clone(), first.modal_damping.clone());
        let (channels, residuals) = ev.fits(&sims);
        let modal = self.modal(&sway_modes(&modes_hz, &first.horizontal_share))?;
        let prior_rows = line_prior_rows(&self.priors, &self.theta(u));
        Ok((sims, Judged { channels, residuals, modal, modes_hz, modal_damping, prior_rows }))
    }

    /// [`simulate`](Self::simulate) without the histories.
    pub fn judge(&self, u: &[f64]) -> Result<Judged, String> {
        self.simulate(u).map(|(_, j)| j)
    }

    /// The frequencies alone at `u` (one eigen solution, no run): a
    /// [`Judged`] without channels; an error without `modal.csv`.
    pub fn judge_modal(&self, u: &[f64]) -> Result<Judged, String> {
        self.judge_modal_on(u, None)
    }

    fn judge_modal_on(&self, u: &[f64], basis: Option<&[Vec<f64>]>) -> Result<Judged, String> {
        let m = (self.evaluation().modal_fit_on(&self.theta(u), basis))
            .ok_or("the bundle has no modal.csv")??;
        let modes_hz = m.eigen_hz.clone();
        Ok(Judged {
            channels: vec![],
            residuals: vec![],
            modal: Some(m),
            modes_hz,
            modal_damping: vec![],
            prior_rows: line_prior_rows(&self.priors, &self.theta(u)),
        })
    }

    /// The fit of `modes_hz` to `modal.csv` (None without one).
    fn modal(&self, modes_hz: &[f64]) -> Result<Option<ModalFit>, String> {
        let Some(entries) = self.bundle.modal.as_deref() else { return Ok(None) };
        if usable(entries).is_empty() {
            return Ok(None);
        }
        modal_fit(entries, modes_hz, crate::specimen::fe_step_s(self.bundle, &self.runs))
            .map(Some)
            .ok_or_else(|| format!("the linear model has {} modes: too few", modes_hz.len()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::farm_executor_tests::tiny_bundle;
    use crate::diagnose::linear_stage::{linear_priors, LINEAR_PRIORS, LINE_LOG_SD};

    /// The line factors' log-normal prior is the objective's only term
    /// that needs no run: ½ Σ (ln f / sd)², zero at the nominal factors.
    #[test]
    fn the_line_factors_prior_enters_the_objective() {
        let tmp = tempfile::tempdir().unwrap();
        let b = tiny_bundle(tmp.path());
        let priors = linear_priors(&b);
        let lines = priors.len() - LINEAR_PRIORS.len();
        let model = LinearModel { bundle: &b, runs: vec![0], priors };
        let mut u: Vec<f64> = (model.priors.iter())
            .zip(crate::diagnose::linear_stage::nominal(&model.priors))
            .map(|(p, v)| p.unit(v))
            .collect();
        let at = model.judge(&u).unwrap();
        assert_eq!(at.prior_rows, vec![0.0; lines]);
        let last = u.len() - 1;
        u[last] = model.priors[last].unit(1.5);
        let moved = model.judge(&u).unwrap();
        let expected = (1.5f64.ln() / LINE_LOG_SD).powi(2) / 2.0;
        let sum_sq: f64 = moved.prior_rows.iter().map(|r| r * r).sum();
        assert!((0.5 * sum_sq - expected).abs() < 1e-9, "{sum_sq}");
        let n_eff = vec![1.0; moved.channels.len()];
        let without: f64 = moved.neg_log_lik(&n_eff) - 0.5 * sum_sq;
        assert!(
            (without - Judged { prior_rows: vec![], ..moved.clone() }.neg_log_lik(&n_eff)).abs()
                < 1e-9
        );
    }

    /// A forward difference reanalysed on the centre's modes is the exact
    /// one: on the tiny bundle, at a spread point, every column of the
    /// residuals' and the frequencies' differences that moves them by more
    /// than 1e-3 of the largest agrees within 2 % (measured: 0.92 % at most,
    /// K_cc2's), and what a reanalysis misses of any column is below 1e-3
    /// of the largest column (measured: 5.2e-5, K_rod_rot's).
    #[test]
    fn reanalysed_differences_are_the_exact_ones() {
        let tmp = tempfile::tempdir().unwrap();
        let b = tiny_bundle(tmp.path());
        let runs: Vec<usize> = (0..b.runs.len()).collect();
        let priors = linear_priors(&b);
        let d = priors.len();
        let model = LinearModel { bundle: &b, runs, priors };
        let u: Vec<f64> = (0..d).map(|k| (0.2 + 0.37 * k as f64) % 1.0).collect();
        let flat = |j: &Judged| -> Vec<f64> {
            let mut v: Vec<f64> = j
                .residuals
                .iter()
                .flatten()
                .map(|x| if x.is_finite() { *x } else { 0.0 })
                .collect();
            v.extend(j.modal.as_ref().map(|m| m.residuals_hz()).unwrap_or_default());
            v
        };
        let norm = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let centre = flat(&model.judge(&u).unwrap());
        let basis = model.basis(&u, false).unwrap();
        assert!(basis.len() > MODES, "the basis holds more modes than a point uses");
        let mut columns = vec![];
        for i in 0..d {
            let mut v = u.clone();
            v[i] += if v[i] + 1e-3 <= 1.0 { 1e-3 } else { -1e-3 };
            let exact = flat(&model.judge(&v).unwrap());
            let near = flat(&model.judge_near(&v, &basis).unwrap());
            let de: Vec<f64> = exact.iter().zip(&centre).map(|(a, c)| a - c).collect();
            let miss: Vec<f64> = exact.iter().zip(&near).map(|(a, n)| a - n).collect();
            columns.push((model.priors[i].name, norm(&de), norm(&miss)));
        }
        let largest = columns.iter().map(|c| c.1).fold(0.0, f64::max);
        assert!(largest > 0.0);
        for (name, size, miss) in &columns {
            assert!(*miss < 1e-3 * largest, "{name}: missed by {miss} (largest column {largest})");
            if *size > 1e-3 * largest {
                assert!(miss / size < 0.02, "{name}: relative error {}", miss / size);
            }
        }
    }

    /// At any point the modal superposition gives the FE transient's
    /// histories on the same linear model (to the modes it leaves out),
    /// the grid lines' along factors included.
    #[test]
    fn the_linear_model_is_the_baselines_fe_model() {
        let tmp = tempfile::tempdir().unwrap();
        let b = tiny_bundle(tmp.path());
        let runs: Vec<usize> = (0..b.runs.len()).collect();
        let priors = linear_priors(&b);
        assert!(priors.len() > LINEAR_PRIORS.len(), "the tiny bundle's lines have factors");
        let d = priors.len();
        let model = LinearModel { bundle: &b, runs: runs.clone(), priors };
        let spread: Vec<f64> = (0..d).map(|k| (0.2 + 0.37 * k as f64) % 1.0).collect();
        for u in [vec![0.5; d], spread] {
            let (sims, _) = model.simulate(&u).unwrap();
            let fe = model.evaluation().simulate(&model.theta(&u)).unwrap();
            for (run_l, run_f) in sims.iter().zip(&fe) {
                for ((id, l), (_, f)) in run_l.iter().zip(run_f) {
                    let rms =
                        |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
                    let diff: Vec<f64> = l.iter().zip(f).map(|(a, b)| a - b).collect();
                    // A sensor across an unshaken direction reads round-off.
                    let e = rms(&diff) / rms(f).max(1e-6);
                    assert!(e < 1e-4, "sensor {id} at {u:?}: relative RMS difference {e}");
                }
            }
        }
    }
}
