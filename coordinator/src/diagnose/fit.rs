//! How well one model variant at one parameter point reproduces measured
//! runs: per channel (run × sensor) the residual sum of squares against the
//! offset-corrected measurement, its lag-one autocorrelation and the
//! effective sample size n(1−ρ)/(1+ρ); the profiled Gaussian log-likelihood
//! −log L = Σ n_eff/2 · log(SSR/n); and the normalised error RMS(res)/RMS(meas).
//! Missing readings (NaN) are skipped, never read as zero.

use super::cause::{model_parameters, Cause, Demand, Prior};
use crate::bundle::{Bundle, RunData};
use crate::specimen::{base_input, fe_spec, run_options, simulate_run};
use fe::ceiling::SimOptions;
use fe::generator::Parameters;

/// The fit of one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelFit {
    /// Run id.
    pub run: String,
    /// Sensor id.
    pub sensor: String,
    /// Σ residual² over the samples present.
    pub ssr: f64,
    /// Samples present.
    pub n: usize,
    /// Lag-one autocorrelation of the residual.
    pub rho: f64,
    /// RMS of the (offset-corrected) measurement.
    pub rms_meas: f64,
    /// Whether the run shook the sensor's direction.
    pub excited: bool,
    /// Nugget estimate of the sensor-noise variance in the residual
    /// ([`super::noise_floor::nugget_variance`]; 0 when too short).
    pub noise_var: f64,
    /// The residual's likelihood over the model's band
    /// ([`super::band_likelihood::model_band_fit`]; None without bins).
    pub band: Option<super::band_likelihood::BandFit>,
}

impl ChannelFit {
    /// RMS(residual) / RMS(measurement).
    pub fn nrmse(&self) -> f64 {
        (self.ssr / self.n.max(1) as f64).sqrt() / self.rms_meas.max(1e-300)
    }

    /// One excited, white-residual sample of a unit measurement whose
    /// −log L under weight 2 is `nll` (SSR = e^nll): tests' points.
    #[cfg(test)]
    pub fn with_neg_log_lik(nll: f64) -> Self {
        ChannelFit {
            run: "r".into(),
            sensor: "s".into(),
            ssr: nll.exp(),
            n: 1,
            rho: 0.0,
            rms_meas: 1.0,
            excited: true,
            noise_var: 0.0,
            band: Some(super::band_likelihood::BandFit {
                neg_log_lik: nll,
                bins: 1,
                mean_square: nll.exp(),
                dof: 2.0,
            }),
        }
    }
}

/// Spring group of the perimeter along-axis springs (friction / elastic).
pub const PERIMETER_GROUP: &str = "perimeter_friction";
/// The across-axis friction springs of free grid ends (damped as the
/// along-axis ones).
pub const PERIMETER_ACROSS_GROUP: &str = "perimeter_friction_across";
/// Spring group of the grid connections' axial springs.
pub const CONNECTION_GROUP: &str = "connection_axial";
/// Spring group of the grid connections' in-plane transverse springs.
pub const CONNECTION_TRANSVERSE_GROUP: &str = "connection_transverse";
/// The spring groups whose peaks make a [`Demand`], in its order.
pub const DEMAND_GROUPS: [&str; 3] =
    [PERIMETER_GROUP, CONNECTION_GROUP, CONNECTION_TRANSVERSE_GROUP];
/// The calibrated parameter that sets the Rayleigh damping ratio.
pub const DAMPING_RATIO: &str = "damping_ratio";
/// The solver parameter that puts the flagged springs' Rayleigh stiffness
/// term on their committed tangent.
pub const DAMPING_COMMITTED_SHARE: &str = worker::ceiling::DAMPING_COMMITTED_SHARE;
/// The calibrated parameter (and solver parameter) that sets the Rayleigh
/// damping's share on the mass term ([`super::damping_share`]).
pub const DAMPING_MASS_SHARE: &str = worker::ceiling::DAMPING_MASS_SHARE;

/// The solver option a calibrated parameter `name` sets (the damping's
/// ratio and share on the mass term), if it sets one.
fn solver_parameter(name: &str) -> Option<&'static str> {
    [DAMPING_RATIO, DAMPING_MASS_SHARE].into_iter().find(|n| *n == name)
}

/// One simulated run at a parameter point: (sensor id, samples) in bundle units.
pub type Simulated = crate::specimen::SensorSeries;

/// Model variant, parameter point and the data it is judged on.
pub struct Evaluation<'a> {
    /// The bundle.
    pub bundle: &'a Bundle,
    /// The variant.
    pub cause: Cause,
    /// Its priors (parameter order).
    pub priors: &'a [Prior],
    /// Indices of the runs used.
    pub runs: &'a [usize],
    /// The baseline's demand that extension parameters are scaled by.
    pub demand: Option<Demand>,
    /// Share of the flagged springs' Rayleigh stiffness term on their
    /// committed tangent (0: the initial stiffness).
    pub committed_share: f64,
}

impl<'a> Evaluation<'a> {
    /// The baseline with `priors` judged on `runs` (no demand, damped on
    /// the initial stiffness).
    pub fn baseline(bundle: &'a Bundle, priors: &'a [Prior], runs: &'a [usize]) -> Self {
        Evaluation { bundle, cause: Cause::NONE, priors, runs, demand: None, committed_share: 0.0 }
    }
}

impl Evaluation<'_> {
    /// The FE specimen of the variant.
    pub fn fe_spec(&self) -> Result<fe::generator::CeilingSpec, String> {
        fe_spec(&self.bundle.manifest.structure, self.cause.model_options())
            .map_err(|e| e.to_string())
    }

    /// The FE parameter values `theta` (prior order) sets, in the order
    /// they are set (`damping_ratio` and `damping_mass_share` included,
    /// under those names), after the bundle's held linear form
    /// ([`Bundle::linear_form`]) for every name `theta` does not set.
    pub fn assignments(&self, theta: &[f64]) -> Vec<(&'static str, f64)> {
        let held = self.held();
        // An effect's mapping reads the whole held linear form: Pinching4
        // joints start at the held K_cc1, which their variant does not
        // take as a parameter.
        let named: Vec<(&str, f64)> = (self.bundle.linear_form.iter().copied())
            .chain(self.priors.iter().map(|p| p.name).zip(theta.iter().copied()))
            .collect();
        let demand = self.demand.unwrap_or(Demand {
            perimeter_mm: 1.0,
            perimeter_n: 1.0,
            connection_n: 1.0,
            connection_transverse_n: 1.0,
            nominal_gap_mm: 1.0,
        });
        let mut own = Vec::new();
        for (p, v) in self.priors.iter().zip(theta) {
            if let Some(name) = solver_parameter(p.name) {
                own.push((name, *v));
            } else {
                own.extend(model_parameters(p, *v, &named, &demand));
            }
        }
        if self.committed_share > 0.0 {
            own.push((DAMPING_COMMITTED_SHARE, self.committed_share));
        }
        let mut out: Vec<(&'static str, f64)> =
            held.into_iter().filter(|(n, _)| !own.iter().any(|(m, _)| m == n)).collect();
        out.extend(own);
        out
    }

    /// The bundle's held linear form ([`Bundle::linear_form`]) as far as
    /// the variant's model uses it (a joint spring of the elastic
    /// connections, say, is not a parameter of Pinching4 connections, which
    /// take their stiffness from it through [`model_parameters`]).
    fn held(&self) -> Vec<(&'static str, f64)> {
        if self.bundle.linear_form.is_empty() {
            return vec![];
        }
        let used = self.fe_spec().map(|s| fe::generator::parameters_for(&s)).unwrap_or_default();
        (self.bundle.linear_form.iter())
            .filter(|(n, _)| {
                solver_parameter(n).is_some()
                    || used.iter().any(|p| p.name == *n)
                    || fe::generator::along::is_along_factor(n)
            })
            .copied()
            .collect()
    }

    /// The FE parameters and simulation options at `theta` (prior order).
    pub fn setup(
        &self,
        theta: &[f64],
    ) -> Result<(fe::generator::CeilingSpec, Parameters, SimOptions), String> {
        let spec = self.fe_spec()?;
        let mut params = Parameters::prior_midpoints_for(&spec);
        let mut opts = run_options(SimOptions::default().damping_ratio);
        for (name, value) in self.assignments(theta) {
            if name == DAMPING_RATIO {
                opts.damping_ratio = value;
            } else if name == DAMPING_COMMITTED_SHARE {
                opts.damping_committed_share = value;
            } else if name == DAMPING_MASS_SHARE {
                opts.damping_mass_share = value;
            } else {
                params.set(name, value).map_err(|e| e.to_string())?;
            }
        }
        Ok((spec, params, opts))
    }

    /// Simulates the runs at `theta` (physical values in prior order).
    pub fn simulate(&self, theta: &[f64]) -> Result<Vec<Simulated>, String> {
        let (spec, params, opts) = self.setup(theta)?;
        self.runs
            .iter()
            .map(|&k| {
                let run = &self.bundle.runs[k];
                let sensors = measured_sensors(self.bundle, run);
                simulate_run(&spec, &params, &sensors, &base_input(run), &opts)
                    .map(|(series, _)| series)
                    .map_err(|e| format!("run {}: {e}", run.id))
            })
            .collect()
    }

    /// Peak perimeter deformation and force and peak connection forces
    /// (axial, transverse) over the runs at `theta` (0 for a group the
    /// variant lacks).
    pub fn demand_at(&self, theta: &[f64]) -> Result<Demand, String> {
        let (spec, params, mut opts) = self.setup(theta)?;
        opts.spring_groups = DEMAND_GROUPS.map(String::from).to_vec();
        let mut d = Demand {
            perimeter_mm: 0.0,
            perimeter_n: 0.0,
            connection_n: 0.0,
            connection_transverse_n: 0.0,
            nominal_gap_mm: spec.structure.nominal_gap_mm,
        };
        for &k in self.runs {
            let run = &self.bundle.runs[k];
            let (_, sim) = simulate_run(&spec, &params, &[], &base_input(run), &opts)
                .map_err(|e| format!("run {}: {e}", run.id))?;
            d.perimeter_mm = d.perimeter_mm.max(sim.spring_peaks[0].deformation_mm);
            d.perimeter_n = d.perimeter_n.max(sim.spring_peaks[0].force_n);
            d.connection_n = d.connection_n.max(sim.spring_peaks[1].force_n);
            d.connection_transverse_n = d.connection_transverse_n.max(sim.spring_peaks[2].force_n);
        }
        Ok(d)
    }

    /// Channel fits of simulated runs against the measured ones.
    pub fn channels(&self, sims: &[Simulated]) -> Vec<ChannelFit> {
        self.fits(sims).0
    }

    /// Channel fits of a model's predictions of runs it was not fitted to:
    /// as [`channels`](Self::channels), but each channel's offset is the
    /// least-squares constant between measurement and prediction
    /// ([`least_squares_offset`]), fitted for each model as its noise is.
    /// A sensor's bias is the sensor's, not the model's: read off a 0.5 s
    /// lead-in of 50 readings with 0.05 mm noise it is 0.01 mm uncertain,
    /// which on a 0.3 mm response is an error of 3 % that no model removes.
    /// The signal stays the measurement about its pre-event offset, the
    /// same for every model.
    pub fn validation_channels(&self, sims: &[Simulated]) -> Vec<ChannelFit> {
        self.fits_by(sims, Offset::Fitted).0
    }

    /// Each channel's windowed RMS misfit (see [`super::envelope`]), in the
    /// order of [`Evaluation::fits`].
    pub fn envelope_misfits(&self, sims: &[Simulated]) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        for (&k, sim) in self.runs.iter().zip(sims) {
            let run = &self.bundle.runs[k];
            for (id, s) in sim {
                if let Some(m) = run.sensor(id) {
                    let off = pre_event_offset(m, run.dt_s);
                    let a: Vec<f64> = m.iter().map(|v| v - off).collect();
                    out.push(super::envelope::window_rms_misfit(&a, s, run.dt_s));
                }
            }
        }
        out
    }

    /// Channel fits and, in the same order, each channel's residuals
    /// (simulated − offset-corrected measured; NaN where a reading is missing).
    pub fn fits(&self, sims: &[Simulated]) -> (Vec<ChannelFit>, Vec<Vec<f64>>) {
        self.fits_by(sims, Offset::PreEvent)
    }

    /// [`fits`](Self::fits) with the residual's offset removed by `rule`.
    fn fits_by(&self, sims: &[Simulated], rule: Offset) -> (Vec<ChannelFit>, Vec<Vec<f64>>) {
        let (mut fits, mut residuals) = (Vec::new(), Vec::new());
        for (&k, sim) in self.runs.iter().zip(sims) {
            let run = &self.bundle.runs[k];
            for (id, s) in sim {
                if let Some(m) = run.sensor(id) {
                    let off = pre_event_offset(m, run.dt_s);
                    let bias = match rule {
                        Offset::PreEvent => off,
                        Offset::Fitted => least_squares_offset(m, s).unwrap_or(off),
                    };
                    let r: Vec<f64> = m.iter().zip(s).map(|(a, b)| b - (a - bias)).collect();
                    let mut c = channel_fit(run, id, m, off, &r);
                    c.excited = excited(self.bundle, run, id);
                    fits.push(c);
                    residuals.push(r);
                }
            }
        }
        (fits, residuals)
    }
}

/// The listed sensors a run measured.
pub fn measured_sensors(b: &Bundle, run: &RunData) -> Vec<crate::bundle::Sensor> {
    b.manifest.sensors.iter().filter(|s| run.sensor(&s.id).is_some()).cloned().collect()
}

/// How the constant offset of a measured channel is removed.
#[derive(Debug, Clone, Copy)]
enum Offset {
    /// [`pre_event_offset`]: read off the record alone.
    PreEvent,
    /// [`least_squares_offset`]: fitted to the simulation.
    Fitted,
}

/// The constant c minimising Σ (m − s − c)² over the samples where both
/// are present: the mean of m − s (None when no sample is).
pub fn least_squares_offset(m: &[f64], s: &[f64]) -> Option<f64> {
    let (sum, n) = m
        .iter()
        .zip(s)
        .map(|(a, b)| a - b)
        .filter(|d| d.is_finite())
        .fold((0.0, 0usize), |(sum, n), d| (sum + d, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// Offset of a measured channel: median of its first 0.5 s (at least 5 samples).
pub fn pre_event_offset(m: &[f64], dt_s: f64) -> f64 {
    let n = ((0.5 / dt_s) as usize).max(5).min(m.len());
    let mut head: Vec<f64> = m[..n].iter().copied().filter(|v| v.is_finite()).collect();
    if head.is_empty() {
        return 0.0;
    }
    head.sort_by(f64::total_cmp);
    head[head.len() / 2]
}

/// The fit of one channel from its measured samples, their offset and the
/// residuals (NaN where either side is missing).
fn channel_fit(run: &RunData, id: &str, m: &[f64], off: f64, r: &[f64]) -> ChannelFit {
    let (mut ssr, mut n, mut mm) = (0.0, 0usize, 0.0);
    let (mut c1, mut prev) = (0.0, None::<f64>);
    for (a, r) in m.iter().zip(r) {
        if !r.is_finite() {
            prev = None;
            continue;
        }
        let a = a - off;
        ssr += r * r;
        mm += a * a;
        n += 1;
        if let Some(p) = prev {
            c1 += r * p;
        }
        prev = Some(*r);
    }
    let rho = if ssr > 0.0 { (c1 / ssr).clamp(0.0, 0.995) } else { 0.0 };
    ChannelFit {
        run: run.id.clone(),
        sensor: id.into(),
        ssr,
        n,
        rho,
        rms_meas: (mm / n.max(1) as f64).sqrt(),
        excited: true,
        noise_var: super::noise_floor::nugget_variance(r).unwrap_or(0.0),
        band: super::band_likelihood::model_band_fit(r, run.dt_s),
    }
}

/// Whether `run` has an input in the direction sensor `id` measures.
fn excited(b: &Bundle, run: &RunData, id: &str) -> bool {
    match b.manifest.sensors.iter().find(|s| s.id == id).map(|s| s.direction) {
        Some(crate::bundle::Direction::X) => run.input_x_m_s2.is_some(),
        Some(crate::bundle::Direction::Y) => run.input_y_m_s2.is_some(),
        None => false,
    }
}

/// Effective sample sizes n(1−ρ)/(1+ρ) of channels.
pub fn effective_sizes(ch: &[ChannelFit]) -> Vec<f64> {
    ch.iter().map(|c| c.n as f64 * (1.0 - c.rho) / (1.0 + c.rho)).collect()
}

/// −log L with the noise variance of each channel profiled out, each
/// channel counting `n_eff` independent samples (constants dropped).
pub fn neg_log_lik(ch: &[ChannelFit], n_eff: &[f64]) -> f64 {
    ch.iter()
        .zip(n_eff)
        .map(|(c, ne)| 0.5 * ne * (c.ssr / c.n.max(1) as f64).max(1e-300).ln())
        .sum()
}

/// Mean normalised error over the channels in the shaken directions (all
/// channels when none is).
pub fn mean_nrmse(ch: &[ChannelFit]) -> f64 {
    let raw: Vec<f64> = ch.iter().map(ChannelFit::nrmse).collect();
    mean_over_shaken(ch, &raw)
}

/// Mean over the shaken channels (all when none is) of the NRMSE in excess
/// of each channel's noise variance `noise_var[c]` (see [`super::noise_floor`]),
/// each channel weighted by the share of its measured power that is signal
/// ([`super::noise_floor::signal_share`]; equal weights if no channel has
/// any): a channel that reads mostly noise adds the error of its noise
/// estimate, not a model's.
pub fn mean_excess_nrmse(ch: &[ChannelFit], noise_var: &[f64]) -> f64 {
    let (excess, share): (Vec<f64>, Vec<f64>) = ch
        .iter()
        .zip(noise_var)
        .map(|(c, v)| {
            let ms = c.rms_meas * c.rms_meas;
            let mse = c.ssr / c.n.max(1) as f64;
            (
                super::noise_floor::excess_nrmse(mse, ms, *v),
                super::noise_floor::signal_share(ms, *v),
            )
        })
        .unzip();
    let weighted = weighted_mean_over_shaken(ch, &excess, &share);
    if weighted.is_nan() {
        mean_over_shaken(ch, &excess)
    } else {
        weighted
    }
}

/// Mean of per-channel `values` over the shaken channels, or over all
/// when no channel is shaken (NaN when there are none).
fn mean_over_shaken(ch: &[ChannelFit], values: &[f64]) -> f64 {
    weighted_mean_over_shaken(ch, values, &vec![1.0; values.len()])
}

/// [`mean_over_shaken`] with per-channel `weights` (NaN when the picked
/// channels' weights sum to 0).
fn weighted_mean_over_shaken(ch: &[ChannelFit], values: &[f64], weights: &[f64]) -> f64 {
    let shaken = ch.iter().any(|c| c.excited);
    let (sum, total) = ch
        .iter()
        .zip(values.iter().zip(weights))
        .filter(|(c, _)| c.excited || !shaken)
        .fold((0.0, 0.0), |(s, t), (_, (v, w))| (s + w * v, t + w));
    if total > 0.0 {
        sum / total
    } else {
        f64::NAN
    }
}
