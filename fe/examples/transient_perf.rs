//! Runs the transient analysis of a model file and prints wall / CPU-ish time
//! per step, Newton iterations and factorizations.
//!
//! `cargo run --release -p ceilfarm-fe --example transient_perf -- MODEL.json [N_STEPS] [OUT.csv] [--whole]`
//!
//! `--whole`: Newton on the whole structure, never condensed onto the
//! nonlinear springs.
//!
//! On `perf/ceiling_typeC_nonlinear.json` (2748 free DOF, 10000 steps) the
//! release build took 5.1 s CPU (0.51 ms per step, 12688 Newton
//! iterations, 1 sparse and 2689 dense factorizations) condensed onto its
//! nonlinear springs and 15.3 s with `--whole` (20951 iterations, 1271
//! factorizations), the same run, on the 2-core reference machine; OpenSees
//! took 565-830 s CPU (`perf_results.json`).

use std::path::Path;
use std::time::Instant;

use fe::model::read_model;
use fe::transient::{run_model, write_history_csv, TransientOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().collect();
    let whole = args.iter().any(|a| a == "--whole");
    args.retain(|a| a != "--whole");
    let path =
        Path::new(args.get(1).ok_or("usage: transient_perf MODEL.json [N_STEPS] [OUT.csv]")?);
    let model = read_model(path)?;
    let mut opts = TransientOptions::new(path.parent().unwrap_or(Path::new(".")));
    opts.max_steps = args.get(2).map(|s| s.parse()).transpose()?;
    opts.newton.condense = !whole;
    let (mut steps, mut iters, mut facts, mut dense) = (0usize, 0usize, 0usize, 0usize);
    let t0 = Instant::now();
    let hist = run_model(&model, &opts, &mut |s| {
        steps = s.step;
        iters += s.iterations;
        facts = s.factorizations;
        dense = s.dense_factorizations;
    })?;
    let wall = t0.elapsed().as_secs_f64();
    println!(
        "{{\"steps\": {steps}, \"wall_s\": {wall:.3}, \"ms_per_step\": {:.4}, \"newton_iterations\": {iters}, \"factorizations\": {facts}, \"dense_factorizations\": {dense}}}",
        1e3 * wall / steps.max(1) as f64
    );
    if let Some(out) = args.get(3) {
        write_history_csv(&hist, Path::new(out))?;
    }
    Ok(())
}
