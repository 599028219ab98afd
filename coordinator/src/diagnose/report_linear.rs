//! The report's first section: the linear stage's fit of the specimen's
//! linear form, before any effect is judged: the frequencies measured
//! against the fitted model's, the linear runs' transfer functions
//! measured vs model at their sensors, each channel's error, and the form
//! found ([`super::linear_stage`]).

use super::linear_stage::report::LinearJson;
use super::linear_stage::LinearStage;
use super::pipeline::Diagnosis;
use super::spectrum::transfer_h1;
use super::unexplained::{channel_misses, Where, EXPLAINED_ERROR};
use crate::bundle::{Bundle, Direction};
use crate::report::{
    line_plot, Block, LinePlot, NoteKind, PlotSize, Section, Series, SeriesStyle, Table,
};

/// Longest FFT segment of the transfer functions (samples): 2048 at
/// 200 Hz is 10 s, a 0.1 Hz resolution that separates close modes.
const SEGMENT: usize = 2048;
/// Transfer functions drawn per linear run.
const PLOTS_PER_RUN: usize = 2;

/// The linear stage's section (a note when the stage did not run).
pub fn linear_section(b: &Bundle, d: &Diagnosis) -> Section {
    let blocks = match &d.linear {
        Some(stage) => linear_blocks(b, stage),
        None => vec![Block::Note {
            kind: NoteKind::Info,
            text: "The linear stage did not run (a double-layer ceiling, or --no-linear-stage): \
                   every model kept the generator's linear form and calibrated the perimeter \
                   stiffness and the damping alone."
                .into(),
        }],
    };
    Section { id: "linear".into(), heading: "Linear fit of the specimen".into(), blocks }
}

fn linear_blocks(b: &Bundle, stage: &LinearStage) -> Vec<Block> {
    let ids: Vec<String> = b.manifest.runs.iter().map(|r| r.id.clone()).collect();
    let j = LinearJson::of(&ids, stage);
    let mut blocks = vec![Block::Paragraph(format!(
        "Before any effect is judged, the specimen's linear form was fitted to the weakest \
         calibration run in each shaken direction ({}) and to modal.csv, by modal superposition \
         ({} linear evaluations). Every model after this holds it; the baseline and each \
         extension calibrate the perimeter stiffness and the damping again within a factor \
         of two of it. Mean normalised error of the linear runs: {:.3}.",
        j.runs.join(", "),
        j.evaluations,
        j.nrmse
    ))];
    let misses = channel_misses(stage.channels(), None, Where::LinearRun);
    if !misses.is_empty() {
        let list: Vec<String> = misses
            .iter()
            .map(|m| format!("{} {} ({:.0} %)", m.run, m.sensor, 100.0 * m.excess_error))
            .collect();
        blocks.push(Block::Note {
            kind: NoteKind::Warning,
            text: format!(
                "The fitted linear form misses these channels of the linear runs by more than \
                 {:.0} % of their signal beyond the noise: {}. A sensor whose sign or gain is \
                 wrong, physics the linear form lacks, or a weakest run that is not linear; the \
                 verdict says whether the named model explains them.",
                100.0 * EXPLAINED_ERROR,
                list.join(", ")
            ),
        });
    }
    blocks.extend(frequency_table(&j));
    blocks.extend(transfer_plots(b, stage));
    blocks.push(Block::Table(Table {
        caption: "The linear form found; interval: ±1 sd of the Laplace approximation, clamped \
                  to the prior."
            .into(),
        header: ["parameter", "unit", "estimate", "≈68 % interval"].map(String::from).to_vec(),
        rows: j
            .parameters
            .iter()
            .map(|p| {
                vec![
                    p.name.clone(),
                    p.unit.clone(),
                    format!("{:.4}", p.value),
                    format!("{:.4} – {:.4}", p.interval[0], p.interval[1]),
                ]
            })
            .collect(),
        highlight_row: None,
    }));
    blocks.push(Block::Table(Table {
        caption: "Each linear run's channels at the fitted linear form.".into(),
        header: ["run", "sensor", "NRMSE"].map(String::from).to_vec(),
        rows: j
            .channels
            .iter()
            .map(|c| vec![c.run.clone(), c.sensor.clone(), format!("{:.3}", c.nrmse)])
            .collect(),
        highlight_row: None,
    }));
    blocks
}

/// Measured frequencies against the linear model's (None without modal.csv).
fn frequency_table(j: &LinearJson) -> Option<Block> {
    let f = j.frequencies.as_ref()?;
    let rows = (0..f.modes.len())
        .map(|i| {
            let sd =
                if f.std_hz[i] > 0.0 { format!(" ± {:.3}", f.std_hz[i]) } else { String::new() };
            let rel = 100.0 * (f.model_hz[i] - f.measured_hz[i]) / f.measured_hz[i];
            vec![
                f.modes[i].to_string(),
                format!("{:.3}{sd}", f.measured_hz[i]),
                format!("{:.3}", f.model_hz[i]),
                format!("{rel:+.1} %"),
            ]
        })
        .collect();
    Some(Block::Table(Table {
        caption: format!(
            "Identified frequencies (modal.csv) and the fitted linear model's sway modes (the \
             modes whose kinetic energy is mostly horizontal, numbered as a lab's horizontal \
             sensors number them), as the runs are integrated at {} ms (Newmark's average \
             acceleration turns a mode slightly slower than its eigenfrequency). Model \
             discrepancy sd: {:.3} Hz.",
            f.step_s * 1e3,
            f.discrepancy_sd_hz
        ),
        header: ["mode", "measured (Hz)", "linear model (Hz)", "difference"]
            .map(String::from)
            .to_vec(),
        rows,
        highlight_row: None,
    }))
}

/// |H(f)| of up to [`PLOTS_PER_RUN`] sensors of each linear run in its
/// shaken direction, measured and fitted.
fn transfer_plots(b: &Bundle, stage: &LinearStage) -> Vec<Block> {
    let mut out = Vec::new();
    for (&k, sim) in stage.runs.iter().zip(&stage.sims) {
        let run = &b.runs[k];
        let mut drawn = 0;
        for (id, model) in sim {
            let Some(sensor) = b.manifest.sensors.iter().find(|s| &s.id == id) else { continue };
            let input = match sensor.direction {
                Direction::X => run.input_x_m_s2.as_ref(),
                Direction::Y => run.input_y_m_s2.as_ref(),
            };
            let (Some(input), Some(meas)) = (input, run.sensor(id)) else { continue };
            if drawn >= PLOTS_PER_RUN {
                break;
            }
            let (Ok(tm), Ok(ts)) = (
                transfer_h1(input, meas, run.dt_s, SEGMENT),
                transfer_h1(input, model, run.dt_s, SEGMENT),
            ) else {
                continue;
            };
            let series = |name: &str, t: &super::spectrum::Transfer, style| Series {
                name: name.into(),
                x: t.freq_hz.clone(),
                y: t.gain.clone(),
                style,
            };
            let plot = line_plot(&LinePlot {
                title: format!("run {}, sensor {id}: |H(f)|", run.id),
                x_label: "frequency (Hz)".into(),
                y_label: "response / input".into(),
                series: vec![
                    series("measured", &tm, SeriesStyle::Solid),
                    series("linear model", &ts, SeriesStyle::Dashed),
                ],
                log_x: false,
                log_y: true,
                size: PlotSize::default(),
            });
            out.push(Block::figure(
                &format!(
                    "Transfer function of linear run {}, sensor {id}, measured and fitted \
                     (H1 estimate, Hann segments of {SEGMENT} samples).",
                    run.id
                ),
                plot,
            ));
            drawn += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::farm_executor_tests::tiny_bundle;
    use crate::diagnose::linear_stage::linear_at;
    use crate::diagnose::pipeline::split_runs;

    /// The section of a linear form: its parameters and channels (and the
    /// frequencies when the bundle has them), and a drawn transfer function
    /// of a sensor in the shaken direction (no plot fell back to a warning).
    #[test]
    fn the_linear_section_draws_the_fit() {
        let tmp = tempfile::tempdir().unwrap();
        let b = tiny_bundle(tmp.path());
        let (cal, _) = split_runs(&b);
        let stage = linear_at(&b, &cal, &[("K_friction".into(), 18.0)]).unwrap();
        let blocks = linear_blocks(&b, &stage);
        let figures = blocks.iter().filter(|b| matches!(b, Block::Figure(_))).count();
        assert!(figures >= 1, "no transfer function drawn");
        let warnings = blocks.iter().filter(|b| matches!(b, Block::Note { kind: NoteKind::Warning, text } if text.contains("not drawn")));
        assert_eq!(warnings.count(), 0);
        let tables = blocks.iter().filter(|b| matches!(b, Block::Table(_))).count();
        assert_eq!(tables, 2 + usize::from(b.modal.is_some()));
    }
}
