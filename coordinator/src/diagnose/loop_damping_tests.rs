use super::*;
use crate::diagnose::testkit::sdof;
use proptest::prelude::*;
use std::f64::consts::{PI, TAU};

const DT: f64 = 1.0 / 200.0;

/// Steady response (after 10 s) of a 5 Hz oscillator with damping ratio
/// `zeta` to harmonic base shaking at `f_hz`: (force per mass, disp).
fn steady(zeta: f64, f_hz: f64) -> (Vec<f64>, Vec<f64>) {
    let ag: Vec<f64> = (0..30 * 200).map(|i| (2.0 * PI * f_hz * i as f64 * DT).sin()).collect();
    let (acc, disp) = sdof(&ag, DT, 5.0, zeta, None);
    let skip = 10 * 200;
    (acc[skip..].iter().map(|a| -a).collect(), disp[skip..].to_vec())
}

#[test]
fn a_linear_oscillator_at_resonance_gives_back_its_damping_ratio() {
    for zeta in [0.02, 0.05, 0.1] {
        let (f, u) = steady(zeta, 5.0);
        let d = loop_damping(&f, &u, 0.5).unwrap();
        assert!((d.zeta_eq / zeta - 1.0).abs() < 0.02, "zeta {zeta}: {d:?}");
        assert!(d.cycles >= 95, "{d:?}");
    }
}

#[test]
fn below_resonance_the_loop_gives_zeta_times_the_frequency_ratio() {
    // ζ_eq = ζ ω/ω_n (Chopra eq. 3.9.3): 0.05 · 4/5 = 0.04.
    let (f, u) = steady(0.05, 4.0);
    let d = loop_damping(&f, &u, 0.5).unwrap();
    assert!((d.zeta_eq - 0.04).abs() < 0.02 * 0.04, "{d:?}");
}

#[test]
fn cycles_with_missing_readings_are_left_out_not_zeroed() {
    let (mut f, mut u) = steady(0.05, 5.0);
    let whole = loop_damping(&f, &u, 0.5).unwrap();
    for i in (100..u.len()).step_by(400) {
        f[i] = f64::NAN;
        u[i + 7] = f64::NAN;
    }
    let holed = loop_damping(&f, &u, 0.5).unwrap();
    assert!(holed.cycles < whole.cycles, "{holed:?} {whole:?}");
    assert!((holed.zeta_eq / whole.zeta_eq - 1.0).abs() < 0.01, "{holed:?} {whole:?}");
    assert!(loop_damping(&[f64::NAN; 50], &[f64::NAN; 50], 0.5).is_none());
    assert!(loop_damping(&[0.0; 50], &[0.0; 50], 0.5).is_none());
}

proptest! {
    /// A Kelvin element F = k u + c u̇ on u = U sin ωt: E_D = π c ω U²,
    /// E_S = k U²/2, so ζ_eq = c ω / (2k); an elastic spring (c = 0) gives 0.
    #[test]
    fn a_kelvin_element_has_zeta_c_omega_over_two_k(
        amp in 1e-4f64..0.1,
        f_hz in 0.5f64..8.0,
        k in 1.0f64..1e4,
        ratio in 0.0f64..0.3,
        phase in 0.0f64..TAU,
        scale in 0.1f64..10.0,
    ) {
        let w = 2.0 * PI * f_hz;
        let c = 2.0 * ratio * k / w;
        let dt = 1.0 / (120.0 * f_hz);
        let n = (12.0 / (f_hz * dt)) as usize;
        let u: Vec<f64> = (0..n).map(|i| amp * (w * i as f64 * dt + phase).sin()).collect();
        let f: Vec<f64> = (0..n)
            .map(|i| k * u[i] + c * amp * w * (w * i as f64 * dt + phase).cos())
            .collect();
        let d = loop_damping(&f, &u, 0.5).unwrap();
        // E_S is read at the sampled extremes, up to half a step δ = π/120
        // of phase off the true ones: F u = kU²(cos²δ ∓ 2ζ sin δ cos δ), a
        // relative error of at most 2ζ sin δ + sin²δ; the trapezoidal loop
        // area is πcωU² sin(h)/h with h = 2π/120, off by at most h²/6.
        let (s, h) = ((PI / 120.0).sin(), TAU / 120.0);
        let tol = ratio * (2.0 * ratio * s + s * s + h * h / 6.0) + 1e-4;
        prop_assert!((d.zeta_eq - ratio).abs() < tol, "{d:?} want {ratio}");
        prop_assert!(d.cycles >= 10);
        // Neither the mass proxy nor the displacement unit matters.
        let fs: Vec<f64> = f.iter().map(|v| v * scale).collect();
        let us: Vec<f64> = u.iter().map(|v| v * scale).collect();
        let ds = loop_damping(&fs, &us, 0.5).unwrap();
        prop_assert!((ds.zeta_eq - d.zeta_eq).abs() < 1e-9 * (1.0 + d.zeta_eq.abs()));
    }
}
