//! `ceilfarm sobol`: first- and total-order Sobol' indices with bootstrap
//! intervals, either of an analytic model (`--function ishigami|sobol-g|
//! borehole`) or of a GP emulator fitted to a sweep store's output
//! (`--store out.db --output f1`), plus the screening decision (inputs
//! with total index below `--threshold`, seed: 1 %, are inert).

use super::gp::{read_table, store_table};
use anyhow::{bail, Context};
use serde::Serialize;
use stats::gp::{fit, GpSettings};
use stats::sobol::{
    analyze, functions, saltelli_sample, screen, AnalyzeSettings, FirstOrder, Problem,
};
use std::path::PathBuf;

/// Arguments of `ceilfarm sobol`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Analytic model: ishigami, sobol-g or borehole.
    #[arg(long, conflicts_with_all = ["store", "csv"])]
    pub function: Option<String>,
    /// Sweep store whose output is emulated by a GP, then analysed.
    #[arg(long, conflicts_with = "csv")]
    pub store: Option<PathBuf>,
    /// CSV dataset (with --inputs) emulated by a GP, then analysed.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Input columns of --csv (default with --store: all parameters).
    #[arg(long, value_delimiter = ',')]
    pub inputs: Vec<String>,
    /// Output to analyse (with --store or --csv).
    #[arg(long)]
    pub output: Option<String>,
    /// Base sample size N (N (d + 2) evaluations).
    #[arg(long, default_value_t = 8192)]
    pub n: usize,
    /// Seed of the Sobol' scrambling and the bootstrap.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// First-order estimator: saltelli2010 or jansen.
    #[arg(long, default_value = "saltelli2010")]
    pub first_order: String,
    /// Bootstrap resamples for the intervals.
    #[arg(long, default_value_t = 100)]
    pub resamples: usize,
    /// Screening threshold on the total index.
    #[arg(long, default_value_t = 0.01)]
    pub threshold: f64,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Report {
    names: Vec<String>,
    #[serde(rename = "S1")]
    s1: Vec<f64>,
    #[serde(rename = "ST")]
    st: Vec<f64>,
    #[serde(rename = "S1_conf")]
    s1_conf: Vec<f64>,
    #[serde(rename = "ST_conf")]
    st_conf: Vec<f64>,
    runs: usize,
    source: String,
    screening: stats::sobol::screening::Screening,
}

/// A model output as a function of one input point.
type Evaluator = Box<dyn Fn(&[f64]) -> Vec<f64>>;

/// Problem and evaluator of the GP emulator of a dataset's output.
fn emulator(a: &Args) -> anyhow::Result<(Problem, Evaluator, String)> {
    let output = a.output.clone().context("--output is required with --store or --csv")?;
    let (table, source, inputs) = match (&a.store, &a.csv) {
        (Some(s), _) => {
            let names = coordinator::store::Store::open_read_only(s)?.parameter_names()?;
            let inputs = if a.inputs.is_empty() { names } else { a.inputs.clone() };
            (store_table(s)?, s.clone(), inputs)
        }
        (None, Some(c)) => {
            if a.inputs.is_empty() {
                bail!("--inputs is required with --csv");
            }
            (read_table(c)?, c.clone(), a.inputs.clone())
        }
        _ => bail!("give --function, --store or --csv"),
    };
    let d = inputs.len();
    let xall = table.select(&inputs, &source)?;
    let yall = table.select(std::slice::from_ref(&output), &source)?;
    let keep: Vec<usize> = (0..yall.len()).filter(|&i| yall[i].is_finite()).collect();
    let x: Vec<f64> = keep.iter().flat_map(|&i| xall[i * d..(i + 1) * d].to_vec()).collect();
    let y: Vec<f64> = keep.iter().map(|&i| yall[i]).collect();
    let gp =
        fit(&x, d, &y, None, &GpSettings::default()).with_context(|| format!("GP of {output}"))?;
    let sc = gp.model.input_scaling.clone();
    let problem = Problem {
        names: inputs,
        bounds: sc.lo.iter().zip(&sc.hi).map(|(l, h)| (*l, *h)).collect(),
    };
    let eval = move |pts: &[f64]| gp.predict(pts, false).map(|p| p.mean).unwrap_or_default();
    Ok((
        problem,
        Box::new(eval),
        format!("GP emulator of {output} ({} runs of {})", y.len(), source.display()),
    ))
}

/// Runs `ceilfarm sobol`.
pub fn run(a: Args) -> anyhow::Result<()> {
    let fo = first_order(&a.first_order)?;
    if a.n < 2 {
        bail!("--n {}: expected at least 2", a.n);
    }
    let (problem, eval, source): (Problem, Evaluator, String) = match &a.function {
        Some(name) => analytic(name)?,
        None => emulator(&a)?,
    };
    let d = problem.dim();
    let x = saltelli_sample(&problem, a.n, a.seed);
    let y = eval(&x);
    if y.len() != x.len() / d {
        bail!("emulator prediction failed");
    }
    let set = AnalyzeSettings {
        first_order: fo,
        resamples: a.resamples,
        seed: a.seed as u64,
        ..Default::default()
    };
    let r = analyze(d, &y, &set)?;
    let screening = screen(&problem.names, &r.st, a.threshold);
    let report = Report {
        names: problem.names,
        s1: r.s1,
        st: r.st,
        s1_conf: r.s1_conf,
        st_conf: r.st_conf,
        runs: y.len(),
        source,
        screening,
    };
    if a.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_table(&report, d, a.threshold);
    }
    Ok(())
}

/// The first-order estimator named by `--first-order`.
fn first_order(name: &str) -> anyhow::Result<FirstOrder> {
    Ok(match name {
        "saltelli2010" => FirstOrder::Saltelli2010,
        "jansen" => FirstOrder::Jansen,
        other => bail!("--first-order {other}: expected saltelli2010 or jansen"),
    })
}

/// Problem and evaluator of the analytic model `name` (ishigami, sobol-g or borehole).
fn analytic(name: &str) -> anyhow::Result<(Problem, Evaluator, String)> {
    let p = functions::problem(name)
        .with_context(|| format!("--function {name}: expected ishigami, sobol-g or borehole"))?;
    let f = functions::function(name).expect("function of a known problem");
    let d = p.dim();
    Ok((p, Box::new(move |x: &[f64]| x.chunks(d).map(f).collect()), format!("function {name}")))
}

/// Prints the indices of the `d` inputs as a table, then the runs and the inputs screened out.
fn print_table(report: &Report, d: usize, threshold: f64) {
    println!("{:<14} {:>9} {:>9} {:>9} {:>9}", "input", "S1", "S1_conf", "ST", "ST_conf");
    for i in 0..d {
        println!(
            "{:<14} {:>9.4} {:>9.4} {:>9.4} {:>9.4}",
            report.names[i], report.s1[i], report.s1_conf[i], report.st[i], report.st_conf[i]
        );
    }
    println!(
        "{} runs ({}); drop (ST < {}): {}",
        report.runs,
        report.source,
        threshold,
        report.screening.drop.join(", ")
    );
}
