//! `ceilfarm diagnose BUNDLE --out DIR`: check the bundle, calibrate the
//! baseline and its extensions on the farm (any transport), name the cause,
//! write `diagnosis.json` and `report.html`. Every FE evaluation is kept in
//! an evaluation store (default `DIR/evaluations.db`) as it arrives; running
//! the same diagnosis again re-uses what is stored and runs only the rest.

use super::sweep::FarmArgs;
use anyhow::{Context, Result};
use clap::Args as ClapArgs;
use coordinator::bundle::Bundle;
use coordinator::diagnose::calibrate::Budget;
use coordinator::diagnose::class_evidence::EvidencePolicy;
use coordinator::diagnose::damping_path::DampingPathUse;
use coordinator::diagnose::evidence::evidence;
use coordinator::diagnose::executor::FeExecutor;
use coordinator::diagnose::farm_executor::{FarmExecutor, FarmPlan};
use coordinator::diagnose::likelihood::LikelihoodKind;
use coordinator::diagnose::pipeline::{diagnose_with, DiagnoseOptions, Diagnosis, VerdictRule};
use coordinator::diagnose::resample::Decimated;
use coordinator::diagnose::verdict::{verdict, VerdictJson};
use coordinator::farm::FarmSettings;
use coordinator::study::TransportKind;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};

/// Worker count when `--workers` is not given.
const DEFAULT_WORKERS: usize = 2;

/// Arguments of `diagnose`.
#[derive(ClapArgs)]
pub struct Args {
    /// The bundle directory.
    pub bundle: PathBuf,
    /// Output directory (diagnosis.json, report.html, evaluations.db).
    #[arg(long)]
    pub out: PathBuf,
    /// The evaluation store (SQLite; default OUT/evaluations.db). An
    /// existing store is re-used: stored evaluations are not run again.
    #[arg(long)]
    pub store: Option<PathBuf>,
    /// Workers, transport, progress (default: 2 in-process workers).
    #[command(flatten)]
    pub farm: FarmArgs,
    /// Design points per calibrated parameter.
    #[arg(long, default_value_t = 5)]
    pub points_per_parameter: usize,
    /// Seed of the calibration designs.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Walks along the least-determined direction of an extension's
    /// parameters after its local search, each followed by another local
    /// search (about 15 % more FE runs; finds narrow valleys the local
    /// search stops in).
    #[arg(long, default_value_t = 0)]
    pub valley_walks: usize,
    /// Walks along the least-determined direction for the extension the
    /// diagnosis names, after every variant is calibrated, each followed by
    /// another local search (~20 FE runs each; at most one in a large
    /// campaign, none there for connection hysteresis); above 0 a ridge
    /// walk along each shape parameter comes first (~30 to 65 FE runs each).
    #[arg(long, default_value_t = 2)]
    pub refine_walks: usize,
    /// When connection hysteresis is also calibrated along a second path
    /// with the viscous damping explored below the baseline's estimate
    /// (about 50 more FE runs; for strong hysteresis, whose dissipation the
    /// baseline takes for damping): `auto` when its first path is within
    /// 1000 nats of the best variant before it and the campaign is small
    /// (grid modules x calibration samples at most 250 000).
    #[arg(long, value_enum, default_value_t = DampingPathUse::WhenContending)]
    pub damping_path: DampingPathUse,
    /// Runs recorded at twice this rate or faster are low-passed and
    /// decimated to the whole fraction of their rate nearest it from above
    /// before calibration (Hz; 0: simulate every run at its own rate, slower
    /// in proportion).
    #[arg(long, default_value_t = coordinator::diagnose::resample::SIMULATION_RATE_HZ)]
    pub simulation_rate_hz: f64,
    /// Skip the linear stage: every variant keeps the generator's linear
    /// form and calibrates the perimeter stiffness and damping alone.
    #[arg(long, conflicts_with = "linear_only")]
    pub no_linear_stage: bool,
    /// Also compute every calibrated class's evidence p(data | class) and
    /// posterior probability (tempered SMC on an emulator of ln L, checked
    /// by FE runs; about 80 to 160 more FE runs a class) and write them to
    /// diagnosis.json beside the verdict (which they name with --verdict
    /// evidence).
    #[arg(long, conflicts_with = "linear_only")]
    pub evidence: bool,
    /// With --evidence: the likelihood it integrates, `band` (the residual
    /// within the model's band, 0 to 40 Hz, under its in-band degrees of
    /// freedom: its nats do not grow with the sampling rate), `time` (the
    /// calibration's Gaussian under effective sample sizes) or `whittle`
    /// (the periodogram's level per 2 Hz sub-band; for comparison).
    #[arg(long, requires = "evidence", default_value = "band",
          value_parser = ["band", "time", "whittle"])]
    pub evidence_likelihood: String,
    /// With --evidence: what names the cause, `mdl` (the MDL rules) or
    /// `evidence` (the class of highest posterior probability).
    #[arg(long, requires = "evidence", default_value = "mdl", value_parser = ["mdl", "evidence"])]
    pub verdict: String,
    /// With --verdict evidence: also search classes of several effects
    /// (forward and backward from the most probable single one;
    /// experimental, see docs/diagnosis.md).
    #[arg(long, requires = "evidence")]
    pub combine: bool,
    /// With --evidence: the prior probability that each effect acts,
    /// independently of the others (0.5: every class equally probable
    /// before the data).
    #[arg(long, requires = "evidence", default_value_t = 0.5)]
    pub effect_prior: f64,
    /// Run the linear stage only: print its fit of the weakest runs and
    /// `modal.csv` and write it to OUT/linear.json.
    #[arg(long)]
    pub linear_only: bool,
    /// With --linear-only: no search, the linear model at these values
    /// (NAME=VALUE, comma-separated; the others at the nominal specimen).
    #[arg(long, requires = "linear_only", value_delimiter = ',')]
    pub linear_at: Vec<String>,
}

/// Runs `diagnose`.
pub fn run(a: Args) -> Result<()> {
    let sweep = a.farm.options(a.out.join("evaluations.db"), true)?;
    let workers = sweep.workers.unwrap_or(DEFAULT_WORKERS);
    let budget = Budget {
        threads: workers,
        per_dim: a.points_per_parameter,
        seed: a.seed,
        valley_walks: a.valley_walks,
        refine_walks: a.refine_walks,
        damping_path: a.damping_path,
        ..Budget::default()
    };
    let plan = FarmPlan {
        transport: sweep.transport.unwrap_or(TransportKind::InProcess),
        workers,
        endpoint: sweep.endpoint,
        settings: FarmSettings::default(),
        store: Some(a.store.unwrap_or(sweep.store)),
        zenoh: sweep.zenoh.clone(),
    };
    let rate = a.simulation_rate_hz;
    if !(rate >= 0.0 && rate.is_finite()) {
        anyhow::bail!("--simulation-rate-hz {rate}: expected a rate in Hz, or 0 for none");
    }
    let p = a.effect_prior;
    if !(p > 0.0 && p < 1.0) {
        anyhow::bail!("--effect-prior {p}: expected a probability strictly between 0 and 1");
    }
    if a.combine && a.verdict != "evidence" {
        anyhow::bail!("--combine: classes of several effects are searched by their evidence; add --verdict evidence");
    }
    let opts = DiagnoseOptions {
        budget,
        combine: a.combine,
        linear_stage: !a.no_linear_stage,
        evidence: a.evidence.then(|| EvidencePolicy {
            likelihood: LikelihoodKind::parse(&a.evidence_likelihood).unwrap_or_default(),
            effect_prior: p,
            ..EvidencePolicy::default()
        }),
        rule: if a.verdict == "evidence" { VerdictRule::Evidence } else { VerdictRule::Mdl },
        ..Default::default()
    };
    if a.linear_only {
        let at = parse_values(&a.linear_at)?;
        return linear_only(&a.bundle, &a.out, &opts, (rate > 0.0).then_some(rate), &at);
    }
    let report =
        diagnose_dir(&a.bundle, &a.out, &opts, (rate > 0.0).then_some(rate), &plan, a.farm.quiet)?;
    println!("report: {}", report.display());
    Ok(())
}

/// The linear stage alone on the bundle in `dir`: prints its fit and writes
/// `out/linear.json`.
fn linear_only(
    dir: &Path,
    out: &Path,
    opts: &DiagnoseOptions,
    rate: Option<f64>,
    at: &[(String, f64)],
) -> Result<()> {
    use coordinator::diagnose::linear_stage::{linear_at, linear_stage, report::LinearJson};
    let (bundle, _) = read_for_simulation(dir, rate)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let (cal, _) = coordinator::diagnose::pipeline::split_runs(&bundle);
    let start = std::time::Instant::now();
    let (threads, seed) = (opts.budget.threads, opts.budget.seed);
    let stage = if at.is_empty() {
        linear_stage(&bundle, &cal, threads, seed, &mut |_, _| {})
    } else {
        linear_at(&bundle, &cal, at)
    }
    .map_err(|e| anyhow::anyhow!(e))?;
    let ids: Vec<String> = bundle.manifest.runs.iter().map(|r| r.id.clone()).collect();
    let json = LinearJson::of(&ids, &stage);
    eprint!("{}", json.summary());
    eprintln!("{} linear evaluations in {:.1} s", stage.evaluations, start.elapsed().as_secs_f64());
    let path = out.join("linear.json");
    std::fs::write(&path, serde_json::to_string_pretty(&json)?)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// `NAME=VALUE` pairs, each value a number.
fn parse_values(items: &[String]) -> Result<Vec<(String, f64)>> {
    items
        .iter()
        .map(|t| {
            let (n, v) = t
                .split_once('=')
                .with_context(|| format!("--linear-at {t}: expected NAME=VALUE"))?;
            let v: f64 = v
                .trim()
                .parse()
                .with_context(|| format!("--linear-at {t}: {v:?} is not a number"))?;
            Ok((n.trim().to_string(), v))
        })
        .collect()
}

/// Diagnoses the bundle in `dir` on the farm of `plan`, its runs recorded
/// at twice `simulation_rate_hz` or faster decimated towards it (None: every
/// run at its own rate), writes the verdict and report to `out`; returns the
/// report's path.
pub fn diagnose_dir(
    dir: &Path,
    out: &Path,
    opts: &DiagnoseOptions,
    simulation_rate_hz: Option<f64>,
    plan: &FarmPlan,
    quiet: bool,
) -> Result<PathBuf> {
    let (bundle, resampled) = read_for_simulation(dir, simulation_rate_hz)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut exec = FarmExecutor::new(plan.clone())?;
    let d = diagnose_with_progress(&bundle, opts, &mut exec, quiet)?;
    let (v, report) = write_diagnosis(out, &bundle, &d, &resampled)?;
    print_verdict(&v, &d);
    if let Some(store) = &plan.store {
        print_store_use(store, plan, &exec);
    }
    Ok(report)
}

/// Reads and summarises the bundle in `dir`, its fast runs decimated towards the rate (Hz).
fn read_for_simulation(
    dir: &Path,
    simulation_rate_hz: Option<f64>,
) -> Result<(Bundle, Vec<Decimated>)> {
    let bundle = coordinator::bundle::read_bundle(dir)?;
    eprintln!("{}", bundle.summary());
    let (bundle, resampled) = match simulation_rate_hz {
        Some(rate) => coordinator::diagnose::resample::for_simulation(&bundle, rate),
        None => (bundle, vec![]),
    };
    for r in &resampled {
        eprintln!(
            "run {}: recorded at {:.0} Hz, low-passed and simulated at {:.0} Hz",
            r.run, r.from_hz, r.to_hz
        );
    }
    Ok((bundle, resampled))
}

/// Diagnoses `bundle` through `exec`, the stages shown on a progress bar (hidden when `quiet`).
fn diagnose_with_progress(
    bundle: &Bundle,
    opts: &DiagnoseOptions,
    exec: &mut dyn FeExecutor,
    quiet: bool,
) -> Result<Diagnosis> {
    let bar = progress_bar(quiet);
    let d = diagnose_with(bundle, opts, exec, &mut |stage, done, planned| {
        bar.set_message(stage.to_string());
        bar.set_length(planned as u64);
        bar.set_position(done as u64);
    })?;
    bar.finish_and_clear();
    Ok(d)
}

/// Writes `diagnosis.json` and `report.html` to `out`; returns the verdict and the report's path.
fn write_diagnosis(
    out: &Path,
    bundle: &Bundle,
    d: &Diagnosis,
    resampled: &[Decimated],
) -> Result<(VerdictJson, PathBuf)> {
    let ids: Vec<String> = bundle.manifest.runs.iter().map(|r| r.id.clone()).collect();
    let symptoms = evidence(bundle, d);
    let v = verdict(d, &ids).with_symptoms(&symptoms);
    let json = out.join("diagnosis.json");
    std::fs::write(&json, serde_json::to_string_pretty(&v)?)
        .with_context(|| format!("writing {}", json.display()))?;
    let report = out.join("report.html");
    let html = coordinator::diagnose::report::render(bundle, d, &symptoms, resampled);
    std::fs::write(&report, html).with_context(|| format!("writing {}", report.display()))?;
    Ok((v, report))
}

/// Prints the cause named and any warning: an extension the validation runs barely
/// exercise, or runs left unexplained.
fn print_verdict(v: &VerdictJson, d: &Diagnosis) {
    eprintln!(
        "cause: {} (gain {:.3}: validation error {:.3} -> {:.3}; {} FE points)",
        v.cause, v.gain, v.baseline_validation_error, v.extended_validation_error, v.fe_points
    );
    eprintln!("load: {}", coordinator::diagnose::stage_load::summary(&d.stage_loads));
    if let Some(u) = &d.unexplained {
        eprintln!("warning: unexplained: no model explains the data within the noise:");
        for line in u.lines() {
            eprintln!("  {line}");
        }
    }
    if coordinator::diagnose::verdict_notes::unexercised_note(d).is_some() {
        eprintln!(
            "warning: {} fits the calibration runs far better, but it and the baseline predict \
             the validation runs alike: they barely exercise it and the gain does not measure \
             it (see the report's verdict)",
            v.cause
        );
    }
    if coordinator::diagnose::verdict_notes::unexplained_note(d).is_some() {
        eprintln!(
            "warning: no extension fits the calibration runs better, but the baseline misses \
             the validation runs by {:.3} in excess of the noise: they show something the \
             calibration runs do not (see the report's verdict)",
            v.baseline_validation_error
        );
    }
}

/// Prints the evaluation store and the FE evaluations run now and re-used from it.
fn print_store_use(store: &Path, plan: &FarmPlan, exec: &FarmExecutor) {
    eprintln!(
        "store: {} ({} FE evaluations run now on {} {} workers, {} re-used; {} run \
         simulations stored now)",
        store.display(),
        exec.simulated(),
        plan.workers,
        plan.transport.as_str(),
        exec.reused(),
        exec.tasks_run()
    );
}

/// The progress bar of the calibration stages (hidden when `quiet`).
fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{msg:28} [{bar:30}] {pos}/{len} FE points {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
