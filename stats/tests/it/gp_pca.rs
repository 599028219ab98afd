//! PCA-reduced emulation of histories: a two-component family
//! y(t; x) = x1 sin(2πt) + x2² cos(2πt) is reduced to exactly two
//! components and predicted at fresh inputs.

use stats::gp::pca::PcaGp;
use stats::gp::GpSettings;

fn history(x: &[f64]) -> Vec<f64> {
    (0..50)
        .map(|j| {
            let t = j as f64 / 49.0;
            x[0] * (2.0 * std::f64::consts::PI * t).sin()
                + x[1] * x[1] * (2.0 * std::f64::consts::PI * t).cos()
        })
        .collect()
}

#[test]
fn two_component_family_is_reduced_and_predicted() {
    let n = 40;
    let x: Vec<f64> =
        (0..n).flat_map(|i| [i as f64 / 39.0, ((i * 13) % 40) as f64 / 39.0]).collect();
    let y: Vec<Vec<f64>> = x.chunks(2).map(history).collect();
    let set = GpSettings { noise_bounds: (1e-10, 1e-4), ..Default::default() };
    let pca = PcaGp::fit(&x, 2, &y, 0.9999, None, &set).unwrap();
    assert_eq!(pca.basis.len(), 2, "explained {}", pca.explained);
    let xt = [0.31, 0.77, 0.55, 0.12];
    let p = pca.predict(&xt).unwrap();
    for (i, pt) in xt.chunks(2).enumerate() {
        let truth = history(pt);
        let err = p.mean[i].iter().zip(&truth).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(err < 1e-2, "point {i}: max error {err}");
        assert!(p.sd[i].iter().all(|s| s.is_finite() && *s >= 0.0));
    }
}
