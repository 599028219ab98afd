//! `ceilfarm fe ...`: the ceiling FE model on its own (materials, models, modes).

use anyhow::Result;
use clap::{Args, Subcommand};
use std::path::PathBuf;

/// Finite-element tools.
#[derive(Subcommand)]
pub enum FeCommand {
    /// Drive one uniaxial material through an imposed deformation protocol.
    ///
    /// MATERIAL.json is one object as in the model format's materials list;
    /// PROTOCOL.csv has the header `step,deformation_mm`. Writes
    /// `deformation_mm,force_N,tangent_N_per_mm`, one committed step per row.
    Material(MaterialArgs),
    /// Run a `ceiling-fe-model` JSON file's own analysis.
    ///
    /// For eigen: writes DIR/eigen.csv (`mode,f_hz`), DIR/modeshapes.csv
    /// (`mode,node,x_mm,y_mm,phi_x,phi_y,phi_z`, mass-normalised) and
    /// DIR/modal.csv (participation factors, effective masses). For a
    /// transient: DIR/history.csv (`t_s,ag_mm_s2,<recorder names>`, one row
    /// per output step from t = 0); a run that fails still writes the rows
    /// it reached and reports the time and reason.
    Run(RunArgs),
    /// Generate a model JSON from a specimen TOML (`[structure]` table).
    ///
    /// Parameters of seed Table 6.1 start at their prior mid-points; `--set
    /// NAME=VALUE` overrides one (units mm², MPa, mm⁴, N/mm). The file runs
    /// unchanged in OpenSees (`run_opensees.py`).
    Mesh(MeshArgs),
    /// Draw the first mode shapes of a `fe run` output directory in plan (SVG).
    PlotModes(PlotModesArgs),
}

/// Arguments of `fe plot-modes`.
#[derive(Args)]
pub struct PlotModesArgs {
    /// Directory with eigen.csv and modeshapes.csv.
    pub dir: PathBuf,
    /// Output SVG.
    #[arg(long)]
    pub out: PathBuf,
    /// Number of modes drawn.
    #[arg(long, default_value_t = 6)]
    pub modes: usize,
}

/// Arguments of `fe mesh`.
#[derive(Args)]
pub struct MeshArgs {
    /// The specimen TOML file.
    pub spec: PathBuf,
    /// Parameter overrides, `NAME=VALUE` (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Output model JSON.
    #[arg(long)]
    pub out: PathBuf,
}

/// Arguments of `fe run`.
#[derive(Args)]
pub struct RunArgs {
    /// The model JSON file (`ceiling-fe-model` v1).
    pub model: PathBuf,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Number of modes (overrides the file's analysis; runs eigen).
    #[arg(long)]
    pub modes: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Arguments of `fe material`.
#[derive(Args)]
pub struct MaterialArgs {
    /// The material JSON file.
    pub material: PathBuf,
    /// The deformation protocol CSV (`step,deformation_mm`).
    pub protocol: PathBuf,
    /// Output CSV.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs an `fe` subcommand.
pub fn run(cmd: FeCommand) -> Result<()> {
    match cmd {
        FeCommand::Material(a) => {
            let rows = fe::materials::driver::run_files(&a.material, &a.protocol, &a.out)?;
            eprintln!("{rows} steps written to {}", a.out.display());
            Ok(())
        }
        FeCommand::PlotModes(a) => {
            fe::eigen::plot::plot_modes_dir(&a.dir, &a.out, a.modes)?;
            eprintln!("mode shapes drawn to {}", a.out.display());
            Ok(())
        }
        FeCommand::Mesh(a) => {
            let spec = fe::generator::CeilingSpec::from_toml_file(&a.spec)?;
            let mut params = fe::generator::Parameters::prior_midpoints_for(&spec);
            for text in &a.set {
                params.set_text(text)?;
            }
            let model = fe::generator::generate(&spec, &params)?;
            fe::model::write_model(&model, &a.out)?;
            eprintln!(
                "{} nodes, {} beams, {} springs written to {}",
                model.nodes.len(),
                model.beams.len(),
                model.springs.len(),
                a.out.display()
            );
            Ok(())
        }
        FeCommand::Run(a) => run_model(&a),
    }
}

/// `fe run`: the file's own analysis, with a progress bar for transients.
fn run_model(a: &RunArgs) -> Result<()> {
    let start = std::time::Instant::now();
    let bar = indicatif::ProgressBar::new(0);
    if a.quiet {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let mut observer = |r: &fe::transient::StepReport| {
        if r.step.is_multiple_of(50) || r.step == r.n_steps {
            bar.set_length(r.n_steps as u64);
            bar.set_position(r.step as u64);
        }
    };
    let summary = fe::run::run_model_file(&a.model, &a.out, a.modes, &mut observer);
    bar.finish_and_clear();
    match summary? {
        fe::run::RunSummary::Eigen(res) => {
            for (k, f) in res.freq_hz.iter().enumerate() {
                eprintln!("mode {:>3}: {:>12.6} Hz  ({})", k + 1, f, res.dominant(k));
            }
            eprintln!(
                "{} modes written to {} in {:.3} s",
                res.freq_hz.len(),
                a.out.display(),
                start.elapsed().as_secs_f64()
            );
        }
        fe::run::RunSummary::Transient(h) => eprintln!(
            "{} output steps of {} channels written to {} in {:.3} s",
            h.rows.len(),
            h.columns.len().saturating_sub(2),
            a.out.join("history.csv").display(),
            start.elapsed().as_secs_f64()
        ),
    }
    Ok(())
}
