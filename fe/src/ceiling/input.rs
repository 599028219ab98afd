//! Base inputs of a run: the seed's sine sweep (frequency falling
//! exponentially from 6.0 to 0.8 Hz over 100 s, cosine ramps at both ends;
//! seed 4.2.3) or any sampled record, in x and/or y, in m/s².

/// Base acceleration samples (m/s²) at a fixed interval, in x and/or y.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseInput {
    /// Sample interval (s).
    pub dt_s: f64,
    /// Acceleration in x (m/s²), sample k at t = k·dt.
    pub x_m_s2: Option<Vec<f64>>,
    /// Acceleration in y (m/s²).
    pub y_m_s2: Option<Vec<f64>>,
}

impl BaseInput {
    /// Number of samples (the longer component).
    pub fn len(&self) -> usize {
        let n = |c: &Option<Vec<f64>>| c.as_ref().map_or(0, Vec::len);
        n(&self.x_m_s2).max(n(&self.y_m_s2))
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// An exponential sine sweep with cosine ramps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SineSweep {
    /// Frequency at t = 0 (Hz).
    pub f_start_hz: f64,
    /// Frequency at the end (Hz).
    pub f_end_hz: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Peak acceleration (m/s²).
    pub amplitude_m_s2: f64,
    /// Length of the cosine ramp at each end (s).
    pub ramp_s: f64,
}

impl SineSweep {
    /// The seed's sweep: 6.0 → 0.8 Hz over `duration_s`, 2 s ramps.
    pub fn seed(duration_s: f64, amplitude_m_s2: f64) -> Self {
        SineSweep { f_start_hz: 6.0, f_end_hz: 0.8, duration_s, amplitude_m_s2, ramp_s: 2.0 }
    }

    /// Instantaneous frequency at `t_s` (Hz).
    pub fn freq_at(&self, t_s: f64) -> f64 {
        self.f_start_hz * (self.f_end_hz / self.f_start_hz).powf(t_s / self.duration_s)
    }
}

/// Samples of a sweep at interval `dt_s` from t = 0 to its duration.
pub fn sine_sweep(s: &SineSweep, dt_s: f64) -> Vec<f64> {
    let n = (s.duration_s / dt_s).round() as usize + 1;
    let ratio = s.f_end_hz / s.f_start_hz;
    let rate = ratio.ln() / s.duration_s;
    let two_pi = 2.0 * std::f64::consts::PI;
    (0..n)
        .map(|k| {
            let t = k as f64 * dt_s;
            let phase = if rate.abs() < 1e-12 {
                two_pi * s.f_start_hz * t
            } else {
                two_pi * s.f_start_hz * ((rate * t).exp() - 1.0) / rate
            };
            s.amplitude_m_s2 * ramp(t, s.duration_s, s.ramp_s) * phase.sin()
        })
        .collect()
}

/// Cosine taper: 0 at both ends, 1 after `ramp_s` and before the last `ramp_s`.
fn ramp(t: f64, duration: f64, ramp_s: f64) -> f64 {
    if ramp_s <= 0.0 {
        return 1.0;
    }
    let edge = t.min(duration - t).max(0.0);
    if edge >= ramp_s {
        1.0
    } else {
        0.5 * (1.0 - (std::f64::consts::PI * edge / ramp_s).cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweep_has_its_amplitude_ramps_and_falling_frequency() {
        let s = SineSweep::seed(100.0, 1.5);
        let a = sine_sweep(&s, 0.005);
        assert_eq!(a.len(), 20001);
        assert_eq!(a[0], 0.0);
        assert!(a[20000].abs() < 1e-9);
        let peak = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(peak <= 1.5 + 1e-12 && peak > 1.49, "{peak}");
        assert!((s.freq_at(0.0) - 6.0).abs() < 1e-12 && (s.freq_at(100.0) - 0.8).abs() < 1e-12);
        // Zero crossings in 10 s windows: about 2 per cycle of the local frequency.
        let crossings = |t0: usize, t1: usize| {
            a[t0..t1].windows(2).filter(|w| w[0] * w[1] < 0.0).count() as f64 / 20.0
        };
        let early = crossings(400, 2400);
        let late = crossings(18000, 20000);
        assert!((early - s.freq_at(7.0)).abs() < 0.3, "{early}");
        assert!((late - s.freq_at(95.0)).abs() < 0.3, "{late}");
    }
}
