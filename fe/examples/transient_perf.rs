//! Runs the transient analysis of a model file and prints wall / CPU-ish time
//! per step, Newton iterations and factorizations.
//!
//! `cargo run --release -p ceilfarm-fe --example transient_perf -- MODEL.json [N_STEPS] [OUT.csv]`
//!
//! On `perf/ceiling_typeC_nonlinear.json` (2748 free DOF, 10000 steps) the
//! release build took 14.2 s CPU (1.42 ms per step, 22688 Newton iterations,
//! 172 factorizations) on the 2-core reference machine, against 565-830 s
//! CPU for OpenSees (`perf_results.json`).

use std::path::Path;
use std::time::Instant;

use fe::model::read_model;
use fe::transient::{run_model, write_history_csv, TransientOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path =
        Path::new(args.get(1).ok_or("usage: transient_perf MODEL.json [N_STEPS] [OUT.csv]")?);
    let model = read_model(path)?;
    let mut opts = TransientOptions::new(path.parent().unwrap_or(Path::new(".")));
    opts.max_steps = args.get(2).map(|s| s.parse()).transpose()?;
    let (mut steps, mut iters, mut facts) = (0usize, 0usize, 0usize);
    let t0 = Instant::now();
    let hist = run_model(&model, &opts, &mut |s| {
        steps = s.step;
        iters += s.iterations;
        facts = s.factorizations;
    })?;
    let wall = t0.elapsed().as_secs_f64();
    println!(
        "{{\"steps\": {steps}, \"wall_s\": {wall:.3}, \"ms_per_step\": {:.4}, \"newton_iterations\": {iters}, \"factorizations\": {facts}}}",
        1e3 * wall / steps.max(1) as f64
    );
    if let Some(out) = args.get(3) {
        write_history_csv(&hist, Path::new(out))?;
    }
    Ok(())
}
