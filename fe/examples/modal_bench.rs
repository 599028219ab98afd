//! Times the eigen analysis of a model file: parse + validate + assemble +
//! Lanczos, `--repeats` times; prints JSON with the median CPU and wall
//! seconds per analysis and the frequencies. Usage:
//! `cargo run --release -p ceilfarm-fe --example modal_bench -- MODEL.json --modes 10 --repeats 5`

use std::path::PathBuf;
use std::time::Instant;

use fe::eigen::{modal_analysis, LanczosSettings};
use fe::model::read_model;

/// CPU time of this process (s), from /proc/self/stat (utime + stime).
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
    let f: Vec<f64> = after.split_whitespace().filter_map(|x| x.parse().ok()).collect();
    // Fields after the comm: state is non-numeric, so utime/stime are at 11 and 12.
    let ticks = 100.0;
    if f.len() > 12 {
        (f[10] + f[11]) / ticks
    } else {
        0.0
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // One thread: CPU time then equals the work done, as on a farm worker.
    faer::set_global_parallelism(faer::Par::Seq);
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = PathBuf::from(args.first().expect("MODEL.json"));
    let opt = |name: &str, default: usize| {
        args.iter()
            .position(|a| a == name)
            .and_then(|k| args.get(k + 1))
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let (modes, repeats, inner) = (opt("--modes", 10), opt("--repeats", 5), opt("--inner", 20));
    let (mut cpu, mut wall, mut freqs) = (vec![], vec![], vec![]);
    for _ in 0..repeats {
        // /proc CPU time ticks at 10 ms: time `inner` runs and divide.
        let (c0, w0) = (cpu_s(), Instant::now());
        for _ in 0..inner {
            let model = read_model(&path).expect("model");
            let (_, res) =
                modal_analysis(&model, modes, &LanczosSettings::default()).expect("eigen");
            freqs = res.freq_hz;
        }
        wall.push(w0.elapsed().as_secs_f64() / inner as f64);
        cpu.push((cpu_s() - c0) / inner as f64);
    }
    println!(
        "{}",
        serde_json::json!({"median_cpu_s": median(cpu.clone()), "median_wall_s": median(wall.clone()),
            "cpu_s": cpu, "wall_s": wall, "f_hz": freqs, "repeats": repeats, "inner": inner})
    );
}
