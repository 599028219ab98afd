//! The leave-one-out shortcut (Rasmussen and Williams 2006, eq. 5.12)
//! equals refitting without each point at fixed hyperparameters.

use stats::gp::{fit, Gp, GpSettings};
use stats::validation::validate;

#[test]
fn loo_shortcut_equals_explicit_refits() {
    let d = 2;
    let n = 25;
    let x: Vec<f64> =
        (0..n).flat_map(|i| [i as f64 / 24.0, ((i * 7) % 25) as f64 / 24.0]).collect();
    let y: Vec<f64> = x.chunks(d).map(|r| (3.0 * r[0]).sin() + r[1] * r[1]).collect();
    let gp = fit(&x, d, &y, None, &GpSettings { noise_bounds: (1e-4, 1.0), ..Default::default() })
        .unwrap();
    let loo = gp.loo();
    for i in [0, 7, 24] {
        let mut m = gp.model.clone();
        m.x = (0..n)
            .filter(|&j| j != i)
            .flat_map(|j| gp.model.x[j * d..(j + 1) * d].to_vec())
            .collect();
        m.y = (0..n).filter(|&j| j != i).map(|j| gp.model.y[j]).collect();
        let g = Gp::from_model(m).unwrap();
        let p = g.predict(&x[i * d..(i + 1) * d], true).unwrap();
        assert!(
            (p.mean[0] - loo.mean[i]).abs() < 1e-8,
            "mean {i}: {} vs {}",
            p.mean[0],
            loo.mean[i]
        );
        assert!((p.sd[0] - loo.sd[i]).abs() < 1e-8, "sd {i}: {} vs {}", p.sd[0], loo.sd[i]);
    }
    let v = validate(&loo.mean, &loo.sd, &y).unwrap();
    assert!(v.r2 > 0.99, "LOO R² {}", v.r2);
}
