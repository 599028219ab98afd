//! A phase-free misfit of a simulated channel against a measured one: the
//! difference of their RMS over sliding windows (2 s long, 1 s apart). A
//! hysteretic model slightly off in stiffness or yield drifts out of phase
//! with the measurement over a long run, and its time-history likelihood
//! then has a needle-sharp optimum among many local ones; the windowed RMS
//! keeps the amplitude-dependent response (where a sweep resonates, how
//! much it is damped) without the phase, so its optimum is broad and lies
//! near the time-history one. Units: those of the channel.

/// Window length (s).
pub const WINDOW_S: f64 = 2.0;
/// Hop between window starts (s).
pub const HOP_S: f64 = 1.0;

/// RMS(simulated) − RMS(measured) over each window; samples where either is
/// missing (NaN) are skipped, windows with no sample give 0.
pub fn window_rms_misfit(measured: &[f64], simulated: &[f64], dt_s: f64) -> Vec<f64> {
    let n = measured.len().min(simulated.len());
    if n == 0 {
        return vec![];
    }
    let win = ((WINDOW_S / dt_s).round() as usize).clamp(1, n);
    let hop = ((HOP_S / dt_s).round() as usize).max(1);
    (0..=n - win)
        .step_by(hop)
        .map(|start| {
            let (mut sm, mut ss, mut k) = (0.0, 0.0, 0usize);
            let span = start..start + win;
            for (a, b) in measured[span.clone()].iter().zip(&simulated[span]) {
                if a.is_finite() && b.is_finite() {
                    sm += a * a;
                    ss += b * b;
                    k += 1;
                }
            }
            if k == 0 {
                0.0
            } else {
                (ss / k as f64).sqrt() - (sm / k as f64).sqrt()
            }
        })
        .collect()
}

/// −log L of windowed misfits, each channel's variance profiled out and
/// each window counted as one sample (constants dropped).
pub fn envelope_neg_log_lik(misfits: &[Vec<f64>]) -> f64 {
    misfits
        .iter()
        .filter(|m| !m.is_empty())
        .map(|m| {
            let n = m.len() as f64;
            let ssr: f64 = m.iter().map(|x| x * x).sum();
            0.5 * n * (ssr / n).max(1e-300).ln()
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_phase_shift_costs_nothing_and_a_gain_costs_its_rms() {
        let dt = 0.01;
        let t: Vec<f64> = (0..1000).map(|i| i as f64 * dt).collect();
        let m: Vec<f64> = t.iter().map(|t| (2.0 * std::f64::consts::PI * 2.0 * t).sin()).collect();
        let shifted: Vec<f64> =
            t.iter().map(|t| (2.0 * std::f64::consts::PI * 2.0 * t + 1.0).sin()).collect();
        let doubled: Vec<f64> = m.iter().map(|x| 2.0 * x).collect();
        // 10 s, 2 s windows 1 s apart: 9 windows.
        assert_eq!(window_rms_misfit(&m, &shifted, dt).len(), 9);
        for r in window_rms_misfit(&m, &shifted, dt) {
            assert!(r.abs() < 1e-9, "{r}");
        }
        for r in window_rms_misfit(&m, &doubled, dt) {
            assert!((r - 0.5f64.sqrt()).abs() < 1e-9, "{r}");
        }
    }

    proptest! {
        #[test]
        fn identical_channels_have_no_misfit(xs in proptest::collection::vec(-5.0f64..5.0, 1..400)) {
            let r = window_rms_misfit(&xs, &xs, 0.01);
            prop_assert!(!r.is_empty());
            prop_assert!(r.iter().all(|v| *v == 0.0));
        }
    }
}
