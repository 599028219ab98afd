//! Timing harness for the generated ceiling models: the 20 s verification
//! sweep (6 -> 0.8 Hz, 0.5 g, dt 0.005 s, 4000 steps, Rayleigh damping of the
//! 2.4 m fixtures) on a 3.6 m x 3.6 m specimen, a 6 m x 4.8 m one and on
//! type C (`configs/specimens/type-c.toml`, 12.6 m x 12.0 m), friction-pounding
//! perimeter, for each grid-connection law. Prints one JSON line per run:
//! CPU seconds (process user + system), steps, Newton iterations, sub-steps,
//! factorizations, low-rank updates and the peaks of the recorded groups
//! (to compare answers between solver versions).
//!
//! `cargo run -p ceilfarm-fe --example transient_variants -- [small|mid|type-c|all]
//!  [rigid|elastic|pinching4|pinching4-transverse|all] [N_STEPS] [OUT_DIR|-] [supernodal|simplicial|auto]
//!  [STALE_MAX_ITER] [--whole]`
//!
//! `--whole`: Newton on the whole structure, never condensed onto the
//! nonlinear springs.
//!
//! With `OUT_DIR` every run's history is written there as
//! `<specimen>_<connections>.csv`. Records are read from the shared
//! verification folder (`CEILFARM_SHARED`, else found above the crate).
//!
//! Measured on the shared 2-core machine (dev profile, CPU s, 4000 steps;
//! factorizations in brackets), before -> after our own substitutions and
//! the supernodal factor: 3.6 m x 3.6 m rigid 0.40 -> 0.22 (1), elastic
//! 0.74 -> 0.43 (1), Pinching4 1.99 -> 1.03 (893); type C rigid 9.5 -> 4.9
//! (94), elastic 20.9 -> 11.0 (122), Pinching4 80.4 -> 48.0 (4116).
//! Histories agree to 1.4e-9 of each channel's peak. Pinching4 stays
//! factorization-bound: hundreds of joints change branch, and so tangent,
//! in every step. Condensed onto the nonlinear springs (release, 2000
//! steps, CPU s, against `--whole`): small Pinching4 (90 nonlinear springs)
//! 0.22 vs 0.45, mid (190) 0.94 vs 1.13; type C has more springs than are
//! condensed.
//!
//! `pinching4-transverse`: the tee joints' transverse springs are Pinching4
//! too (`conn_transverse_force_scale` 1). Mid, 2000 steps, release, CPU s,
//! at commit 7137fe7 on the shared machine with one other busy process:
//! 316 nonlinear springs, so whole Newton, 1.16–1.32 s; condensed (the
//! limit raised for the measurement) 2.2–2.5 s, since 220–262 springs leave
//! their initial tangent in most steps and the dense LU of that order costs
//! more than the sparse refactorization. Axial joints only (190 springs):
//! condensed 0.70–0.81 s against whole 1.00–1.10 s, with up to 136 active.
//! The limit of 192 stays.

use std::path::{Path, PathBuf};

use fe::generator::{generate, CeilingSpec, Connections, ModelOptions, Parameters, Perimeter};
use fe::model::{Analysis, Damping, Model};
use fe::transient::{run_model, write_history_csv, CholeskyLayout, History, TransientOptions};
use serde_json::json;

/// The shared verification folder.
fn verification_dir() -> Result<PathBuf, String> {
    if let Ok(dir) = std::env::var("CEILFARM_SHARED") {
        return Ok(PathBuf::from(dir).join("verification"));
    }
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|a| a.join("shared").join("verification"))
        .find(|p| p.join("MODEL_FORMAT.md").is_file())
        .ok_or_else(|| "shared/verification not found; set CEILFARM_SHARED".to_string())
}

/// Process CPU time (user + system, s) from `/proc/self/stat` (100 Hz ticks).
fn cpu_s() -> f64 {
    let text = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = text.rsplit_once(") ").map_or("", |(_, r)| r);
    let f: Vec<f64> = after.split_whitespace().map(|x| x.parse().unwrap_or(0.0)).collect();
    f.get(11).zip(f.get(12)).map_or(f64::NAN, |(u, s)| (u + s) / 100.0)
}

/// Recorders: one mid-grid node, every x-wall friction spring, every gap
/// spring (force) and every axial connection (deformation).
fn recorders(m: &Model) -> Vec<serde_json::Value> {
    let mut r = vec![json!({"name": "u_x_mm", "node": m.masses[m.masses.len() / 2].node,
                            "dof": 1, "response": "disp"})];
    for s in &m.springs {
        let x_wall = matches!(s.side.as_deref(), Some("x0" | "x1"));
        let (name, response) = match s.group.as_deref() {
            Some("perimeter_friction") if x_wall => (format!("friction_{}", s.id), "deformation"),
            Some("perimeter_gap") => (format!("gap_{}", s.id), "force"),
            Some("connection_axial") => (format!("joint_{}", s.id), "deformation"),
            _ => continue,
        };
        r.push(json!({"name": name, "element": s.id, "response": response}));
    }
    r
}

/// Rayleigh damping and the 0.5 g sweep, `n_steps` of 0.005 s.
fn with_sweep(mut m: Model, n_steps: usize) -> Model {
    m.damping = Some(Damping {
        kind: "rayleigh".into(),
        alpha_m_per_s: 4.7639975198557405,
        beta_k_s: 0.0005247684902613158,
        extra: Default::default(),
    });
    let block = json!({
        "excitation": {"type": "uniform_base_acceleration", "dof": 1,
                       "record_csv": "sweep_x_unit_1g.csv", "dt": 0.002, "npts": 10001,
                       "scale": 0.5},
        "integrator": {"type": "Newmark", "gamma": 0.5, "beta": 0.25},
        "dt": 0.005, "n_steps": n_steps, "recorders": recorders(&m),
    });
    if let serde_json::Value::Object(map) = block {
        m.analysis = Some(Analysis::Transient(map));
    }
    m
}

/// Peak |value| over the columns whose name starts with `prefix`.
fn peak(h: &History, prefix: &str) -> f64 {
    let cols: Vec<usize> =
        (0..h.columns.len()).filter(|&c| h.columns[c].starts_with(prefix)).collect();
    h.rows.iter().flat_map(|r| cols.iter().map(move |&c| r[c].abs())).fold(0.0, f64::max)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().collect();
    let whole = args.iter().any(|a| a == "--whole");
    args.retain(|a| a != "--whole");
    let which = args.get(1).map_or("all", String::as_str);
    let conn = args.get(2).map_or("all", String::as_str);
    let n_steps: usize = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(4000);
    let out_dir = args.get(4).filter(|d| *d != "-").map(PathBuf::from);
    let stale_max_iter: usize = args.get(6).map(|s| s.parse()).transpose()?.unwrap_or(0);
    let layout = match args.get(5).map(String::as_str) {
        Some("auto") => CholeskyLayout::Auto,
        Some("simplicial") => CholeskyLayout::Simplicial,
        Some("supernodal") | None => CholeskyLayout::Supernodal,
        Some(other) => {
            return Err(format!("layout {other:?}: expected auto, simplicial or supernodal").into())
        }
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let type_c = CeilingSpec::from_toml_file(&root.join("configs/specimens/type-c.toml"))?;
    let mut small = type_c.clone();
    small.structure.length_x_m = 3.6;
    small.structure.length_y_m = 3.6;
    let mut mid = type_c.clone();
    mid.structure.length_x_m = 6.0;
    mid.structure.length_y_m = 4.8;
    let records = verification_dir()?.join("models");
    for (name, base) in [("small", &small), ("mid", &mid), ("type-c", &type_c)] {
        if which != "all" && which != name {
            continue;
        }
        let variants = [
            (Connections::Rigid, false),
            (Connections::Elastic, false),
            (Connections::Pinching4, false),
            (Connections::Pinching4, true),
        ];
        for (c, transverse) in variants {
            let label =
                if transverse { format!("{}-transverse", c.name()) } else { c.name().to_string() };
            if conn != "all" && conn != label {
                continue;
            }
            let spec = base.with_model(ModelOptions::new(Perimeter::FrictionPounding, c));
            let mut p = Parameters::prior_midpoints_for(&spec);
            if transverse {
                p.set("conn_transverse_force_scale", 1.0)?;
            }
            let m = generate(&spec, &p)?;
            let n_springs = m.springs.len();
            let m = with_sweep(m, n_steps);
            let (mut steps, mut iters, mut subs, mut facts, mut lr, mut cols, mut stale) =
                (0, 0, 0, 0, 0, 0, 0);
            let mut dense = 0;
            let nonlinear = m
                .springs
                .iter()
                .filter(|s| {
                    let mat = m.materials.iter().find(|d| d.id == s.mat);
                    !matches!(
                        mat.map(|d| &d.spec),
                        Some(fe::materials::MaterialSpec::Elastic { .. })
                    )
                })
                .count();
            let c0 = cpu_s();
            let mut opts = TransientOptions::new(&records);
            opts.cholesky = layout;
            opts.newton.stale_max_iter = stale_max_iter;
            opts.newton.condense = !whole;
            let h = run_model(&m, &opts, &mut |s| {
                steps = s.step;
                iters += s.iterations;
                subs += s.substeps;
                facts = s.factorizations;
                lr = s.low_rank_updates;
                cols = s.column_solves;
                stale = s.stale_iterations;
                dense = s.dense_factorizations;
            })?;
            let cpu = cpu_s() - c0;
            println!(
                "{{\"specimen\": \"{name}\", \"connections\": \"{}\", \"layout\": \"{layout:?}\", \"springs\": {n_springs}, \"nonlinear\": {nonlinear}, \
                 \"cpu_s\": {cpu:.2}, \"steps\": {steps}, \"substeps\": {subs}, \
                 \"newton_iterations\": {iters}, \"factorizations\": {facts}, \
                 \"low_rank_updates\": {lr}, \"column_solves\": {cols}, \"stale_iterations\": {stale}, \"dense_factorizations\": {dense}, \"peak_u_x_mm\": {:.9e}, \"peak_friction_mm\": {:.9e}, \
                 \"peak_gap_n\": {:.9e}, \"peak_joint_mm\": {:.9e}}}",
                label,
                peak(&h, "u_x"),
                peak(&h, "friction_"),
                peak(&h, "gap_"),
                peak(&h, "joint_")
            );
            if let Some(dir) = &out_dir {
                std::fs::create_dir_all(dir)?;
                write_history_csv(&h, &dir.join(format!("{name}_{label}.csv")))?;
            }
        }
    }
    Ok(())
}
