//! Generalisability Gr % (seed eq. 6.12):
//! Gr = (1 − sum_i |y(x_i, theta) − y_truth(x_i)| / sum_i |y_truth(x_i)|) × 100.

/// Gr % of predictions against the true responses at the same points.
pub fn gr_percent(predicted: &[f64], truth: &[f64]) -> f64 {
    let err: f64 = predicted.iter().zip(truth).map(|(p, t)| (p - t).abs()).sum();
    let scale: f64 = truth.iter().map(|t| t.abs()).sum();
    (1.0 - err / scale) * 100.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_prediction_is_one_hundred() {
        assert_eq!(gr_percent(&[1.0, -2.0], &[1.0, -2.0]), 100.0);
    }

    #[test]
    fn ten_percent_off_is_ninety() {
        assert!((gr_percent(&[1.1, 2.2], &[1.0, 2.0]) - 90.0).abs() < 1e-12);
    }
}
