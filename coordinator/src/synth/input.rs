//! Base inputs of a synthetic run (m/s², one sample per 1/`sample_rate_hz`):
//! the seed's sine sweep, band-limited Gaussian white noise (1 s cosine
//! ramps), or a record file; scaled to the run's peak acceleration.

use super::spec::{Excitation, Shaking, SynthRun};
use crate::diagnose::filter::Biquad;
use fe::ceiling::{sine_sweep, SineSweep};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::path::Path;
use worker::ceiling::excitation::{self, Columns, G_M_S2 as G};

/// Why an input could not be built.
#[derive(Debug, thiserror::Error)]
#[error("run {run}: {message}")]
pub struct InputError {
    /// Run id.
    pub run: String,
    /// What is wrong.
    pub message: String,
}

/// The input samples of a run (m/s²) and their step (s).
pub fn build_input(
    run: &SynthRun,
    seed: u64,
    base_dir: &Path,
) -> Result<(Vec<f64>, f64), InputError> {
    let err = |message: String| InputError { run: run.id.clone(), message };
    let dt = 1.0 / run.sample_rate_hz;
    let (mut a, dt) = match run.excitation {
        Excitation::SineSweep => {
            let s = SineSweep {
                f_start_hz: run.f_start_hz,
                f_end_hz: run.f_end_hz,
                duration_s: run.duration_s,
                amplitude_m_s2: 1.0,
                ramp_s: (0.1 * run.duration_s).min(2.0),
            };
            (sine_sweep(&s, dt), dt)
        }
        Excitation::WhiteNoise => (white_noise(run, seed, dt).map_err(err)?, dt),
        Excitation::Record => {
            let path = base_dir.join(run.record.as_deref().unwrap_or(Path::new("")));
            let (a, dt) = read_record(&path).map_err(err)?;
            (a.iter().map(|v| v * run.record_units.to_m_s2()).collect(), dt)
        }
    };
    if let Some(pga) = run.pga_g {
        let peak = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if peak == 0.0 {
            return Err(err("the input is all zeros; it cannot be scaled to pga_g".into()));
        }
        let k = pga * G / peak;
        a.iter_mut().for_each(|v| *v *= k);
    }
    Ok((a, dt))
}

fn white_noise(run: &SynthRun, seed: u64, dt: f64) -> Result<Vec<f64>, String> {
    let n = (run.duration_s / dt).round() as usize + 1;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let x: Vec<f64> = (0..n).map(|_| StandardNormal.sample(&mut rng)).collect();
    let [lo, hi] = run.band_hz;
    let hp = Biquad::high_pass(lo, dt).ok_or(format!("band_hz low {lo} Hz above Nyquist"))?;
    let lp = Biquad::low_pass(hi, dt).ok_or(format!("band_hz high {hi} Hz above Nyquist"))?;
    let y = lp.filtfilt(&hp.filtfilt(&x));
    let ramp = 1.0f64.min(0.1 * run.duration_s);
    Ok(y.iter()
        .enumerate()
        .map(|(k, v)| {
            let t = k as f64 * dt;
            let edge = t.min(run.duration_s - t).max(0.0);
            let w = if edge >= ramp {
                1.0
            } else {
                0.5 * (1.0 - (std::f64::consts::PI * edge / ramp).cos())
            };
            v * w
        })
        .collect())
}

/// A record CSV: a header line, then `t,a` rows on a uniform step (the
/// `ceiling` worker's record reader, acceleration in the second column).
fn read_record(path: &Path) -> Result<(Vec<f64>, f64), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let cols = Columns { direction: Shaking::X, x: &None, y: &None };
    let (dt_s, a, _) = excitation::read_record(&text, &cols)
        .map_err(|e| format!("{}: {}", path.display(), e.message))?;
    Ok((a, dt_s))
}
