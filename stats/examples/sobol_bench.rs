//! Sobol' indices of Ishigami and the G function by Saltelli sampling,
//! timed from sampling to bootstrap intervals, with the max error against
//! the exact values of the benchmark README.
//! `sobol_bench N` prints `function N runs cpu_s wall_s max_err_s1 max_err_st`.

use stats::sobol::{analyze, functions, saltelli_sample, AnalyzeSettings};
use std::time::Instant;

fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after.split_whitespace().map(|v| v.parse().unwrap_or(0.0)).collect();
    if f.len() > 12 {
        (f[11] + f[12]) / 100.0
    } else {
        f64::NAN
    }
}

fn max_err(got: &[f64], exact: &[f64]) -> f64 {
    got.iter().zip(exact).map(|(g, e)| (g - e).abs()).fold(0.0, f64::max)
}

fn main() {
    let n: usize = std::env::args().nth(1).map(|v| v.parse().expect("N")).unwrap_or(8192);
    let cases: [(&str, Vec<f64>, Vec<f64>); 2] = [
        ("ishigami", vec![0.3139, 0.4424, 0.0], vec![0.5576, 0.4424, 0.2437]),
        (
            "sobol-g",
            vec![0.7162, 0.1790, 0.0237, 0.0072, 0.0001, 0.0001, 0.0001, 0.0001],
            vec![0.7871, 0.2422, 0.0343, 0.0105, 0.0001, 0.0001, 0.0001, 0.0001],
        ),
    ];
    for (name, s1, st) in cases {
        let (c0, w0) = (cpu_seconds(), Instant::now());
        let p = functions::problem(name).unwrap();
        let f = functions::function(name).unwrap();
        let x = saltelli_sample(&p, n, 0);
        let y: Vec<f64> = x.chunks(p.dim()).map(f).collect();
        let r = analyze(p.dim(), &y, &AnalyzeSettings::default()).unwrap();
        let (cpu, wall) = (cpu_seconds() - c0, w0.elapsed().as_secs_f64());
        println!(
            "{name} {n} {} {cpu:.3} {wall:.4} {:.5} {:.5}",
            y.len(),
            max_err(&r.s1, &s1),
            max_err(&r.st, &st)
        );
    }
}
