//! Farm overhead: tasks/s of the in-process farm on the no-op model, at 1
//! and 2 workers, without a store (pure scheduling + transport) and with
//! the SQLite store. Run by `scripts/bench/farm-overhead`.

use coordinator::farm::{run_farm, FarmSettings, ResultSink, Silent};
use coordinator::store::{Keep, Store};
use coordinator::study::Study;
use protocol::in_process::InProcess;
use protocol::{Task, TaskId, TaskResult};
use std::time::Instant;

struct Null;
impl ResultSink for Null {
    fn accept(&mut self, _: &[TaskResult]) -> Result<(), String> {
        Ok(())
    }
}

struct StoreSink(Store);
impl ResultSink for StoreSink {
    fn accept(&mut self, r: &[TaskResult]) -> Result<(), String> {
        self.0.record(r, 1, &Keep::default()).map(|_| ()).map_err(|e| e.to_string())
    }
}

#[path = "common/cpu.rs"]
mod cpu;

/// CPU seconds of this process.
fn cpu_s() -> f64 {
    cpu::cpu_s().0
}

const STUDY: &str = r#"
[study]
name = "noop"
[model]
kind = "noop"
[[parameters]]
name = "a"
low = 0.0
high = 1.0
[design]
method = "lhs"
n = 2
seed = 1
"#;

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(50_000);
    let repeats: usize = std::env::args().nth(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let study = Study::parse(STUDY, std::path::Path::new("noop.toml")).expect("study");
    let spec = study.model_spec();
    let tasks: Vec<Task> =
        (0..n).map(|i| Task { id: TaskId(i as u64), params: vec![0.5] }).collect();
    println!(
        "{:<10} {:>8} {:>12} {:>12} {:>12}",
        "sink", "workers", "tasks/s", "wall us/task", "cpu us/task"
    );
    for with_store in [false, true] {
        for workers in [1usize, 2] {
            let mut best = (0.0f64, f64::INFINITY, f64::INFINITY);
            for _ in 0..repeats {
                let dir = tempfile::tempdir().expect("tempdir");
                let design: Vec<Vec<f64>> = vec![vec![0.5]; n];
                let mut transport = InProcess::new(workers, worker::LocalRunner::factory());
                let (c0, t0) = (cpu_s(), Instant::now());
                let settings = FarmSettings::default();
                let summary = if with_store {
                    let store =
                        Store::create(&dir.path().join("s.db"), &study, &design, &["y".into()])
                            .expect("store");
                    let mut sink = StoreSink(store);
                    run_farm(
                        &mut transport,
                        "h",
                        &spec,
                        tasks.clone(),
                        &settings,
                        &mut sink,
                        &mut Silent,
                    )
                } else {
                    run_farm(
                        &mut transport,
                        "h",
                        &spec,
                        tasks.clone(),
                        &settings,
                        &mut Null,
                        &mut Silent,
                    )
                }
                .expect("farm");
                assert_eq!(summary.ok, n);
                let wall = t0.elapsed().as_secs_f64();
                let cpu = cpu_s() - c0;
                if wall < best.1 {
                    best = (n as f64 / wall, wall * 1e6 / n as f64, cpu * 1e6 / n as f64);
                }
            }
            let sink = if with_store { "sqlite" } else { "none" };
            println!("{sink:<10} {workers:>8} {:>12.0} {:>12.2} {:>12.2}", best.0, best.1, best.2);
        }
    }
}
