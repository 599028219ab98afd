//! Analytic LML gradient against central finite differences, for every
//! kernel family, at random hyperparameters (Rasmussen and Williams 2006,
//! eq. 5.9), plus GP behaviour with known answers: interpolation of
//! noise-free data and recovery of a known length scale.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use stats::gp::likelihood::lml_and_grad;
use stats::gp::{fit, GpSettings, KernelKind, MeanKind};

fn data(n: usize, d: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x: Vec<f64> = (0..n * d).map(|_| rng.random::<f64>()).collect();
    let y = x
        .chunks(d)
        .map(|r| (3.0 * r[0]).sin() + r.iter().sum::<f64>() * 0.5 + 0.05 * rng.random::<f64>())
        .collect();
    (x, y)
}

#[test]
fn lml_gradient_matches_finite_differences_for_every_kernel() {
    let d = 3;
    let (x, y) = data(40, d, 7);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for kind in KernelKind::ALL {
        for _ in 0..5 {
            let np = kind.n_params(d) + 1;
            let mut theta: Vec<f64> = (0..np).map(|_| rng.random_range(-1.5..0.5)).collect();
            theta[np - 1] = rng.random_range(-6.0..-2.0);
            let (_, g) = lml_and_grad(kind, &theta, &x, d, &y).unwrap();
            for j in 0..np {
                let h = 1e-5;
                let mut tp = theta.clone();
                tp[j] += h;
                let mut tm = theta.clone();
                tm[j] -= h;
                let fp = lml_and_grad(kind, &tp, &x, d, &y).unwrap().0;
                let fm = lml_and_grad(kind, &tm, &x, d, &y).unwrap().0;
                let fd = (fp - fm) / (2.0 * h);
                let tol = 1e-5 * (1.0 + fd.abs());
                assert!(
                    (fd - g[j]).abs() < tol,
                    "{kind:?} theta[{j}]: analytic {} vs fd {fd}",
                    g[j]
                );
            }
        }
    }
}

#[test]
fn interpolates_noise_free_data() {
    let d = 2;
    let x: Vec<f64> = (0..30)
        .flat_map(|i| {
            let t = i as f64 / 29.0;
            [t, (7.0 * t).fract()]
        })
        .collect();
    let y: Vec<f64> = x.chunks(d).map(|r| (4.0 * r[0]).sin() * r[1] + r[1]).collect();
    for kind in KernelKind::ALL {
        let set = GpSettings { kernel: kind, noise_bounds: (1e-10, 1e-6), ..Default::default() };
        let gp = fit(&x, d, &y, None, &set).unwrap();
        let p = gp.predict(&x, false).unwrap();
        for (m, t) in p.mean.iter().zip(&y) {
            assert!((m - t).abs() < 1e-3, "{kind:?}: {m} vs {t}");
        }
        assert!(p.sd.iter().all(|s| *s < 1e-2), "{kind:?}: sd at training points");
    }
}

#[test]
fn recovers_known_length_scale() {
    // Draw from a GP prior with l = (0.2, 2.0) on [0, 1]^2, then refit.
    let d = 2;
    let n = 300;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let x: Vec<f64> = (0..n * d).map(|_| rng.random::<f64>()).collect();
    let truth = stats::gp::Kernel {
        kind: KernelKind::SquaredExponential,
        lengths: vec![0.2, 2.0],
        variance: 1.0,
        alpha: 1.0,
    };
    let k = stats::gp::likelihood::covariance(&truth, 1e-4, &x, d);
    let l = k.as_ref().llt(faer::Side::Lower).unwrap();
    let z: Vec<f64> = (0..n).map(|_| rng.sample::<f64, _>(rand_distr::StandardNormal)).collect();
    let y: Vec<f64> = (0..n).map(|i| (0..=i).map(|j| l.L()[(i, j)] * z[j]).sum()).collect();
    let set = GpSettings { mean: MeanKind::Zero, restarts: 3, ..Default::default() };
    let bounds = stats::gp::InputScaling { lo: vec![0.0; d], hi: vec![1.0; d] };
    let gp = fit(&x, d, &y, Some(bounds), &set).unwrap();
    let l0 = gp.model.kernel.lengths[0];
    assert!((l0 - 0.2).abs() < 0.03, "fitted l0 = {l0}");
    assert!(gp.model.kernel.lengths[1] > 0.8, "fitted l1 = {}", gp.model.kernel.lengths[1]);
}

#[test]
fn shared_lml_gradient_matches_finite_differences() {
    let d = 2;
    let (x, y1) = data(30, d, 5);
    let y2: Vec<f64> = x.chunks(d).map(|r| (2.0 * r[1]).cos() - r[0]).collect();
    let ys: [&[f64]; 2] = [&y1, &y2];
    for kind in KernelKind::ALL {
        let np = kind.n_params(d) + 1;
        let mut theta: Vec<f64> = (0..np).map(|k| -0.3 - 0.1 * k as f64).collect();
        theta[np - 1] = -4.0;
        let (v, g) = stats::gp::likelihood::lml_and_grad_shared(kind, &theta, &x, d, &ys).unwrap();
        let v1 = lml_and_grad(kind, &theta, &x, d, &y1).unwrap().0;
        let v2 = lml_and_grad(kind, &theta, &x, d, &y2).unwrap().0;
        assert!((v - v1 - v2).abs() < 1e-8 * v.abs().max(1.0), "{kind:?}: shared LML is the sum");
        for j in 0..np {
            let h = 1e-5;
            let (mut tp, mut tm) = (theta.clone(), theta.clone());
            tp[j] += h;
            tm[j] -= h;
            let fp = stats::gp::likelihood::lml_and_grad_shared(kind, &tp, &x, d, &ys).unwrap().0;
            let fm = stats::gp::likelihood::lml_and_grad_shared(kind, &tm, &x, d, &ys).unwrap().0;
            let fd = (fp - fm) / (2.0 * h);
            assert!(
                (fd - g[j]).abs() < 1e-5 * (1.0 + fd.abs()),
                "{kind:?} theta[{j}]: {} vs {fd}",
                g[j]
            );
        }
    }
}
