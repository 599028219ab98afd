//! The symptoms of a diagnosis: every symptom kernel applied in the same
//! way to the measured runs, to the calibrated baseline's simulations of
//! them and to the chosen extension's, at one acceleration and one
//! displacement sensor in the shaken direction.
//!
//! Sensors: the direction is the one the strongest simulated run shakes
//! (x on a tie); the accelerometer is, in that direction, one beside a
//! displacement sensor if any, else the one nearest the plan centre; the
//! displacement sensor likewise. Numbers in the table are those of the
//! focus run, the simulated run with the largest peak input; per-run values
//! go to the plots. Accelerations in m/s², displacements in mm, amplitudes
//! in g. Missing readings (NaN) are skipped; gaps of up to
//! [`BRIDGE_SAMPLES`] samples are bridged linearly for the spectral
//! estimates, longer ones leave their segments out. A symptom that cannot
//! be computed carries the reason.

use super::fit::{pre_event_offset, Simulated};
use super::loop_damping::loop_damping;
use super::pipeline::{CandidateResult, Diagnosis};
use super::spectrogram::{segment_for, spectrogram};
use super::spectrum::{resonance, transfer_h1};
use super::symptoms::{amplitude_trend, plateau, residual_drift, spike_share};
use crate::bundle::{Bundle, Direction, RunData, SensorKind};

/// Longest run of missing readings bridged for spectral estimates (samples).
pub const BRIDGE_SAMPLES: usize = 3;
/// Standard gravity (m/s²).
const G: f64 = 9.80665;
/// Sensors closer than this are "beside" each other (m).
const BESIDE_M: f64 = 0.3;

/// One number of a symptom, or why there is none.
#[derive(Debug, Clone, PartialEq)]
pub enum Reading {
    /// The value, in the symptom's unit.
    Value(f64),
    /// Not computable, with the reason.
    NotComputable(String),
    /// The column is the reference the others are measured against.
    Reference,
}

impl Reading {
    /// The value, if any.
    pub fn value(&self) -> Option<f64> {
        match self {
            Reading::Value(v) => Some(*v),
            _ => None,
        }
    }
    /// The value or NaN (for plots).
    pub fn or_nan(&self) -> f64 {
        self.value().unwrap_or(f64::NAN)
    }
}

/// Which record a reading comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The measurement.
    Measured,
    /// The calibrated baseline's simulation.
    Baseline,
    /// The chosen extension's simulation.
    Extended,
}

/// The three sources in table order.
pub const SOURCES: [Source; 3] = [Source::Measured, Source::Baseline, Source::Extended];

/// One symptom: its numbers on the focus run and per simulated run.
#[derive(Debug, Clone, PartialEq)]
pub struct Symptom {
    /// Machine name (`diagnosis.json`).
    pub key: &'static str,
    /// What is measured, for the table.
    pub name: &'static str,
    /// A short name for plot titles and axes.
    pub short: &'static str,
    /// Unit of the numbers ("-" for ratios).
    pub unit: &'static str,
    /// What a departure of the measurement from the baseline points to.
    pub points_to: &'static str,
    /// Measured, baseline, extended.
    pub readings: [Reading; 3],
    /// Per run: (run id, [measured, baseline, extended]), NaN when not computable.
    pub per_run: Vec<(String, [f64; 3])>,
}

/// Apparent frequency of one run against its amplitude.
#[derive(Debug, Clone, PartialEq)]
pub struct FrequencyPoint {
    /// Run id.
    pub run: String,
    /// Peak input in the shaken direction (g).
    pub amplitude_g: f64,
    /// Measured, baseline, extended resonance frequency (Hz); NaN when not computable.
    pub freq_hz: [f64; 3],
    /// Whether the models simulated the run.
    pub simulated: bool,
}

impl FrequencyPoint {
    /// Whether the run counts in the trend: the measured frequency and, if
    /// the run was simulated, both models' are there (so that every source
    /// is judged on the same runs).
    pub fn complete(&self) -> bool {
        self.freq_hz[0].is_finite()
            && (!self.simulated || self.freq_hz[1..].iter().all(|f| f.is_finite()))
    }
}

/// Short-time spectrum of a model's residual at the accelerometer.
#[derive(Debug, Clone, PartialEq)]
pub struct ResidualMap {
    /// Model whose residual it is.
    pub model: String,
    /// Run id.
    pub run: String,
    /// Sensor id.
    pub sensor: String,
    /// Segment centres (s from the run's first sample).
    pub t_s: Vec<f64>,
    /// Frequencies (Hz).
    pub freq_hz: Vec<f64>,
    /// `level_db[it][ik]`: residual power over the median measured cell power (dB).
    pub level_db: Vec<Vec<f64>>,
}

/// All the evidence of a diagnosis.
#[derive(Debug, Clone, PartialEq)]
pub struct Evidence {
    /// Shaken direction the symptoms are read in.
    pub direction: Direction,
    /// Accelerometer used.
    pub accel: Option<String>,
    /// Displacement sensor used.
    pub disp: Option<String>,
    /// Name of the extended column's model.
    pub extended_model: String,
    /// Run the table's numbers come from.
    pub focus_run: Option<String>,
    /// The symptoms in table order.
    pub symptoms: Vec<Symptom>,
    /// Apparent frequency per run.
    pub frequency: Vec<FrequencyPoint>,
    /// Residual maps: baseline, then the extension if one was chosen.
    pub maps: Vec<ResidualMap>,
}

/// A run with whatever simulations the diagnosis kept of it.
struct RunView<'a> {
    data: &'a RunData,
    base: Option<&'a Simulated>,
    ext: Option<&'a Simulated>,
    pga_g: f64,
}

impl RunView<'_> {
    /// A channel of one source: offset-corrected if measured.
    fn channel(&self, src: Source, id: &str) -> Result<Vec<f64>, String> {
        let sims = match src {
            Source::Measured => {
                let m = self
                    .data
                    .sensor(id)
                    .ok_or_else(|| format!("run {} did not record sensor {id}", self.data.id))?;
                let off = pre_event_offset(m, self.data.dt_s);
                return Ok(m.iter().map(|v| v - off).collect());
            }
            Source::Baseline => self.base,
            Source::Extended => self.ext,
        };
        let sims = sims.ok_or_else(|| format!("run {} was not simulated", self.data.id))?;
        sims.iter()
            .find(|(s, _)| s == id)
            .map(|(_, v)| v.clone())
            .ok_or_else(|| format!("run {} has no simulated {id}", self.data.id))
    }
}

/// The evidence of diagnosis `d` of bundle `b`.
pub fn evidence<'a>(b: &'a Bundle, d: &'a Diagnosis) -> Evidence {
    let base = d.candidates.first();
    let chosen = d.candidates.iter().find(|c| c.selected).or(base);
    let pick = |k: usize, validation: bool| {
        let get = |c: Option<&'a CandidateResult>| c.and_then(|c| sims_of(c, validation).get(k));
        (get(base), get(chosen))
    };
    let mut sims: Vec<(Option<&Simulated>, Option<&Simulated>)> = vec![(None, None); b.runs.len()];
    for (k, &run) in d.calibration_runs.iter().enumerate() {
        if let Some(s) = sims.get_mut(run) {
            *s = pick(k, false);
        }
    }
    for (k, &run) in d.validation_runs.iter().enumerate() {
        if let Some(s) = sims.get_mut(run) {
            *s = pick(k, true);
        }
    }
    let direction = shaken_direction(b, &sims);
    let all: Vec<RunView> = b
        .runs
        .iter()
        .zip(&sims)
        .map(|(data, &(base, ext))| RunView { data, base, ext, pga_g: pga_g(data, direction) })
        .collect();
    let simulated: Vec<&RunView> =
        all.iter().filter(|v| v.base.is_some() && v.pga_g > 0.0).collect();
    let focus = simulated.iter().copied().max_by(|a, b| a.pga_g.total_cmp(&b.pga_g));
    let accel = pick_sensor(b, direction, SensorKind::Acceleration);
    let disp = pick_sensor(b, direction, SensorKind::Displacement);
    let ctx = Context { b, direction, accel: accel.clone(), disp: disp.clone() };
    let frequency = frequency_points(&ctx, &all);
    let fc_hz = spike_corner_hz(&frequency, focus);
    let mut symptoms = vec![frequency_trend(&frequency, &all)];
    symptoms.extend(per_run_symptoms(&ctx, &simulated, focus, fc_hz));
    if let Some(loops) = symptoms.iter().find(|s| s.key == "loop_damping_ratio") {
        symptoms.push(damping_growth(loops, &simulated));
    }
    let extended = match (base, chosen) {
        (Some(b), Some(c)) if b.cause != c.cause => Some(c.cause.as_str()),
        _ => None,
    };
    let maps = focus.map(|f| residual_maps(&ctx, f, extended.is_some())).unwrap_or_default();
    symptoms.push(residual_energy(&ctx, focus));
    Evidence {
        direction,
        accel,
        disp,
        extended_model: extended.unwrap_or("none chosen: the baseline").into(),
        focus_run: focus.map(|f| f.data.id.clone()),
        symptoms,
        frequency,
        maps,
    }
}

/// A candidate's simulations of the validation or the calibration runs.
fn sims_of(c: &CandidateResult, validation: bool) -> &[Simulated] {
    if validation {
        &c.validation_sims
    } else {
        &c.calibration_sims
    }
}

/// The sensors and direction every symptom is read at.
struct Context<'a> {
    b: &'a Bundle,
    direction: Direction,
    accel: Option<String>,
    disp: Option<String>,
}

impl Context<'_> {
    fn accel(&self) -> Result<&str, String> {
        self.accel.as_deref().ok_or_else(|| {
            format!("no acceleration sensor in the shaken direction {}", self.direction.as_str())
        })
    }
    fn disp(&self) -> Result<&str, String> {
        self.disp.as_deref().ok_or_else(|| {
            format!("no displacement sensor in the shaken direction {}", self.direction.as_str())
        })
    }
}

/// Input record of a run in a direction, m/s².
fn input(run: &RunData, dir: Direction) -> Option<&[f64]> {
    match dir {
        Direction::X => run.input_x_m_s2.as_deref(),
        Direction::Y => run.input_y_m_s2.as_deref(),
    }
}

/// Peak |input| of a run in a direction (g); 0 without that input.
pub(super) fn pga_g(run: &RunData, dir: Direction) -> f64 {
    input(run, dir)
        .map_or(0.0, |x| x.iter().filter(|v| v.is_finite()).fold(0.0f64, |m, v| m.max(v.abs())) / G)
}

/// The direction the strongest simulated run shakes (x on a tie).
fn shaken_direction(b: &Bundle, sims: &[(Option<&Simulated>, Option<&Simulated>)]) -> Direction {
    let best = |dir| {
        b.runs
            .iter()
            .zip(sims)
            .filter(|(_, s)| s.0.is_some())
            .map(|(r, _)| pga_g(r, dir))
            .fold(0.0f64, f64::max)
    };
    if best(Direction::Y) > best(Direction::X) {
        Direction::Y
    } else {
        Direction::X
    }
}

/// A sensor of `kind` in `dir`: beside a sensor of the other kind if any,
/// else nearest the plan centre.
fn pick_sensor(b: &Bundle, dir: Direction, kind: SensorKind) -> Option<String> {
    let s = &b.manifest.structure;
    let (cx, cy) = (0.5 * s.length_x_m, 0.5 * s.length_y_m);
    let in_dir = |k: SensorKind| {
        b.manifest.sensors.iter().filter(move |x| x.direction == dir && x.kind == k)
    };
    let other = if kind == SensorKind::Acceleration {
        SensorKind::Displacement
    } else {
        SensorKind::Acceleration
    };
    let beside = |x: &crate::bundle::Sensor| {
        in_dir(other).any(|o| (o.x_m - x.x_m).hypot(o.y_m - x.y_m) <= BESIDE_M)
    };
    let centre = |x: &crate::bundle::Sensor| (x.x_m - cx).hypot(x.y_m - cy);
    in_dir(kind)
        .min_by(|a, b| {
            (!beside(a), centre(a))
                .partial_cmp(&(!beside(b), centre(b)))
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .map(|x| x.id.clone())
}

/// A copy with runs of at most [`BRIDGE_SAMPLES`] missing readings bridged
/// linearly between finite neighbours; longer runs and the ends stay NaN.
pub fn bridge_short_gaps(x: &[f64]) -> Vec<f64> {
    let mut out = x.to_vec();
    let mut i = 0;
    while i < x.len() {
        if x[i].is_finite() {
            i += 1;
            continue;
        }
        let start = i;
        while i < x.len() && !x[i].is_finite() {
            i += 1;
        }
        if start > 0 && i < x.len() && i - start <= BRIDGE_SAMPLES {
            let (a, b) = (x[start - 1], x[i]);
            let span = (i - start + 1) as f64;
            for (j, v) in out[start..i].iter_mut().enumerate() {
                *v = a + (b - a) * (j + 1) as f64 / span;
            }
        }
    }
    out
}

/// Apparent (resonance) frequency of one source of one run (Hz) and its
/// half-power damping ratio when the bandwidth spans at least three bins;
/// a peak at the edge of the band is no resonance and is refused.
/// The peak is sought where the input carries power (mean short-time power
/// within 20 dB of its largest), between 0.5 Hz and min(25 Hz, 0.4 × the
/// sampling rate): elsewhere H1 divides noise by nothing.
fn apparent_freq(ctx: &Context, v: &RunView, src: Source) -> Result<(f64, Option<f64>), String> {
    let id = ctx.accel()?;
    let dt = v.data.dt_s;
    let inp = input(v.data, ctx.direction)
        .ok_or_else(|| format!("run {} has no input in {}", v.data.id, ctx.direction.as_str()))?;
    let out = v.channel(src, id)?;
    let n = inp.len().min(out.len());
    let inp = bridge_short_gaps(&inp[..n]);
    let t = transfer_h1(&inp, &bridge_short_gaps(&out[..n]), dt, (n / 2).max(64))
        .map_err(|e| format!("run {}: {e}", v.data.id))?;
    let df = t.freq_hz[1] - t.freq_hz[0];
    let (lo, hi) = input_band(&inp, dt, t.freq_hz.len())
        .map(|(a, b)| (a.max(0.5), b.min(25.0).min(0.4 / dt)))
        .ok_or_else(|| format!("run {}: the input carries no power", v.data.id))?;
    let r = resonance(&t, lo, hi)
        .ok_or_else(|| format!("run {}: no resonance between {lo:.2} and {hi:.2} Hz", v.data.id))?;
    if r.freq_hz < lo + 1.5 * df || r.freq_hz > hi - 1.5 * df {
        return Err(format!(
            "run {}: the transfer peaks at the edge of the input's band {lo:.2}–{hi:.2} Hz \
             (no resonance inside it)",
            v.data.id
        ));
    }
    let zeta = r.damping_ratio.filter(|z| 2.0 * z * r.freq_hz >= 3.0 * df);
    Ok((r.freq_hz, zeta))
}

/// Lowest and highest frequency (Hz) where the mean short-time power of
/// `x` (segments giving `bins` bins) is within 20 dB of its largest.
fn input_band(x: &[f64], dt_s: f64, bins: usize) -> Option<(f64, f64)> {
    let seg = 2 * (bins - 1);
    let s = spectrogram(x, dt_s, seg, seg / 2).ok()?;
    let cols: Vec<&Vec<f64>> = s.power.iter().filter(|c| c[0].is_finite()).collect();
    let mean: Vec<f64> = (0..bins).map(|k| cols.iter().map(|c| c[k]).sum::<f64>()).collect();
    let top = mean.iter().copied().fold(0.0f64, f64::max);
    let strong: Vec<usize> = (1..bins).filter(|k| mean[*k] >= 0.01 * top).collect();
    let (a, b) = (*strong.first()?, *strong.last()?);
    (top > 0.0).then(|| (s.freq_hz[a], s.freq_hz[b]))
}

fn frequency_points(ctx: &Context, runs: &[RunView]) -> Vec<FrequencyPoint> {
    runs.iter()
        .filter(|v| v.pga_g > 0.0)
        .map(|v| FrequencyPoint {
            run: v.data.id.clone(),
            amplitude_g: v.pga_g,
            freq_hz: SOURCES.map(|s| apparent_freq(ctx, v, s).map_or(f64::NAN, |r| r.0)),
            simulated: v.base.is_some(),
        })
        .collect()
}

/// Frequency at the strongest over the weakest run, per source, over the
/// runs where every source has one ([`FrequencyPoint::complete`]).
fn frequency_trend(points: &[FrequencyPoint], runs: &[RunView]) -> Symptom {
    let readings = [0, 1, 2].map(|k| {
        let pairs: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.complete() && p.freq_hz[k].is_finite())
            .map(|p| (p.amplitude_g, p.freq_hz[k]))
            .collect();
        match amplitude_trend(&pairs) {
            Some(t) => Reading::Value(t.strong_over_weak),
            None => Reading::NotComputable(format!(
                "{} of {} shaken runs show a resonance inside their input band in the \
                 measurement and both models; need two of distinct amplitude",
                pairs.len(),
                runs.iter().filter(|v| v.pga_g > 0.0).count()
            )),
        }
    });
    Symptom {
        key: "apparent_frequency_strong_over_weak",
        name: "apparent frequency, strongest run / weakest run",
        short: "apparent frequency strong / weak",
        unit: "-",
        points_to: "below 1 while the model stays at 1: softening with amplitude (friction slip, \
                    yielding connections); above 1: stiffening by contact (pounding)",
        readings,
        per_run: points.iter().map(|p| (p.run.clone(), p.freq_hz)).collect(),
    }
}

/// High-pass corner for the spike share: 5 × the measured apparent
/// frequency of the focus run (else the highest of any run, else 4 Hz), at
/// least 10 Hz, at most 0.4 × the focus run's sampling rate.
fn spike_corner_hz(points: &[FrequencyPoint], focus: Option<&RunView>) -> f64 {
    let at_focus = focus
        .and_then(|v| points.iter().find(|p| p.run == v.data.id))
        .map(|p| p.freq_hz[0])
        .filter(|f| f.is_finite());
    let highest = points.iter().map(|p| p.freq_hz[0]).filter(|f| f.is_finite()).reduce(f64::max);
    let fc = (5.0 * at_focus.or(highest).unwrap_or(4.0)).max(10.0);
    focus.map_or(fc, |v| fc.min(0.4 / v.data.dt_s))
}

type Kernel<'a> = Box<dyn Fn(&RunView, Source) -> Result<f64, String> + 'a>;

/// A symptom computed run by run: its names and the kernel giving its number.
struct RunKernel<'a> {
    key: &'static str,
    short: &'static str,
    name: &'static str,
    unit: &'static str,
    points_to: &'static str,
    f: Kernel<'a>,
}

/// The symptoms computed run by run.
fn per_run_symptoms(
    ctx: &Context,
    runs: &[&RunView],
    focus: Option<&RunView>,
    fc_hz: f64,
) -> Vec<Symptom> {
    per_run_kernels(ctx, fc_hz).into_iter().map(|k| run_symptom(k, runs, focus)).collect()
}

/// The run-by-run kernels in table order; the spike share high-passes at `fc_hz`.
fn per_run_kernels<'a>(ctx: &'a Context, fc_hz: f64) -> Vec<RunKernel<'a>> {
    vec![
        RunKernel {
            key: "spike_share",
            short: "spike share",
            name: "high-frequency share of acceleration at displacement peaks",
            unit: "-",
            points_to: "measured far above the model: impacts at the displacement peaks (pounding)",
            f: Box::new(move |v, s| spike_share_of(ctx, v, s, fc_hz)),
        },
        RunKernel {
            key: "peak_over_gap",
            short: "peak displacement / gap",
            name: "largest displacement / nominal gap",
            unit: "-",
            points_to: "near 1 in the measurement while the model goes beyond: the gap closes \
                        and stops the grid",
            f: Box::new(move |v, s| peak_over_gap_of(ctx, v, s)),
        },
        RunKernel {
            key: "plateau_saturation",
            short: "plateau saturation",
            name: "share of large half-cycles peaking within 10 % of the largest",
            unit: "-",
            points_to: "higher than the model: cycle peaks pile up at a stop (contact at the gap)",
            f: Box::new(move |v, s| plateau_saturation_of(ctx, v, s)),
        },
        RunKernel {
            key: "residual_drift_mm",
            short: "residual drift",
            name: "residual drift: mean of the last 10 % − mean of the first 10 %",
            unit: "mm",
            points_to: "a permanent offset the model lacks: slip at the perimeter (friction)",
            f: Box::new(move |v, s| residual_drift_of(ctx, v, s)),
        },
        RunKernel {
            key: "loop_damping_ratio",
            short: "loop damping ratio ζ_eq",
            name: "equivalent damping ratio of the hysteresis loops (cycles ≥ 50 % of the largest)",
            unit: "-",
            points_to: "above the model, growing with amplitude: energy lost to friction or \
                        hysteretic connections",
            f: Box::new(move |v, s| loop_damping_of(ctx, v, s)),
        },
        RunKernel {
            key: "half_power_damping_ratio",
            short: "half-power damping ratio",
            name: "damping ratio from the half-power bandwidth of the input→accelerometer transfer",
            unit: "-",
            points_to: "wider than the model: amplitude-dependent damping or a smeared resonance \
                        (nonlinearity)",
            f: Box::new(move |v, s| half_power_damping_of(ctx, v, s)),
        },
    ]
}

/// A run-by-run symptom: its kernel on every run and, for the table, on the focus run.
fn run_symptom(k: RunKernel, runs: &[&RunView], focus: Option<&RunView>) -> Symptom {
    let RunKernel { key, short, name, unit, points_to, f } = k;
    let per_run: Vec<(String, [f64; 3])> = runs
        .iter()
        .map(|v| (v.data.id.clone(), SOURCES.map(|s| f(v, s).unwrap_or(f64::NAN))))
        .collect();
    let readings = match focus {
        Some(v) => SOURCES.map(|s| match f(v, s) {
            Ok(x) if x.is_finite() => Reading::Value(x),
            Ok(x) => Reading::NotComputable(format!("not finite ({x})")),
            Err(e) => Reading::NotComputable(e),
        }),
        None => no_focus(),
    };
    Symptom { key, name, short, unit, points_to, readings, per_run }
}

/// Acceleration (m/s²) and displacement (mm) of one source of a run at the sensors used.
fn accel_and_disp(ctx: &Context, v: &RunView, s: Source) -> Result<(Vec<f64>, Vec<f64>), String> {
    let a = v.channel(s, ctx.accel()?)?;
    let d = v.channel(s, ctx.disp()?)?;
    Ok((a, d))
}

/// Displacement (mm) of one source of a run at the displacement sensor used.
fn disp_of(ctx: &Context, v: &RunView, s: Source) -> Result<Vec<f64>, String> {
    v.channel(s, ctx.disp()?)
}

/// The bundle's nominal gap (mm), or why there is none.
fn nominal_gap(ctx: &Context) -> Result<f64, String> {
    let gap = ctx.b.manifest.structure.nominal_gap_mm;
    gap.ok_or_else(|| "the bundle gives no nominal gap".to_string())
}

/// Spike share of a run, high-passed at `fc_hz` (at most 0.4 × its sampling rate).
fn spike_share_of(ctx: &Context, v: &RunView, s: Source, fc_hz: f64) -> Result<f64, String> {
    let (a, d) = accel_and_disp(ctx, v, s)?;
    spike_share(&a, &d, v.data.dt_s, fc_hz.min(0.4 / v.data.dt_s))
        .ok_or_else(|| format!("run {}: no displacement peaks", v.data.id))
}

/// Largest displacement of a run over the nominal gap.
fn peak_over_gap_of(ctx: &Context, v: &RunView, s: Source) -> Result<f64, String> {
    let g = nominal_gap(ctx)?;
    plateau(&disp_of(ctx, v, s)?, g)
        .map(|p| p.peak_over_gap)
        .ok_or_else(|| format!("run {}: no displacement", v.data.id))
}

/// Share of a run's large half-cycles peaking near the largest.
fn plateau_saturation_of(ctx: &Context, v: &RunView, s: Source) -> Result<f64, String> {
    let g = nominal_gap(ctx)?;
    plateau(&disp_of(ctx, v, s)?, g)
        .map(|p| p.saturation)
        .ok_or_else(|| format!("run {}: no displacement", v.data.id))
}

/// Residual drift of a run's displacement (mm), over its first and last 10 %.
fn residual_drift_of(ctx: &Context, v: &RunView, s: Source) -> Result<f64, String> {
    residual_drift(&disp_of(ctx, v, s)?, 0.1).ok_or_else(|| format!("run {}: too short", v.data.id))
}

/// Equivalent damping ratio of a run's loops of −acceleration against displacement (m).
fn loop_damping_of(ctx: &Context, v: &RunView, s: Source) -> Result<f64, String> {
    let (a, d) = accel_and_disp(ctx, v, s)?;
    let f: Vec<f64> = a.iter().map(|x| -x).collect();
    let u: Vec<f64> = d.iter().map(|x| x / 1000.0).collect();
    loop_damping(&f, &u, 0.5)
        .map(|l| l.zeta_eq)
        .ok_or_else(|| format!("run {}: no complete displacement cycle", v.data.id))
}

/// Half-power damping ratio of a run's input→accelerometer transfer.
fn half_power_damping_of(ctx: &Context, v: &RunView, s: Source) -> Result<f64, String> {
    apparent_freq(ctx, v, s)?.1.ok_or_else(|| {
        format!("run {}: half-power points out of band or under 3 bins apart", v.data.id)
    })
}

/// Loop damping of the strongest simulated run over that of the weakest.
fn damping_growth(loops: &Symptom, runs: &[&RunView]) -> Symptom {
    let readings = [0, 1, 2].map(|k| {
        let pts: Vec<(f64, f64)> = runs
            .iter()
            .zip(&loops.per_run)
            .filter(|(_, (_, v))| v[k].is_finite() && v[k] > 0.0)
            .map(|(r, (_, v))| (r.pga_g, v[k]))
            .collect();
        let weak = pts.iter().min_by(|a, b| a.0.total_cmp(&b.0));
        let strong = pts.iter().max_by(|a, b| a.0.total_cmp(&b.0));
        match (weak, strong) {
            (Some(w), Some(s)) if s.0 > w.0 => Reading::Value(s.1 / w.1),
            _ => Reading::NotComputable(format!(
                "loop damping on {} simulated run(s) of distinct amplitude; need two",
                pts.len()
            )),
        }
    });
    Symptom {
        key: "loop_damping_strong_over_weak",
        name: "loop damping ratio, strongest simulated run / weakest",
        short: "loop damping growth",
        unit: "-",
        points_to: "above 1 while the model stays at 1: damping grows with amplitude (friction, \
                    hysteretic connections); below 1: an elastic stop stores energy (pounding)",
        readings,
        per_run: vec![],
    }
}

fn no_focus() -> [Reading; 3] {
    [0, 1, 2].map(|_| Reading::NotComputable("no simulated run shakes the ceiling".into()))
}

/// Residual maps of the baseline (and the extension) at the focus run.
fn residual_maps(ctx: &Context, v: &RunView, extended: bool) -> Vec<ResidualMap> {
    let Ok(id) = ctx.accel() else { return vec![] };
    let Ok(meas) = v.channel(Source::Measured, id) else { return vec![] };
    let seg = segment_for(0.64, v.data.dt_s);
    let Ok(pm) = spectrogram(&bridge_short_gaps(&meas), v.data.dt_s, seg, seg / 4) else {
        return vec![];
    };
    let mut cells: Vec<f64> =
        pm.power.iter().flatten().copied().filter(|p| p.is_finite()).collect();
    cells.sort_by(f64::total_cmp);
    let Some(&median) = cells.get(cells.len() / 2) else { return vec![] };
    let median = median.max(1e-30);
    let mut srcs = vec![(Source::Baseline, "baseline".to_string())];
    if extended {
        srcs.push((Source::Extended, "extended".to_string()));
    }
    srcs.into_iter()
        .filter_map(|(s, model)| {
            let sim = v.channel(s, id).ok()?;
            let res: Vec<f64> = meas.iter().zip(&sim).map(|(m, x)| m - x).collect();
            let p = spectrogram(&bridge_short_gaps(&res), v.data.dt_s, seg, seg / 4).ok()?;
            let level_db = p
                .power
                .iter()
                .map(|col| {
                    col.iter().map(|x| 10.0 * (x.max(median * 1e-6) / median).log10()).collect()
                })
                .collect();
            Some(ResidualMap {
                model,
                run: v.data.id.clone(),
                sensor: id.to_string(),
                t_s: p.t_s,
                freq_hz: p.freq_hz,
                level_db,
            })
        })
        .collect()
}

/// Energy of the residual over that of the measurement at the accelerometer (dB).
fn residual_energy(ctx: &Context, focus: Option<&RunView>) -> Symptom {
    let energy = |v: &RunView, s: Source| -> Result<f64, String> {
        let id = ctx.accel()?;
        let m = v.channel(Source::Measured, id)?;
        let x = v.channel(s, id)?;
        let (mut er, mut em) = (0.0, 0.0);
        for (a, b) in m.iter().zip(&x) {
            if a.is_finite() && b.is_finite() {
                er += (a - b) * (a - b);
                em += a * a;
            }
        }
        if em > 0.0 && er > 0.0 {
            Ok(10.0 * (er / em).log10())
        } else {
            Err(format!("run {}: no finite samples", v.data.id))
        }
    };
    let readings = match focus {
        Some(v) => [
            Reading::Reference,
            energy(v, Source::Baseline).map_or_else(Reading::NotComputable, Reading::Value),
            energy(v, Source::Extended).map_or_else(Reading::NotComputable, Reading::Value),
        ],
        None => no_focus(),
    };
    Symptom {
        key: "residual_energy_db",
        name: "residual energy / measured energy at the accelerometer",
        short: "residual energy",
        unit: "dB",
        points_to: "what the model leaves unexplained; the maps show when and at which frequencies",
        readings,
        per_run: vec![],
    }
}

#[cfg(test)]
#[path = "evidence_tests.rs"]
mod tests;
