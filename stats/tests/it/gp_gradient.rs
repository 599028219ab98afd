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

#[test]
fn warped_lml_gradient_matches_finite_differences() {
    let d = 3;
    let (x, y) = data(30, d, 9);
    // Inputs 0 and 2 warped (ranges spanning 500 and 3), input 1 not.
    let ratios = [Some(500.0), None, Some(3.0)];
    let lml = |kind, t: &[f64]| {
        stats::gp::likelihood::lml_and_grad_warped(kind, &ratios, t, &x, d, &[&y]).unwrap()
    };
    for kind in KernelKind::ALL {
        let nk = kind.n_params(d);
        let mut theta: Vec<f64> = (0..nk).map(|k| -0.5 + 0.1 * k as f64).collect();
        theta.extend([0.3, 1.7, -4.0]);
        let g = lml(kind, &theta).1;
        for j in 0..theta.len() {
            let h = 1e-5;
            let (mut tp, mut tm) = (theta.clone(), theta.clone());
            tp[j] += h;
            tm[j] -= h;
            let fd = (lml(kind, &tp).0 - lml(kind, &tm).0) / (2.0 * h);
            assert!(
                (fd - g[j]).abs() < 1e-5 * (1.0 + fd.abs()),
                "{kind:?} theta[{j}]: {} vs {fd}",
                g[j]
            );
        }
    }
}

#[test]
fn warp_learns_log_scale_of_an_input_spanning_decades() {
    // y = sin(ln x) on x in [1, 1000]: smooth in ln x, not in x.
    let n = 40;
    let x: Vec<f64> = (0..n).map(|i| 10f64.powf(3.0 * i as f64 / (n - 1) as f64)).collect();
    let y: Vec<f64> = x.iter().map(|v| v.ln().sin()).collect();
    let scaling = stats::gp::InputScaling { lo: vec![1.0], hi: vec![1000.0] };
    let xt: Vec<f64> = (0..200).map(|i| 1.0 + 999.0 * (i as f64 + 0.5) / 200.0).collect();
    let rmse = |warp: bool| {
        let set = GpSettings { warp, ..Default::default() };
        let gp = fit(&x, 1, &y, Some(scaling.clone()), &set).unwrap();
        let p = gp.predict(&xt, false).unwrap();
        let e = p.mean.iter().zip(&xt).map(|(m, v)| (m - v.ln().sin()).powi(2)).sum::<f64>();
        ((e / xt.len() as f64).sqrt(), gp.model.warp)
    };
    let (warped, warp) = rmse(true);
    let (plain, _) = rmse(false);
    let lambda = warp.inputs[0].unwrap().lambda;
    assert!(lambda.abs() < 0.2, "λ = {lambda} (log scale is 0)");
    assert!(warped < 1e-3 && warped < 0.1 * plain, "RMSE warped {warped}, plain {plain}");
}

#[test]
fn reused_workspace_gives_the_fresh_workspace_answer() {
    // One workspace through kernels, sizes and warps in turn, against a
    // fresh one each time: buffers left from an earlier call must not leak.
    use stats::gp::lml_workspace::LmlWorkspace;
    let d = 3;
    let mut ws = LmlWorkspace::default();
    let ratios = [Some(50.0), None, Some(4.0)];
    for (n, kind) in [(25, KernelKind::RationalQuadratic), (40, KernelKind::Matern52)]
        .into_iter()
        .chain([(25, KernelKind::SquaredExponential), (25, KernelKind::RationalQuadratic)])
    {
        let (x, y) = data(n, d, n as u64);
        let mut theta: Vec<f64> = (0..kind.n_params(d)).map(|k| -0.4 + 0.1 * k as f64).collect();
        theta.extend([0.5, 1.2, -5.0]);
        let reused = ws.lml_and_grad(kind, &ratios, &theta, &x, d, &[&y]).unwrap();
        let fresh = LmlWorkspace::default().lml_and_grad(kind, &ratios, &theta, &x, d, &[&y]);
        assert_eq!(reused, fresh.unwrap(), "{kind:?}, n = {n}");
    }
}
