//! `report.html` of a diagnosis: the linear fit of the specimen
//! ([`super::report_linear`]), the verdict, the specimen, the symptoms
//! (table and plots, [`super::report_symptoms`]), the model comparison (MDL
//! table and chart), the chosen model's calibrated parameters and posterior
//! ([`super::report_posterior`]), and measured
//! vs baseline vs extended histories at the sensors where the two models
//! differ most.

use super::cause::Cause;
use super::damping_form::FORM_NATS;
use super::evidence::Evidence;
use super::fit::{pre_event_offset, Simulated, DAMPING_MASS_SHARE};
use super::pipeline::{
    CandidateResult, Diagnosis, VerdictRule, LINEAR_PART_NATS, MISFIT_NATS, TIE_NATS,
};
use super::report_evidence::evidence_section;
use super::report_linear::linear_section;
use super::report_posterior::posterior_section;
use super::report_symptoms::symptoms_section;
use super::resample::Decimated;
use super::symptoms::{half_cycle_peaks, rms};
use super::unexplained::{Unexplained, EXPLAINED_ERROR};
use super::verdict::UNEXPLAINED;
use super::verdict_notes::{reach_note, unexercised_note, unexplained_note};
use crate::bundle::{Bundle, RunData, SensorKind};
use crate::report::{
    bar_chart, line_plot, plan_svg, BarChart, BarGroup, Block, LinePlot, NoteKind, Page,
    PlanSensor, PlotSize, Section, Series, SeriesStyle, Table,
};

/// A number for the page: four decimals, or – when not finite.
pub(super) fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4}")
    } else {
        "–".into()
    }
}

/// The report page as HTML, with the symptoms `e` of the diagnosis
/// ([`super::evidence::evidence`]).
pub fn render(b: &Bundle, d: &Diagnosis, e: &Evidence, resampled: &[Decimated]) -> String {
    let telling = telling_channels(b, d);
    let cause = if d.unexplained.is_some() { UNEXPLAINED } else { d.cause.as_str() };
    // An unexplained verdict leads; otherwise the linear fit comes first.
    let (first, second) = if d.unexplained.is_some() {
        (verdict_section(b, d), linear_section(b, d))
    } else {
        (linear_section(b, d), verdict_section(b, d))
    };
    let page = Page {
        title: format!("Diagnosis of {}", b.manifest.name),
        subtitle: format!(
            "cause: {cause} · gain on the validation runs {:.3} · {} FE parameter points",
            d.gain, d.fe_points
        ),
        sections: vec![
            first,
            second,
            specimen_section(b, &telling, resampled),
            symptoms_section(e),
            comparison_section(d),
        ]
        .into_iter()
        .chain(evidence_section(d))
        .chain([parameters_section(d), posterior_section(d), histories_section(b, d, &telling)])
        .collect(),
    };
    page.to_html()
}

fn verdict_section(b: &Bundle, d: &Diagnosis) -> Section {
    let chosen = d.candidates.iter().find(|c| c.selected);
    let mut blocks: Vec<Block> = d.unexplained.iter().map(unexplained_block).collect();
    blocks.push(Block::KeyValues(vec![
        ("cause".into(), d.cause.as_str().into()),
        ("what it means".into(), d.cause.explain().into()),
        ("baseline validation error".into(), num(d.baseline_validation_error)),
        ("extended validation error".into(), num(d.extended_validation_error)),
        ("gain (1 − extended / baseline)".into(), num(d.gain)),
    ]));
    if let Some(c) = chosen {
        let rule = match d.rule {
            VerdictRule::Mdl => format!(
                "scored by its minimum description length; {} is chosen ({:.1} nats). The lowest \
                 MDL is chosen, where an extension must beat the baseline by {MISFIT_NATS} nats",
                c.cause.as_str(),
                c.mdl.as_ref().map_or(f64::NAN, |m| m.total),
            ),
            VerdictRule::Evidence => format!(
                "scored by its evidence p(data | class) (section \"Model classes: evidence\"); \
                 {} is chosen, the class of highest posterior probability under equal prior odds",
                c.cause.as_str(),
            ),
        };
        blocks.push(Block::Paragraph(format!(
            "Every candidate model was calibrated on the calibration runs and {rule}; the \
             validation runs measure the verdict and never choose it. Validation errors are \
             the mean over the sensors of the validation runs of the normalised RMS error in \
             excess of the sensor noise, √max(MSE − σ², 0) / √(MS − σ²) (MSE of simulated − \
             measured, MS of measured), 0 for a model that misses by the noise alone, each \
             sensor weighted by the share of its measured power that is signal, (MS − σ²)/MS; each \
             sensor's constant offset is fitted to each model's prediction (least squares) and \
             σ² per sensor is the nugget of the residual's variogram, the smallest over the \
             candidate models. Raw NRMSE (noise included): baseline {}, extended {}.",
            num(d.candidates[0].validation_nrmse),
            num(c.validation_nrmse),
        )));
    }
    blocks.extend(unexercised_note(d));
    blocks.extend(reach_note(b, d));
    blocks.extend(unexplained_note(d));
    if d.calibration_runs == d.validation_runs {
        blocks.push(Block::Note {
            kind: NoteKind::Warning,
            text: "The bundle has a single usable split: validation reuses the calibration runs."
                .into(),
        });
    }
    Section { id: "verdict".into(), heading: "Verdict".into(), blocks }
}

/// The warning that leads an unexplained verdict: what is missed, by how much.
fn unexplained_block(u: &Unexplained) -> Block {
    Block::Note {
        kind: NoteKind::Warning,
        text: format!(
            "Unexplained: the data show something no model here explains, or the evidence \
             cannot say which does. The model the verdict rule ranked first is reported below, \
             but a model explains a channel only when it misses it by at most {:.0} % of the \
             signal beyond the noise, and here: {}.",
            100.0 * EXPLAINED_ERROR,
            u.lines().join("; ")
        ),
    }
}

fn specimen_section(b: &Bundle, telling: &[(usize, String)], resampled: &[Decimated]) -> Section {
    let s = &b.manifest.structure;
    let sensors: Vec<PlanSensor> = b
        .manifest
        .sensors
        .iter()
        .map(|x| PlanSensor {
            id: x.id.clone(),
            x_m: x.x_m,
            y_m: x.y_m,
            direction: match x.direction {
                crate::bundle::Direction::X => crate::report::Direction::X,
                crate::bundle::Direction::Y => crate::report::Direction::Y,
            },
            kind: match x.kind {
                SensorKind::Acceleration => crate::report::SensorKind::Acceleration,
                SensorKind::Displacement => crate::report::SensorKind::Displacement,
            },
            highlight: telling.iter().any(|(_, id)| *id == x.id),
        })
        .collect();
    let plan = plan_svg(s.length_x_m, s.length_y_m, s.module_m, s.main_tee_spacing_m, &sensors);
    Section {
        id: "specimen".into(),
        heading: "Specimen".into(),
        blocks: vec![
            Block::KeyValues(vec![
                ("plan".into(), format!("{} m × {} m", s.length_x_m, s.length_y_m)),
                (
                    "module / main-tee spacing".into(),
                    format!("{} m / {} m", s.module_m, s.main_tee_spacing_m),
                ),
                (
                    "hangers".into(),
                    format!("{} m long every {} m", s.hanger_length_m, s.hanger_spacing_m),
                ),
                ("panel mass".into(), format!("{} kg", s.panel_mass_kg)),
                (
                    "perimeter".into(),
                    match s.nominal_gap_mm {
                        Some(g) => format!("{}, nominal gap {g} mm", s.boundary.as_str()),
                        None => s.boundary.as_str().to_string(),
                    },
                ),
                ("runs".into(), run_rates(b, resampled)),
            ]),
            Block::figure("Plan with the sensors; highlighted: the sensors shown below.", plan),
        ],
    }
}

/// Each run's id and sampling rate; a run recorded faster than the
/// simulation's rate shows both ("1000 Hz, simulated at 200 Hz").
fn run_rates(b: &Bundle, resampled: &[Decimated]) -> String {
    let rate = |r: &crate::bundle::RunData| match resampled.iter().find(|x| x.run == r.id) {
        Some(x) => format!("{} ({:.0} Hz, simulated at {:.0} Hz)", r.id, x.from_hz, x.to_hz),
        None => format!("{} ({:.0} Hz)", r.id, 1.0 / r.dt_s),
    };
    b.runs.iter().map(rate).collect::<Vec<_>>().join(", ")
}

/// The model comparison: the MDL table, the error chart and the notes on the choice.
fn comparison_section(d: &Diagnosis) -> Section {
    let rows = comparison_rows(d);
    let highlight = d.candidates.iter().position(|c| c.selected);
    let chart = error_chart(d, highlight);
    Section {
        id: "models".into(),
        heading: "Model comparison (MDL)".into(),
        blocks: vec![
            Block::Table(mdl_table(rows, highlight)),
            Block::figure(
                "Errors of each calibrated model on the calibration and validation runs.",
                chart,
            ),
        ]
        .into_iter()
        .chain(channels_note(d))
        .chain(linear_part_notes(d))
        .chain(misfit_note(d))
        .collect(),
    }
}

/// One row per candidate: its MDL terms and ΔMDL (nats), its errors and its FE points.
fn comparison_rows(d: &Diagnosis) -> Vec<Vec<String>> {
    let best = d
        .candidates
        .iter()
        .filter_map(|c| c.mdl.as_ref().map(|m| m.total))
        .fold(f64::INFINITY, f64::min);
    d.candidates
        .iter()
        .map(|c| {
            let m = c.mdl.as_ref();
            vec![
                c.cause.as_str().into(),
                c.k.to_string(),
                m.map_or("–".into(), |m| format!("{:.1}", m.fit)),
                m.map_or("–".into(), |m| format!("{:.1}", m.parametric)),
                m.map_or("–".into(), |m| format!("{:.1}", m.geometric)),
                m.map_or("–".into(), |m| format!("{:.1}", m.total)),
                m.map_or("–".into(), |m| format!("{:.1}", m.total - best)),
                num(c.calibration_error),
                num(c.validation_nrmse),
                num(c.validation_error),
                format!("{} ({} failed)", c.fe_points, c.failed_points),
            ]
        })
        .collect()
}

/// The MDL table of [`comparison_rows`], the chosen model's row highlighted.
fn mdl_table(rows: Vec<Vec<String>>, highlight: Option<usize>) -> Table {
    Table {
        caption: "MDL = −log f(x|θ̂) + k/2 log(N/2π) + log ∫√det I(θ) dθ (nats); lowest wins."
            .into(),
        header: [
            "model",
            "k",
            "−log f",
            "k/2 log(N/2π)",
            "geometric",
            "MDL",
            "ΔMDL",
            "cal. NRMSE",
            "val. NRMSE",
            "val. error over noise",
            "FE points",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        highlight_row: highlight,
    }
}

/// Bar chart of each candidate's calibration and validation errors (SVG).
fn error_chart(
    d: &Diagnosis,
    highlight: Option<usize>,
) -> Result<String, crate::report::ReportError> {
    bar_chart(&BarChart {
        title: "Normalised error by model".into(),
        x_label: "model".into(),
        y_label: "mean normalised RMS error (-)".into(),
        categories: d.candidates.iter().map(|c| c.cause.as_str().into()).collect(),
        groups: vec![
            BarGroup {
                name: "calibration runs, NRMSE".into(),
                values: d.candidates.iter().map(|c| c.calibration_error).collect(),
            },
            BarGroup {
                name: "validation runs, NRMSE".into(),
                values: d.candidates.iter().map(|c| c.validation_nrmse).collect(),
            },
            BarGroup {
                name: "validation runs, over noise".into(),
                values: d.candidates.iter().map(|c| c.validation_error).collect(),
            },
        ],
        highlight,
        size: PlotSize::default(),
    })
}

/// On a double-layer ceiling, a note on whether the baseline calibrates the
/// carrying channels (their mass and beams), with the MDL of both forms.
fn channels_note(d: &Diagnosis) -> Option<Block> {
    let f = d.channels?;
    let choice = if f.calibrated {
        "it is lower with the channels calibrated, so every model carries them"
    } else {
        "the channels do not earn their parameters, so no model carries them"
    };
    Some(Block::Note {
        kind: NoteKind::Info,
        text: format!(
            "A double-layer ceiling has carrying channels above the grid. The baseline's MDL is \
             {:.1} nats without them and {:.1} with them (their mass in kg/m along x, lumped at \
             the rod nodes, and their beams between the rod nodes as a fraction of the seed's \
             U50x15x1; {} FE points spent on the form not kept): {choice}.",
            f.mdl_without, f.mdl_with, f.fe_points_other
        ),
    })
}

/// A note per extension with a linear part: its MDL, and whether the
/// extension beat it (else it was out of the running).
fn linear_part_notes(d: &Diagnosis) -> Vec<Block> {
    d.candidates
        .iter()
        .filter_map(|c| Some((c, c.linear_part_mdl?, c.mdl.as_ref()?.total)))
        .map(|(c, linear, total)| {
            let verdict = if total <= linear - LINEAR_PART_NATS {
                "it beats that by more than ln 100 nats, so the nonlinearity earns its place"
            } else {
                "it does not beat that by ln 100 nats, so its gain is a linear change of the \
                 model, not its physics, and it is out of the running"
            };
            Block::Note {
                kind: NoteKind::Info,
                text: format!(
                    "{}'s linear part (its onset out of reach, only the parameters that act \
                     before it free) has MDL {linear:.1}, against {total:.1} for the extension: \
                     {verdict}.",
                    c.cause.as_str()
                ),
            }
        })
        .collect()
}

/// A note when the baseline is kept although an extension's MDL is lower,
/// by less than [`MISFIT_NATS`].
fn misfit_note(d: &Diagnosis) -> Option<Block> {
    let base = d.candidates.first()?.mdl.as_ref()?.total;
    if d.cause != Cause::NONE {
        return None;
    }
    let (c, total) = d
        .candidates
        .iter()
        .filter(|c| c.cause != Cause::NONE)
        .filter_map(|c| Some((c, c.contending_mdl()?)))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    (base - total > TIE_NATS).then(|| Block::Note {
        kind: NoteKind::Info,
        text: format!(
            "{}'s MDL is {:.1} nats below the baseline's, less than the {MISFIT_NATS} nats an \
             extension must win by: a baseline that only approximates the specimen leaves a \
             misfit that any extension's extra freedom takes a few tens of nats from, so the \
             baseline is kept.",
            c.cause.as_str(),
            base - total
        ),
    })
}

fn parameters_section(d: &Diagnosis) -> Section {
    let c = d.candidates.iter().find(|c| c.selected).unwrap_or(&d.candidates[0]);
    let rows = c
        .estimates
        .iter()
        .map(|e| {
            vec![
                e.name.clone(),
                e.unit.clone(),
                format!("{:.4}", e.value),
                format!("{:.4} – {:.4}", e.interval.0, e.interval.1),
            ]
        })
        .collect();
    let mut blocks = vec![Block::Table(Table {
        caption: "Best FE-evaluated point; interval: ±1 sd of the Laplace approximation (Gauss–Newton matrix at the estimate), in prior coordinates.".into(),
        header: ["parameter", "unit", "estimate", "≈68 % interval"].map(String::from).to_vec(),
        rows,
        highlight_row: None,
    })];
    blocks.extend(modal_table(&d.candidates[0], c));
    if c.committed_share > 0.0 {
        blocks.push(Block::Note {
            kind: NoteKind::Info,
            text: format!(
                "Damped on the committed tangent: {}'s springs carry Rayleigh's stiffness term \
                 on their last committed tangent rather than their initial stiffness, which \
                 fitted the calibration runs better by more than {FORM_NATS} nats.",
                c.cause.as_str()
            ),
        });
    }
    if let Some(share) = c.estimates.iter().find(|e| e.name == DAMPING_MASS_SHARE) {
        blocks.push(Block::Note {
            kind: NoteKind::Info,
            text: format!(
                "Damping split freed: Rayleigh's mass term carries a share {:.2} of the damping \
                 (0.5: the seed's pair on the first x and y modes), which fitted the \
                 calibration runs better by more than {FORM_NATS} nats. It stands for the \
                 damping's form over frequency, not a measurement of it.",
                share.value
            ),
        });
    }
    Section {
        id: "parameters".into(),
        heading: format!("Calibrated parameters of {}", c.cause.as_str()),
        blocks,
    }
}

/// The identified frequencies against the baseline's and the chosen
/// model's at their estimates (None without `modal.csv`).
fn modal_table(base: &CandidateResult, chosen: &CandidateResult) -> Option<Block> {
    let m = chosen.modal.as_ref()?;
    let b = base.modal.as_ref().filter(|b| b.modes == m.modes);
    let sd = |v: f64| if v > 0.0 { format!(" ± {:.3}", v.sqrt()) } else { String::new() };
    let rows = (0..m.modes.len())
        .map(|i| {
            let mut row = vec![
                m.modes[i].to_string(),
                format!("{:.3}{}", m.measured_hz[i], sd(m.lab_var_hz2[i])),
            ];
            if chosen.cause != base.cause {
                row.push(b.map_or("–".into(), |b| format!("{:.3}", b.model_hz[i])));
            }
            row.push(format!("{:.3}", m.model_hz[i]));
            row
        })
        .collect();
    let mut header = vec!["mode".to_string(), "measured (Hz)".into()];
    if chosen.cause != base.cause {
        header.push("baseline (Hz)".into());
    }
    header.push(format!("{} (Hz)", chosen.cause.as_str()));
    Some(Block::Table(Table {
        caption: format!(
            "Identified frequencies (modal.csv, ± the lab's one sigma) and the models' at their \
             estimates, which were calibrated on them too. Model discrepancy sd of {}: {:.3} Hz \
             (estimated; 0 when the frequencies lie within the lab's uncertainty).",
            chosen.cause.as_str(),
            m.discrepancy_var_hz2.sqrt()
        ),
        header,
        rows,
        highlight_row: None,
    }))
}

/// Per validation run, up to two sensors in the shaken direction (the most
/// telling acceleration and displacement) where the chosen model improves
/// most on the baseline (all channels when no extension was chosen).
fn telling_channels(b: &Bundle, d: &Diagnosis) -> Vec<(usize, String)> {
    let base = &d.candidates[0];
    let chosen = d.candidates.iter().find(|c| c.selected).unwrap_or(base);
    let mut out = Vec::new();
    for (k, &run) in d.validation_runs.iter().enumerate() {
        let data = &b.runs[run];
        let (Some(sb), Some(sc)) = (base.validation_sims.get(k), chosen.validation_sims.get(k))
        else {
            continue;
        };
        for kind in [SensorKind::Acceleration, SensorKind::Displacement] {
            let mut best: Option<(f64, String)> = None;
            for ((id, xb), (_, xc)) in sb.iter().zip(sc) {
                let Some(sensor) = b.manifest.sensors.iter().find(|s| &s.id == id) else {
                    continue;
                };
                let shaken = match sensor.direction {
                    crate::bundle::Direction::X => data.input_x_m_s2.is_some(),
                    crate::bundle::Direction::Y => data.input_y_m_s2.is_some(),
                };
                let Some(m) = data.sensor(id) else { continue };
                if sensor.kind != kind || !shaken {
                    continue;
                }
                let off = pre_event_offset(m, data.dt_s);
                let err = |x: &[f64]| {
                    let r: Vec<f64> = x.iter().zip(m).map(|(a, b)| a - (b - off)).collect();
                    rms(&r)
                };
                let score = (err(xb) - err(xc)) / rms(m).max(1e-300) + rms(m) * 1e-9;
                if best.as_ref().is_none_or(|(s, _)| score > *s) {
                    best = Some((score, id.clone()));
                }
            }
            if let Some((_, id)) = best {
                out.push((run, id));
            }
        }
    }
    out
}

/// Measured vs baseline vs extended histories at the telling sensors.
fn histories_section(b: &Bundle, d: &Diagnosis, telling: &[(usize, String)]) -> Section {
    let base = &d.candidates[0];
    let chosen = d.candidates.iter().find(|c| c.selected).unwrap_or(base);
    let mut blocks = Vec::new();
    for (run, id) in telling {
        blocks.extend(history_blocks(b, d, base, chosen, *run, id));
    }
    if blocks.is_empty() {
        blocks.push(Block::Note {
            kind: NoteKind::Info,
            text: "No validation histories to show.".into(),
        });
    }
    Section {
        id: "histories".into(),
        heading: "Time histories at the telling sensors".into(),
        blocks,
    }
}

/// The plot, the zoom on the measured peak and the peaks and RMS of validation
/// run `run` at sensor `id`; nothing if the run did not record the sensor.
fn history_blocks(
    b: &Bundle,
    d: &Diagnosis,
    base: &CandidateResult,
    chosen: &CandidateResult,
    run: usize,
    id: &str,
) -> Vec<Block> {
    let k = d.validation_runs.iter().position(|r| *r == run).unwrap_or(0);
    let data = &b.runs[run];
    let Some(meas) = data.sensor(id) else { return vec![] };
    let unit = history_unit(b, id);
    let series = history_series(data, meas, k, id, base, chosen);
    let stats = peak_rms_stats(&series);
    let plot = line_plot(&LinePlot {
        title: format!("run {}, sensor {id}", data.id),
        x_label: "time (s)".into(),
        y_label: unit.into(),
        series: series.clone(),
        log_x: false,
        log_y: false,
        size: PlotSize::default(),
    });
    let mut blocks = vec![Block::figure(
        &format!("Validation run {}, sensor {id}: measured vs models.", data.id),
        plot,
    )];
    if let Some(zoom) = zoomed(
        &series,
        data.dt_s,
        &format!("run {}, sensor {id}, around the measured peak", data.id),
        unit,
    ) {
        blocks
            .push(Block::figure(&format!("The same, 3 s around the measured peak of {id}."), zoom));
    }
    blocks.push(Block::Paragraph(stats));
    blocks
}

/// The y-axis label of sensor `id`'s histories: displacement or acceleration.
fn history_unit(b: &Bundle, id: &str) -> &'static str {
    let sensor = b.manifest.sensors.iter().find(|s| s.id == id);
    match sensor.map(|s| s.kind) {
        Some(SensorKind::Displacement) => "displacement (mm)",
        _ => "acceleration (m/s²)",
    }
}

/// The measured history `meas` (offset-corrected) of validation run number
/// `k`, then the baseline's and, if an extension was chosen, its simulation.
fn history_series(
    data: &RunData,
    meas: &[f64],
    k: usize,
    id: &str,
    base: &CandidateResult,
    chosen: &CandidateResult,
) -> Vec<Series> {
    let off = pre_event_offset(meas, data.dt_s);
    let t: Vec<f64> = (0..meas.len()).map(|i| data.t0_s + i as f64 * data.dt_s).collect();
    let pick = |sims: &[Simulated]| {
        sims.get(k).and_then(|s| s.iter().find(|(s, _)| s == id)).map(|(_, v)| v.clone())
    };
    let mut series = vec![Series {
        name: "measured".into(),
        x: t.clone(),
        y: meas.iter().map(|v| v - off).collect(),
        style: SeriesStyle::Solid,
    }];
    if let Some(v) = pick(&base.validation_sims) {
        series.push(Series {
            name: "baseline".into(),
            x: t.clone(),
            y: v,
            style: SeriesStyle::Dashed,
        });
    }
    if chosen.cause != base.cause {
        if let Some(v) = pick(&chosen.validation_sims) {
            series.push(Series {
                name: format!("extended ({})", chosen.cause.as_str()),
                x: t.clone(),
                y: v,
                style: SeriesStyle::Solid,
            });
        }
    }
    series
}

/// Each series' largest half-cycle peak and RMS, joined by "; ".
fn peak_rms_stats(series: &[Series]) -> String {
    let peaks = |y: &[f64]| half_cycle_peaks(y).into_iter().fold(0.0f64, f64::max);
    let stats: Vec<String> = series
        .iter()
        .map(|s| format!("{} peak {:.3}, RMS {:.3}", s.name, peaks(&s.y), rms(&s.y)))
        .collect();
    stats.join("; ")
}

/// The series cut to 3 s around the first series' largest |value|.
fn zoomed(
    series: &[Series],
    dt_s: f64,
    title: &str,
    unit: &str,
) -> Option<Result<String, crate::report::ReportError>> {
    let first = series.first()?;
    let k = (0..first.y.len())
        .filter(|i| first.y[*i].is_finite())
        .max_by(|a, b| first.y[*a].abs().total_cmp(&first.y[*b].abs()))?;
    let half = (1.5 / dt_s) as usize;
    let (lo, hi) = (k.saturating_sub(half), (k + half).min(first.y.len()));
    let cut: Vec<Series> = series
        .iter()
        .map(|s| Series {
            name: s.name.clone(),
            x: s.x[lo..hi].to_vec(),
            y: s.y[lo..hi].to_vec(),
            style: s.style,
        })
        .collect();
    Some(line_plot(&LinePlot {
        title: title.into(),
        x_label: "time (s)".into(),
        y_label: unit.into(),
        series: cut,
        log_x: false,
        log_y: false,
        size: PlotSize::default(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::reach::validation_reach;
    use crate::diagnose::testkit::pounding_diagnosis;
    use crate::diagnose::verdict_notes::REACH_NOTE;

    #[test]
    fn a_baseline_kept_against_a_lower_mdl_says_why() {
        let (_, mut d) = pounding_diagnosis(false, true);
        let mdl = |total| crate::diagnose::testkit::mdl_of(total, 2);
        d.candidates[0].mdl = Some(mdl(-100.0));
        d.candidates[1].mdl = Some(mdl(-130.0));
        let text = match misfit_note(&d) {
            Some(Block::Note { kind: NoteKind::Info, text }) => text,
            other => panic!("{other:?}"),
        };
        assert!(text.starts_with("perimeter-pounding's MDL is 30.0 nats below"), "{text}");
        d.candidates[1].mdl = Some(mdl(-100.5));
        assert!(misfit_note(&d).is_none(), "a tie needs no word");
        d.cause = Cause::PERIMETER_POUNDING;
        d.candidates[1].mdl = Some(mdl(-300.0));
        assert!(misfit_note(&d).is_none(), "an extension named");
    }

    #[test]
    fn a_freed_damping_split_is_said_with_its_share() {
        let (_, mut d) = pounding_diagnosis(true, true);
        let notes = |d: &Diagnosis| -> Vec<String> {
            parameters_section(d)
                .blocks
                .into_iter()
                .filter_map(|bl| match bl {
                    Block::Note { text, .. } => Some(text),
                    _ => None,
                })
                .collect()
        };
        assert!(!notes(&d).iter().any(|t| t.contains("Damping split")));
        let named = d.candidates.iter_mut().find(|c| c.selected).unwrap();
        named.estimates.push(crate::diagnose::pipeline::Estimate {
            name: DAMPING_MASS_SHARE.into(),
            unit: "-".into(),
            value: 0.62,
            sd_unit: 0.01,
            interval: (0.61, 0.63),
        });
        let text = notes(&d).into_iter().find(|t| t.contains("Damping split")).unwrap();
        assert!(text.contains("share 0.62"), "{text}");
    }

    #[test]
    fn the_verdict_says_when_validation_runs_go_beyond_the_calibration_runs() {
        // Without contact the validation run (band noise of rms 0.6) moves
        // the oscillator far beyond the weak calibration run (0.1).
        let (b, mut d) = pounding_diagnosis(false, true);
        d.calibration_runs = vec![0];
        let r = validation_reach(&b, &d.calibration_runs, &d.validation_runs).unwrap();
        assert!(r.ratio > REACH_NOTE, "{r:?}");
        let notes: Vec<String> = verdict_section(&b, &d)
            .blocks
            .into_iter()
            .filter_map(|bl| match bl {
                Block::Note { kind: NoteKind::Info, text } => Some(text),
                _ => None,
            })
            .collect();
        let beyond = format!("sensor {}'s peak in them is {:.2} times", r.sensor, r.ratio);
        assert!(notes.iter().any(|t| t.contains(&beyond)), "{notes:?}");
        // Validation inside the calibration range, or only somewhat beyond
        // it (0.6 against 0.3): no note.
        let mut inside = d.clone();
        inside.calibration_runs = vec![0, 1];
        let r = validation_reach(&b, &inside.calibration_runs, &inside.validation_runs).unwrap();
        assert!(r.ratio > 1.0 && r.ratio < REACH_NOTE, "{r:?}");
        let notes = verdict_section(&b, &inside).blocks;
        assert!(!notes.iter().any(|bl| matches!(bl, Block::Note { kind: NoteKind::Info, .. })));
    }
}
