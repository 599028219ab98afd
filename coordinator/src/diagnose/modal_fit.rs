//! The identified natural frequencies (`modal.csv`) in a calibration's
//! likelihood. Mode k of the table is compared with the model's k-th sway
//! mode at the parameter point ([`sway_modes`]: the modes whose kinetic
//! energy is mostly horizontal, every spring at its initial tangent, as
//! the model's own modal analysis has it). Each mode is Gaussian with
//! the lab's one-sigma uncertainty plus one model-discrepancy variance
//! common to the modes, estimated at each point (profiled, as the time
//! histories' noise is): frequencies the model reproduces within the lab's
//! uncertainty count in full, a systematic misfit no parameter removes
//! counts as little as a misfit of one more channel.
//!
//! The model's frequencies are compared *as integrated*: every run is
//! simulated by Newmark's average acceleration at step h, which turns a
//! mode of frequency f at f̃ = atan(π f h)/(π h) (its rotation per step is
//! 2 atan(ω h/2); [`as_integrated_hz`]): 1.8 % below f for a 15 Hz mode at
//! 5 ms. The runs and `modal.csv` are two records of one specimen; the
//! model meets the runs at f̃, so meeting `modal.csv` at f would pull the
//! two apart by the step's period error (on the bench's seed 1, made
//! otherwise like this model, 3.3 % against 0.2 % with the truth
//! integrated at the model's own step). The model's eigenfrequencies stay
//! in [`ModalFit::eigen_hz`].
//! Units: Hz, Hz², s.

use super::fit::Evaluation;
use crate::bundle::ModalEntry;
use fe::assembly::Structure;
use fe::eigen::{horizontal_share, modal_analysis_on, LanczosSettings, ModalResult};
use fe::generator::generate;

/// Least share of a mode's kinetic energy in x and y for it to count as
/// one a shaking table identifies: its horizontal sensors see a mode that
/// moves mostly sideways, and number the modes they see, so a vertical
/// mode of the model takes no number.
pub const SWAY_SHARE: f64 = 0.5;

/// The frequencies of the modes whose horizontal share is at least
/// [`SWAY_SHARE`], in order.
pub fn sway_modes(freq_hz: &[f64], horizontal_share: &[f64]) -> Vec<f64> {
    freq_hz
        .iter()
        .zip(horizontal_share)
        .filter(|(_, s)| **s >= SWAY_SHARE)
        .map(|(f, _)| *f)
        .collect()
}

/// Highest mode number used: the model's lowest modes are the ones a
/// shaking table identifies; higher entries of the table are left out.
pub const MAX_MODE: u32 = 20;

/// Least variance of a mode (Hz²): keeps −log L finite when the lab gives no
/// uncertainty and the model matches to round-off.
const FLOOR_HZ2: f64 = 1e-8;

/// How the model's frequencies at one point meet the measured ones.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalFit {
    /// Mode numbers used (1-based).
    pub modes: Vec<u32>,
    /// Measured frequencies (Hz).
    pub measured_hz: Vec<f64>,
    /// The model's frequencies of the same modes as integrated (Hz):
    /// [`as_integrated_hz`] of [`Self::eigen_hz`] at [`Self::step_s`].
    pub model_hz: Vec<f64>,
    /// The model's eigenfrequencies of the same modes (Hz).
    pub eigen_hz: Vec<f64>,
    /// The integration step the runs are simulated at (s; 0: exact).
    pub step_s: f64,
    /// The lab's variances (Hz²; 0 when unknown).
    pub lab_var_hz2: Vec<f64>,
    /// The profiled discrepancy variance (Hz²).
    pub discrepancy_var_hz2: f64,
    /// −log L of the modes (½ log 2π dropped).
    pub neg_log_lik: f64,
}

impl ModalFit {
    /// Residuals over their standard deviations, (model − measured)/σ: the
    /// rows a Gauss–Newton step fits with weight 1.
    pub fn whitened(&self) -> Vec<f64> {
        self.residuals_hz()
            .iter()
            .zip(&self.lab_var_hz2)
            .map(|(r, v)| r / total_var(*v, self.discrepancy_var_hz2).sqrt())
            .collect()
    }

    /// Each mode's standard deviation (Hz): the lab's and the discrepancy's.
    pub fn sd_hz(&self) -> Vec<f64> {
        self.lab_var_hz2.iter().map(|v| total_var(*v, self.discrepancy_var_hz2).sqrt()).collect()
    }

    /// Model minus measured frequency of each mode (Hz).
    pub fn residuals_hz(&self) -> Vec<f64> {
        self.model_hz.iter().zip(&self.measured_hz).map(|(m, f)| m - f).collect()
    }
}

/// The entries a calibration uses: modes 1 to [`MAX_MODE`].
pub fn usable(entries: &[ModalEntry]) -> Vec<&ModalEntry> {
    entries.iter().filter(|e| e.mode >= 1 && e.mode <= MAX_MODE).collect()
}

/// The frequency (Hz) at which Newmark's average acceleration at step
/// `step_s` turns a mode of eigenfrequency `f_hz`: atan(π f h)/(π h), below
/// f by about (2π f h)²/12; `f_hz` itself at step 0.
pub fn as_integrated_hz(f_hz: f64, step_s: f64) -> f64 {
    if step_s > 0.0 {
        let x = std::f64::consts::PI * step_s;
        (x * f_hz).atan() / x
    } else {
        f_hz
    }
}

/// The fit of the model's eigenfrequencies `model_hz` (lowest first), as
/// integrated at `step_s` ([`as_integrated_hz`]), to the usable `entries`;
/// None when no entry is usable or the model has too few modes.
pub fn modal_fit(entries: &[ModalEntry], model_hz: &[f64], step_s: f64) -> Option<ModalFit> {
    let used = usable(entries);
    if used.is_empty() || used.iter().any(|e| e.mode as usize > model_hz.len()) {
        return None;
    }
    let modes: Vec<u32> = used.iter().map(|e| e.mode).collect();
    let measured_hz: Vec<f64> = used.iter().map(|e| e.freq_hz).collect();
    let eigen_hz: Vec<f64> = used.iter().map(|e| model_hz[e.mode as usize - 1]).collect();
    let model: Vec<f64> = eigen_hz.iter().map(|f| as_integrated_hz(*f, step_s)).collect();
    let lab: Vec<f64> = used.iter().map(|e| e.std_hz.map_or(0.0, |s| s * s)).collect();
    let r2: Vec<f64> = model.iter().zip(&measured_hz).map(|(m, f)| (m - f).powi(2)).collect();
    let s = profiled_discrepancy(&r2, &lab);
    Some(ModalFit {
        modes,
        measured_hz,
        model_hz: model,
        eigen_hz,
        step_s,
        neg_log_lik: neg_log_lik(&r2, &lab, s),
        lab_var_hz2: lab,
        discrepancy_var_hz2: s,
    })
}

/// A mode's variance: the lab's plus the discrepancy, at least [`FLOOR_HZ2`].
fn total_var(lab: f64, discrepancy: f64) -> f64 {
    (lab + discrepancy).max(FLOOR_HZ2)
}

/// Σ ½ log(v_i + s) + r_i² / (2 (v_i + s)): −log L of squared residuals
/// `r2` under lab variances `v` and discrepancy variance `s`.
pub fn neg_log_lik(r2: &[f64], v: &[f64], s: f64) -> f64 {
    r2.iter()
        .zip(v)
        .map(|(r2, v)| {
            let t = total_var(*v, s);
            0.5 * t.ln() + r2 / (2.0 * t)
        })
        .sum()
}

/// The discrepancy variance s ≥ 0 that minimises [`neg_log_lik`]: 0 when
/// the residuals sit within the lab's uncertainty. Above 0 the profile may
/// have several stationary points (unequal lab variances), so the best of
/// 0 and a geometric grid up to the largest r² is refined by bisection on
/// the derivative between its neighbours. With equal lab variances v it is
/// max(0, mean r² − v).
pub fn profiled_discrepancy(r2: &[f64], v: &[f64]) -> f64 {
    let h = |s: f64| neg_log_lik(r2, v, s);
    // 2 dh/ds.
    let slope = |s: f64| -> f64 {
        r2.iter()
            .zip(v)
            .map(|(r2, v)| {
                let t = total_var(*v, s);
                (t - r2) / (t * t)
            })
            .sum()
    };
    let top = r2.iter().copied().fold(0.0, f64::max);
    if top <= FLOOR_HZ2 {
        return 0.0;
    }
    const GRID: usize = 120;
    let ratio = (top / FLOOR_HZ2).powf(1.0 / (GRID - 1) as f64);
    let grid: Vec<f64> =
        std::iter::once(0.0).chain((0..GRID).map(|k| FLOOR_HZ2 * ratio.powi(k as i32))).collect();
    let values: Vec<f64> = grid.iter().map(|s| h(*s)).collect();
    let k = (0..grid.len()).min_by(|a, b| values[*a].total_cmp(&values[*b])).unwrap_or(0);
    let (mut lo, mut hi) = (grid[k.saturating_sub(1)], grid[(k + 1).min(grid.len() - 1)]);
    if !(slope(lo) < 0.0 && slope(hi) > 0.0) {
        return grid[k];
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if slope(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let s = 0.5 * (lo + hi);
    if h(s) <= values[k] {
        s
    } else {
        grid[k]
    }
}

impl Evaluation<'_> {
    /// The modal fit at `theta` (physical values in prior order): None when
    /// the bundle has no usable `modal.csv`; an error when the model's
    /// modal analysis fails.
    pub fn modal_fit(&self, theta: &[f64]) -> Option<Result<ModalFit, String>> {
        self.modal_fit_on(theta, None)
    }

    /// [`modal_fit`](Self::modal_fit) with the modes found by Rayleigh–Ritz
    /// on `basis` when given (the modes of a nearby point,
    /// [`modal_basis`](Self::modal_basis); Lanczos when it does not fit).
    pub fn modal_fit_on(
        &self,
        theta: &[f64],
        basis: Option<&[Vec<f64>]>,
    ) -> Option<Result<ModalFit, String>> {
        let entries = self.bundle.modal.as_deref()?;
        let highest = usable(entries).iter().map(|e| e.mode).max()? as usize;
        let step_s = crate::specimen::fe_step_s(self.bundle, self.runs);
        Some(self.model_frequencies(theta, highest, basis).and_then(|f| {
            modal_fit(entries, &f, step_s)
                .ok_or_else(|| format!("modal analysis gave {} modes: expected {highest}", f.len()))
        }))
    }

    /// The modes at `theta` a Rayleigh–Ritz reanalysis of the modal fit
    /// near it runs on: `share` times as many as the fit computes (None
    /// without a usable `modal.csv`).
    pub fn modal_basis(&self, theta: &[f64], share: f64) -> Option<Result<Vec<Vec<f64>>, String>> {
        let entries = self.bundle.modal.as_deref()?;
        let highest = usable(entries).iter().map(|e| e.mode).max()? as usize;
        let wanted = (modes_for(highest) as f64 * share).ceil() as usize;
        Some(self.modes(theta, wanted, None).map(|(_, modal)| modal.shapes))
    }

    /// The model's lowest `n` sway frequencies at `theta` (Hz): of the
    /// lowest [`modes_for`]`(n)` modes, those that [`sway_modes`] keeps.
    fn model_frequencies(
        &self,
        theta: &[f64],
        n: usize,
        basis: Option<&[Vec<f64>]>,
    ) -> Result<Vec<f64>, String> {
        let (s, modal) = self.modes(theta, modes_for(n), basis)?;
        let mut f = sway_modes(&modal.freq_hz, &horizontal_share(&s, &modal));
        f.truncate(n);
        Ok(f)
    }

    /// The lowest `wanted` modes at `theta` (as many as carry mass when
    /// fewer), by Rayleigh–Ritz on `basis` when it fits the mesh, else by
    /// Lanczos.
    fn modes(
        &self,
        theta: &[f64],
        wanted: usize,
        basis: Option<&[Vec<f64>]>,
    ) -> Result<(Structure, ModalResult), String> {
        let (spec, params, _) = self.setup(theta)?;
        let model = generate(&spec, &params).map_err(|e| e.to_string())?;
        let wanted = wanted.min(model.mass_dofs()).max(2);
        modal_analysis_on(&model, basis, wanted, &LanczosSettings::default())
            .map_err(|e| format!("modal analysis: {e}"))
    }
}

/// Modes computed to find the lowest `n` sway modes: 2n + 4 (the vertical
/// and rod modes between them), at least n.
fn modes_for(n: usize) -> usize {
    (2 * n + 4).max(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn entry(mode: u32, freq_hz: f64, std_hz: Option<f64>) -> ModalEntry {
        ModalEntry { mode, freq_hz, std_hz }
    }

    #[test]
    fn modes_meet_the_models_by_number() {
        let entries = [entry(3, 9.0, Some(0.1)), entry(1, 7.0, None), entry(40, 30.0, None)];
        let fit = modal_fit(&entries, &[7.2, 8.0, 9.1], 0.0).unwrap();
        assert_eq!(fit.modes, [3, 1]);
        assert_eq!(fit.model_hz, [9.1, 7.2]);
        assert!((fit.residuals_hz()[1] - 0.2).abs() < 1e-12);
        assert!(modal_fit(&entries, &[7.2, 8.0], 0.0).is_none(), "mode 3 missing from the model");
        assert!(modal_fit(&[entry(40, 30.0, None)], &[7.2], 0.0).is_none(), "no usable mode");
    }

    /// The frequency of a unit oscillator of frequency `f_hz` integrated by
    /// Newmark's average acceleration at `step_s`, free from u = 1: its
    /// upward zero crossings over 2000 periods, interpolated.
    fn newmark_frequency_hz(f_hz: f64, step_s: f64) -> f64 {
        let (w2, h) = ((2.0 * std::f64::consts::PI * f_hz).powi(2), step_s);
        let (mut u, mut v, mut a) = (1.0, 0.0, -w2);
        let mut crossings = vec![];
        let mut t = 0.0;
        while crossings.len() < 2001 {
            // (1/β h² + ω²) u' = u/βh² + v/βh + (1/2β − 1) a, β = 1/4.
            let next_u = (4.0 / (h * h) * u + 4.0 / h * v + a) / (4.0 / (h * h) + w2);
            let next_a = -w2 * next_u;
            let next_v = v + 0.5 * h * (a + next_a);
            if u < 0.0 && next_u >= 0.0 {
                crossings.push(t + h * u / (u - next_u));
            }
            (u, v, a, t) = (next_u, next_v, next_a, t + h);
        }
        2000.0 / (crossings[2000] - crossings[0])
    }

    #[test]
    fn the_integrated_frequency_is_newmarks() {
        for (f, h) in [(15.0, 0.005), (20.0, 0.005), (9.0, 0.0025), (40.0, 0.01)] {
            let (formula, newmark) = (as_integrated_hz(f, h), newmark_frequency_hz(f, h));
            assert!(
                (formula / newmark - 1.0).abs() < 1e-5,
                "{f} Hz at {h} s: {formula} vs {newmark}"
            );
            assert!(formula < f);
        }
        assert!((as_integrated_hz(15.0, 0.005) / 15.0 - 0.982).abs() < 1e-3);
        assert_eq!(as_integrated_hz(15.0, 0.0), 15.0);
        let fit = modal_fit(&[entry(1, 14.7, Some(0.05))], &[15.0], 0.005).unwrap();
        assert_eq!(fit.eigen_hz, [15.0]);
        assert_eq!(fit.model_hz, [as_integrated_hz(15.0, 0.005)]);
    }

    #[test]
    fn residuals_within_the_labs_uncertainty_count_in_full() {
        let v = [0.04, 0.04];
        let near = [0.01, 0.02];
        assert_eq!(profiled_discrepancy(&near, &v), 0.0);
        let far = [0.5, 0.7];
        let s = profiled_discrepancy(&far, &v);
        assert!((s - (0.6 - 0.04)).abs() < 1e-9, "equal lab variances: mean r² − v, got {s}");
        let whitened =
            modal_fit(&[entry(1, 10.0, Some(0.2)), entry(2, 12.0, Some(0.2))], &[10.1, 11.8], 0.0)
                .unwrap()
                .whitened();
        assert!((whitened[0] - 0.5).abs() < 1e-12 && (whitened[1] + 1.0).abs() < 1e-12);
    }

    /// On a synthetic bundle whose table holds the model's own frequencies
    /// at one point, that point meets them with no discrepancy and another
    /// perimeter stiffness misses them.
    #[test]
    fn the_models_own_frequencies_fit_at_their_point() {
        let dir = tempfile::tempdir().unwrap();
        let mut b = crate::diagnose::farm_executor_tests::tiny_bundle(dir.path());
        let priors = crate::diagnose::cause::Cause::NONE.priors();
        let runs = [0usize];
        let theta: Vec<f64> = priors.iter().map(|p| p.at(0.5)).collect();
        let own =
            Evaluation::baseline(&b, &priors, &runs).model_frequencies(&theta, 3, None).unwrap();
        // As the runs are integrated (the table a lab would identify from them).
        let step_s = crate::specimen::fe_step_s(&b, &runs);
        assert!(step_s > 0.0);
        let seen = |k: usize| as_integrated_hz(own[k], step_s);
        b.modal = Some((0..3).map(|k| entry(k as u32 + 1, seen(k), Some(0.01))).collect());
        let ev = Evaluation::baseline(&b, &priors, &runs);
        let at = ev.modal_fit(&theta).unwrap().unwrap();
        assert_eq!(at.discrepancy_var_hz2, 0.0);
        assert!((at.neg_log_lik - 1.5 * 1e-4f64.ln()).abs() < 1e-6, "{}", at.neg_log_lik);
        let mut stiffer = theta.clone();
        stiffer[0] = priors[0].at(0.9);
        let off = ev.modal_fit(&stiffer).unwrap().unwrap();
        assert!(off.residuals_hz().iter().all(|r| *r > 0.0), "{:?}", off.residuals_hz());
        assert!(off.neg_log_lik > at.neg_log_lik + 1.0);
        b.modal = None;
        assert!(Evaluation::baseline(&b, &priors, &runs).modal_fit(&theta).is_none());
    }

    proptest! {
        /// The profiled discrepancy is no worse than any other, and its
        /// −log L never rises when a residual shrinks.
        #[test]
        fn the_profiled_discrepancy_minimises(
            r in proptest::collection::vec(-1.0..1.0f64, 1..6),
            sd in proptest::collection::vec(prop_oneof![Just(0.0), 0.001..0.3f64], 6),
            trial in 0.0..2.0f64,
        ) {
            let r2: Vec<f64> = r.iter().map(|x| x * x).collect();
            let v: Vec<f64> = sd[..r.len()].iter().map(|s| s * s).collect();
            let s = profiled_discrepancy(&r2, &v);
            let best = neg_log_lik(&r2, &v, s);
            prop_assert!(s >= 0.0);
            prop_assert!(best <= neg_log_lik(&r2, &v, trial) + 1e-9);
            let mut smaller = r2.clone();
            smaller[0] *= 0.5;
            let s2 = profiled_discrepancy(&smaller, &v);
            prop_assert!(neg_log_lik(&smaller, &v, s2) <= best + 1e-9);
        }
    }
}
