//! What the pipeline tells its user: a timed line per stage on stderr (a
//! spinner on a terminal), summary.json, and the closing text tables.

use super::calibration::{ParameterRow, PredictiveRow};
use super::emulators::{EmulatorReport, Split};
use coordinator::sweep::SweepReport;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use stats::selection::SelectionTable;
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Wall time of one stage.
#[derive(Debug, Clone, Serialize)]
pub struct StageTime {
    /// Stage name.
    pub stage: String,
    /// Seconds.
    pub wall_s: f64,
}

/// Times the stages and shows which one runs.
pub struct Stages {
    quiet: bool,
    current: Option<(String, Instant, ProgressBar)>,
    times: Vec<StageTime>,
}

impl Stages {
    /// No output with `quiet`.
    pub fn new(quiet: bool) -> Self {
        Stages { quiet, current: None, times: Vec::new() }
    }

    /// Starts stage `name`.
    pub fn start(&mut self, name: &str) {
        let target = if self.quiet || !std::io::stderr().is_terminal() {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        };
        let bar = ProgressBar::with_draw_target(None, target);
        if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} {elapsed}") {
            bar.set_style(style);
        }
        bar.set_message(name.to_string());
        if name != "sweep" {
            bar.enable_steady_tick(Duration::from_millis(200));
        }
        self.current = Some((name.to_string(), Instant::now(), bar));
    }

    /// Ends the current stage with a one-line result.
    pub fn done(&mut self, what: &str) {
        if let Some((name, t0, bar)) = self.current.take() {
            bar.finish_and_clear();
            let wall_s = t0.elapsed().as_secs_f64();
            if !self.quiet {
                eprintln!("{name:<12} {wall_s:8.1} s  {what}");
            }
            self.times.push(StageTime { stage: name, wall_s });
        }
    }

    /// The stage times.
    pub fn finish(self) -> Vec<StageTime> {
        self.times
    }
}

/// One line on the emulators.
pub fn emulator_line(r: &[EmulatorReport], s: &Split) -> String {
    let each: Vec<String> =
        r.iter().map(|e| format!("{} {} R2 {:.4}", e.output, e.kernel, e.test.r2)).collect();
    format!("{}/{}/{} runs; {}", s.train, s.validation, s.test, each.join("; "))
}

/// Screening decision.
#[derive(Debug, Clone, Serialize)]
pub struct ScreeningSummary {
    /// Kept, by decreasing total index.
    pub keep: Vec<String>,
    /// Dropped.
    pub drop: Vec<String>,
}

/// summary.json.
#[derive(Debug, Serialize)]
pub struct Summary {
    /// The pipeline file.
    pub config: String,
    /// The sweep.
    pub sweep: SweepReport,
    /// Sizes of the emulator sets.
    pub split: Split,
    /// Emulator accuracy.
    pub emulators: Vec<EmulatorReport>,
    /// Screening.
    pub screening: ScreeningSummary,
    /// Posterior per parameter.
    pub posterior: Vec<ParameterRow>,
    /// Predicted against measured.
    pub predictive: Vec<PredictiveRow>,
    /// Winner per criterion.
    pub selected: BTreeMap<String, String>,
    /// Wall time per stage.
    pub stages: Vec<StageTime>,
}

fn emulator_table(s: &Summary) -> String {
    let mut t = format!(
        "\nEmulators ({} train / {} validation / {} test runs)\n{:<8} {:<9} {:>10} {:>8} {:>8} {:>9} {:>9}\n",
        s.split.train, s.split.validation, s.split.test, "output", "kernel", "RMSE", "R2", "NLPD", "cover95", "accuracy"
    );
    for e in &s.emulators {
        t += &format!(
            "{:<8} {:<9} {:>10.2e} {:>8.4} {:>8.2} {:>9.3} {:>8.1}%\n",
            e.output,
            e.kernel,
            e.test.rmse,
            e.test.r2,
            e.test.nlpd,
            e.test.coverage95,
            e.test_accuracy_percent
        );
    }
    t
}

fn posterior_table(s: &Summary) -> String {
    let mut t = format!(
        "\nPosterior (dropped: {})\n{:<14} {:>12} {:>12} {:>12} {:>12} {:>12} {:>8}\n",
        if s.screening.drop.is_empty() { "none".into() } else { s.screening.drop.join(", ") },
        "parameter",
        "prior low",
        "prior high",
        "mean",
        "sd",
        "q05..q95",
        "sd/prior"
    );
    for r in &s.posterior {
        let p = &r.posterior;
        t += &format!(
            "{:<14} {:>12.5} {:>12.5} {:>12.5} {:>12.4e} {:>5.4e}..{:.4e} {:>8.3}\n",
            r.name, r.prior[0], r.prior[1], p.mean, p.sd, p.q05, p.q95, r.sd_ratio
        );
    }
    t += &format!(
        "\n{:<8} {:>9} {:>8} {:>10} {:>16} {:>12} {:>10}\n",
        "output", "measured", "sd", "model", "model 5..95 %", "discrepancy", "corrected"
    );
    for p in &s.predictive {
        t += &format!(
            "{:<8} {:>9.4} {:>8.4} {:>10.4} {:>7.4}..{:<7.4} {:>12.4} {:>10.4}\n",
            p.output,
            p.measured,
            p.sd,
            p.simulator[0],
            p.simulator[1],
            p.simulator[2],
            p.discrepancy,
            p.corrected
        );
    }
    t
}

fn criteria_table(table: &SelectionTable) -> String {
    let mut t = format!(
        "\nModel selection\n{:<12} {:>3} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12}\n",
        "candidate", "k", "-log L", "AIC", "BIC", "DIC", "ICOMP", "MDL"
    );
    for c in &table.candidates {
        t += &format!(
            "{:<12} {:>3} {:>12.3} {:>12.3} {:>12.3} {:>12.3} {:>12.3} {:>12.3}{}\n",
            c.name,
            c.free_parameters.len(),
            c.neg_log_likelihood,
            c.aic,
            c.bic,
            c.dic,
            c.icomp,
            c.mdl,
            if c.identifiable { "" } else { "  (k > observations: not identifiable)" }
        );
    }
    let sel: Vec<String> = table.selected.iter().map(|(k, v)| format!("{k}: {v}")).collect();
    t + &format!("selected: {}\n", sel.join(", "))
}

/// The closing report on stdout.
pub fn text(s: &Summary, table: &SelectionTable) -> String {
    let stages: Vec<String> =
        s.stages.iter().map(|t| format!("{} {:.1} s", t.stage, t.wall_s)).collect();
    emulator_table(s)
        + &posterior_table(s)
        + &criteria_table(table)
        + &format!("\ntime: {}\n", stages.join(", "))
}
