//! e^x for x ≤ 0 in plain arithmetic, so that a loop over a slice
//! vectorises (libm's `exp` is one call per element): Cody–Waite reduction
//! x = k ln 2 + r, |r| ≤ ln 2 / 2, a degree-13 Taylor polynomial of e^r
//! (truncation below 5e-18 relative) and 2^k from the exponent bits.
//! Kernel matrices evaluate it once per pair of points.

/// ln 2 split so that k · LN2_HI is exact for |k| < 2¹¹.
const LN2_HI: f64 = 0.693_147_180_369_123_8;
/// ln 2 − LN2_HI.
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// 1.5 · 2⁵²: adding it rounds to the nearest integer, which lands in the
/// low mantissa bits.
const ROUND: f64 = 6_755_399_441_055_744.0;
/// Below this, e^x is subnormal or zero; the kernel returns 0.
pub const UNDERFLOW: f64 = -708.0;

/// e^x for x ≤ 0 (relative error a few ulp; exactly 0 below [`UNDERFLOW`]
/// and for −∞; NaN stays NaN).
#[inline(always)]
pub fn exp_nonpositive(x: f64) -> f64 {
    let xc = x.max(UNDERFLOW);
    let shifted = xc * std::f64::consts::LOG2_E + ROUND;
    let k = shifted - ROUND;
    let r = (xc - k * LN2_HI) - k * LN2_LO;
    let mut p = 1.0 / 6_227_020_800.0;
    for c in [
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ] {
        p = p * r + c;
    }
    // The low bits of `shifted` hold k (two's complement); 2^k's exponent
    // field is k + 1023.
    let k_bits = shifted.to_bits().wrapping_sub(ROUND.to_bits());
    let scale = f64::from_bits(k_bits.wrapping_add(1023) << 52);
    if x >= UNDERFLOW {
        p * scale
    } else if x < UNDERFLOW {
        0.0
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn rel_err(x: f64) -> f64 {
        let (a, b) = (exp_nonpositive(x), x.exp());
        (a - b).abs() / b
    }

    #[test]
    fn exact_points_and_limits() {
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert_eq!(exp_nonpositive(-0.0), 1.0);
        assert_eq!(exp_nonpositive(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp_nonpositive(-800.0), 0.0);
        assert!(exp_nonpositive(f64::NAN).is_nan());
        assert!(rel_err(UNDERFLOW) < 4e-16);
        assert!(rel_err(-std::f64::consts::LN_2) < 4e-16);
    }

    #[test]
    fn dense_scan_of_the_kernel_range() {
        // u/2 of the squared exponential spans 0 … a few hundred.
        let worst = (0..200_000).map(|i| rel_err(-(i as f64) * 3.5e-3)).fold(0.0, f64::max);
        assert!(worst < 4e-16, "worst relative error {worst:e}");
    }

    proptest! {
        #[test]
        fn matches_libm(x in -708.0..0.0f64) {
            prop_assert!(rel_err(x) < 4e-16, "x = {x}: {}", rel_err(x));
        }

        #[test]
        fn is_monotone(x in -700.0..0.0f64, dx in 1e-12..1.0f64) {
            prop_assert!(exp_nonpositive(x - dx) <= exp_nonpositive(x));
        }
    }
}
