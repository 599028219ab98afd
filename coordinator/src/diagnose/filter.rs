//! Second-order Butterworth sections (bilinear transform, RBJ cookbook form)
//! for separating the high-frequency content of accelerations.

/// One biquad section, direct form I, normalised so that `a0 = 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

impl Biquad {
    /// Butterworth high-pass with corner `fc_hz` at sampling step `dt_s`.
    ///
    /// `None` unless `0 < fc_hz < ` the Nyquist frequency.
    pub fn high_pass(fc_hz: f64, dt_s: f64) -> Option<Self> {
        Self::butterworth(fc_hz, dt_s, |cos| [(1.0 + cos) / 2.0, -(1.0 + cos), (1.0 + cos) / 2.0])
    }

    /// Butterworth low-pass with corner `fc_hz` at sampling step `dt_s`.
    ///
    /// `None` unless `0 < fc_hz < ` the Nyquist frequency.
    pub fn low_pass(fc_hz: f64, dt_s: f64) -> Option<Self> {
        Self::butterworth(fc_hz, dt_s, |cos| [(1.0 - cos) / 2.0, 1.0 - cos, (1.0 - cos) / 2.0])
    }

    /// A second-order section with Q = 1/√2 and numerator `b(cos ω0)`.
    fn butterworth(fc_hz: f64, dt_s: f64, b: impl Fn(f64) -> [f64; 3]) -> Option<Self> {
        let nyquist = 0.5 / dt_s;
        if !(fc_hz > 0.0 && fc_hz < nyquist && dt_s > 0.0) {
            return None;
        }
        let w0 = 2.0 * std::f64::consts::PI * fc_hz * dt_s;
        let (sin, cos) = w0.sin_cos();
        let alpha = sin / (2.0 * std::f64::consts::FRAC_1_SQRT_2);
        let a0 = 1.0 + alpha;
        let b = b(cos).map(|v| v / a0);
        let a = [-2.0 * cos / a0, (1.0 - alpha) / a0];
        Some(Self { b, a })
    }

    /// Filters `x` forward then backward (zero phase, squared magnitude).
    pub fn filtfilt(&self, x: &[f64]) -> Vec<f64> {
        let mut y = self.run(x.iter().copied());
        y.reverse();
        let mut z = self.run(y.into_iter());
        z.reverse();
        z
    }

    fn run(&self, x: impl Iterator<Item = f64>) -> Vec<f64> {
        let (mut x1, mut x2, mut y1, mut y2) = (0.0, 0.0, 0.0, 0.0);
        x.map(|x0| {
            let y0 =
                self.b[0] * x0 + self.b[1] * x1 + self.b[2] * x2 - self.a[0] * y1 - self.a[1] * y2;
            (x2, x1, y2, y1) = (x1, x0, y1, y0);
            y0
        })
        .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::Biquad;

    fn rms_after(f_hz: f64, fc_hz: f64) -> f64 {
        let dt = 1.0 / 200.0;
        let x: Vec<f64> =
            (0..4000).map(|i| (2.0 * std::f64::consts::PI * f_hz * i as f64 * dt).sin()).collect();
        let y = Biquad::high_pass(fc_hz, dt).unwrap().filtfilt(&x);
        let mid = &y[1000..3000];
        (mid.iter().map(|v| v * v).sum::<f64>() / mid.len() as f64).sqrt()
    }

    #[test]
    fn the_corner_passes_half_the_power_each_way() {
        // filtfilt squares the magnitude: -3 dB each pass, -6 dB in all.
        let at_corner = rms_after(20.0, 20.0) * std::f64::consts::SQRT_2;
        assert!((at_corner - 0.5).abs() < 0.01, "{at_corner}");
    }

    #[test]
    fn low_frequencies_are_removed_and_high_ones_kept() {
        assert!(rms_after(2.0, 20.0) < 2e-4);
        let high = rms_after(60.0, 20.0) * std::f64::consts::SQRT_2;
        assert!((high - 1.0).abs() < 0.02, "{high}");
    }

    #[test]
    fn corners_outside_the_band_are_refused() {
        assert!(Biquad::high_pass(0.0, 0.01).is_none());
        assert!(Biquad::high_pass(50.0, 0.01).is_none());
        assert!(Biquad::high_pass(10.0, 0.0).is_none());
    }

    #[test]
    fn low_pass_mirrors_high_pass() {
        let dt = 1.0 / 200.0;
        let rms = |f_hz: f64| {
            let x: Vec<f64> = (0..4000)
                .map(|i| (2.0 * std::f64::consts::PI * f_hz * i as f64 * dt).sin())
                .collect();
            let y = Biquad::low_pass(20.0, dt).unwrap().filtfilt(&x);
            let mid = &y[1000..3000];
            (mid.iter().map(|v| v * v).sum::<f64>() / mid.len() as f64).sqrt()
        };
        assert!((rms(20.0) * std::f64::consts::SQRT_2 - 0.5).abs() < 0.01);
        assert!((rms(2.0) * std::f64::consts::SQRT_2 - 1.0).abs() < 1e-3);
        assert!(rms(80.0) < 0.01);
    }
}
