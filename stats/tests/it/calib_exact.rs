//! The grid quadrature used as ground truth reproduces the benchmark's
//! exact posteriors (shared benchmarks README §3).

use crate::calib_common::*;

fn check(label: &str, e: &Exact, mean: [f64; 3], sd: [f64; 3]) {
    println!(
        "{label}: mean {:?} sd {:?} corr(k,m) {:.4} corr(k,c) {:.4}",
        e.mean, e.sd, e.corr[0][2], e.corr[0][1]
    );
    for j in 0..3 {
        assert!(
            (e.mean[j] - mean[j]).abs() < 1e-3,
            "{label} mean {j}: {} vs {}",
            e.mean[j],
            mean[j]
        );
        assert!(
            (e.sd[j] - sd[j]).abs() < 2e-3 * sd[j].max(0.01) / 0.01,
            "{label} sd {j}: {} vs {}",
            e.sd[j],
            sd[j]
        );
    }
}

#[test]
fn quadrature_reproduces_benchmark_posteriors() {
    let nodisc = plain_posterior("calib_nodisc.csv");
    let e = quadrature(nodisc.likelihood(), [1.1924, 0.3023, 1.0073], [0.25, 0.06, 0.22], 64);
    check("nodisc", &e, [1.1924, 0.3023, 1.0073], [0.0326, 0.0070, 0.0294]);
    let disc = koh_posterior("calib_disc.csv");
    let e = quadrature(disc.likelihood(), [1.1378, 0.2969, 0.9601], [0.55, 0.09, 0.48], 64);
    check("disc", &e, [1.1378, 0.2969, 0.9601], [0.0756, 0.0114, 0.0663]);
    let ignored = plain_posterior("calib_disc.csv");
    let e = quadrature(ignored.likelihood(), [1.1345, 0.30, 1.0], [0.25, 0.06, 0.22], 64);
    println!("ignored discrepancy: mean {:?} sd {:?}", e.mean, e.sd);
    assert!(
        (e.mean[0] - 1.1345).abs() < 1e-3 && (e.sd[0] - 0.0299).abs() < 1e-3,
        "{:?} {:?}",
        e.mean,
        e.sd
    );
}
