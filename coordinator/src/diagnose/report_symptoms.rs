//! The "Symptoms" section of `report.html`: the table of symptoms
//! (measured, baseline, extended, what a departure points to) and one plot
//! per symptom: apparent frequency against run amplitude, per-run bars of
//! each run-wise symptom, and the time-frequency maps of the residuals.

use super::evidence::{Evidence, Reading, ResidualMap, Symptom};
use crate::report::{
    bar_chart, heatmap, line_plot, BarChart, BarGroup, Block, Figure, Heatmap, LinePlot, NoteKind,
    PlotSize, Section, Series, SeriesStyle, Table,
};

/// Largest |level| the residual maps' colour scale spans (dB).
const MAP_LIMIT_DB: f64 = 40.0;

fn cell(r: &Reading) -> String {
    match r {
        Reading::Value(v) if v.abs() >= 1e-3 || *v == 0.0 => format!("{v:.4}"),
        Reading::Value(v) => format!("{v:.3e}"),
        Reading::NotComputable(why) => format!("not computable: {why}"),
        Reading::Reference => "reference".into(),
    }
}

/// A cell repeating its left neighbour's reason says so briefly.
fn same(r: &Reading) -> String {
    match r {
        Reading::NotComputable(_) => "not computable: the same".into(),
        other => cell(other),
    }
}

/// The section for evidence `e`.
pub fn symptoms_section(e: &Evidence) -> Section {
    let mut blocks = vec![Block::Paragraph(intro(e)), Block::Table(table(e))];
    blocks.push(Block::figure(
        "Apparent first frequency (peak of the H1 transfer from the table input to the \
         accelerometer, inside the band the input carries power in; a peak at the band's \
         edge is no resonance and is left out) against the run's peak input. A linear model \
         keeps it flat; softening (slip) lowers it with amplitude, contact raises it.",
        line_plot(&frequency_plot(e)),
    ));
    let mut grid = Vec::new();
    for s in e.symptoms.iter().filter(|s| !s.per_run.is_empty() && s.key != FREQ_KEY) {
        if s.per_run.iter().all(|(_, v)| v.iter().all(|x| !x.is_finite())) {
            blocks.push(Block::Note {
                kind: NoteKind::Info,
                text: format!("{}: no plot, not computable on any run.", s.name),
            });
            continue;
        }
        match bar_chart(&per_run_chart(e, s)) {
            Ok(svg) => grid.push(Figure {
                caption: format!("{} ({}) per simulated run.", s.name, s.unit),
                svg,
            }),
            Err(err) => blocks.push(Block::Note {
                kind: NoteKind::Warning,
                text: format!("{}: not drawn: {err}", s.name),
            }),
        }
    }
    if !grid.is_empty() {
        blocks.push(Block::FigureGrid(grid));
    }
    for m in &e.maps {
        blocks.push(Block::figure(
            &format!(
                "Time-frequency map of the {} residual (measured − simulated) at {}, run {}: \
                 short-time power (Hann segments) over the median cell of the measurement's \
                 own map, dB. Red: the model misses energy the measurement has there.",
                m.model, m.sensor, m.run
            ),
            heatmap(&map_plot(m)),
        ));
    }
    if e.maps.is_empty() {
        blocks.push(Block::Note {
            kind: NoteKind::Info,
            text: "No residual map: no simulated run with an accelerometer in the shaken \
                   direction long enough for a short-time spectrum."
                .into(),
        });
    }
    Section { id: "symptoms".into(), heading: "Symptoms".into(), blocks }
}

const FREQ_KEY: &str = "apparent_frequency_strong_over_weak";

fn intro(e: &Evidence) -> String {
    format!(
        "Each symptom is computed in the same way on the measurement, on the calibrated \
         baseline's simulation and on the extended model's ({}), in direction {} at \
         accelerometer {} and displacement sensor {}. Table values are those of run {} (the \
         simulated run with the largest peak input); the plots show every simulated run. \
         Missing readings are skipped; a symptom that cannot be computed says why. Not \
         shown: low post-slip frequencies (they need free-vibration tails).",
        e.extended_model,
        e.direction.as_str(),
        e.accel.as_deref().unwrap_or("(none)"),
        e.disp.as_deref().unwrap_or("(none)"),
        e.focus_run.as_deref().unwrap_or("(none)"),
    )
}

fn table(e: &Evidence) -> Table {
    let rows = e
        .symptoms
        .iter()
        .map(|s| {
            let mut row = vec![s.name.to_string(), s.unit.to_string()];
            let [m, b, x] = &s.readings;
            row.push(cell(m));
            row.push(if b == m { same(b) } else { cell(b) });
            row.push(if x == b { same(x) } else { cell(x) });
            row.push(s.points_to.to_string());
            row
        })
        .collect();
    Table {
        caption: "Symptoms: measured vs calibrated baseline vs extended model.".into(),
        header: vec![
            "symptom".into(),
            "unit".into(),
            "measured".into(),
            "baseline".into(),
            format!("extended ({})", e.extended_model),
            "what a departure from the baseline points to".into(),
        ],
        rows,
        highlight_row: None,
    }
}

fn frequency_plot(e: &Evidence) -> LinePlot {
    let names = [
        "measured".to_string(),
        "baseline".to_string(),
        format!("extended ({})", e.extended_model),
    ];
    let mut pts = e.frequency.clone();
    pts.sort_by(|a, b| a.amplitude_g.total_cmp(&b.amplitude_g));
    let series = (0..3)
        .map(|k| Series {
            name: names[k].clone(),
            x: pts.iter().map(|p| p.amplitude_g).collect(),
            y: pts.iter().map(|p| p.freq_hz[k]).collect(),
            style: SeriesStyle::Points,
        })
        .collect();
    LinePlot {
        title: "Apparent frequency vs run amplitude".into(),
        x_label: "peak input (g)".into(),
        y_label: "apparent frequency (Hz)".into(),
        series,
        log_x: pts.len() > 1 && pts[0].amplitude_g > 0.0,
        log_y: false,
        size: PlotSize::default(),
    }
}

fn per_run_chart(e: &Evidence, s: &Symptom) -> BarChart {
    let names = [
        "measured".to_string(),
        "baseline".to_string(),
        format!("extended ({})", e.extended_model),
    ];
    BarChart {
        title: s.short.to_string(),
        x_label: "run".into(),
        y_label: format!("{} ({})", s.short, s.unit),
        categories: s.per_run.iter().map(|(r, _)| r.clone()).collect(),
        groups: (0..3)
            .map(|k| BarGroup {
                name: names[k].clone(),
                values: s.per_run.iter().map(|(_, v)| v[k]).collect(),
            })
            .collect(),
        highlight: s.per_run.iter().position(|(r, _)| Some(r) == e.focus_run.as_ref()),
        size: PlotSize { width_px: 460, height_px: 300 },
    }
}

fn map_plot(m: &ResidualMap) -> Heatmap {
    let top =
        m.level_db.iter().flatten().filter(|v| v.is_finite()).fold(0.0f64, |a, v| a.max(v.abs()));
    Heatmap {
        title: format!("{} residual, {} run {}", m.model, m.sensor, m.run),
        x_label: "time (s)".into(),
        y_label: "frequency (Hz)".into(),
        z_label: "residual re median measured (dB)".into(),
        x: m.t_s.clone(),
        y: m.freq_hz.clone(),
        z: m.level_db.clone(),
        z_limit: Some(top.clamp(10.0, MAP_LIMIT_DB)),
        size: PlotSize::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::super::evidence::evidence;
    use super::super::report::render;
    use super::*;
    use crate::diagnose::testkit::pounding_diagnosis;

    /// The symptoms section's figures: the frequency plot, five per-run
    /// bar charts (half-power damping is not computable at 20 s), two maps.
    const SYMPTOM_FIGURES: usize = 8;

    #[test]
    fn the_report_of_a_pounding_campaign_shows_its_symptoms() {
        let (b, d) = pounding_diagnosis(true, true);
        let section = symptoms_section(&evidence(&b, &d));
        let figures: usize = section
            .blocks
            .iter()
            .map(|bl| match bl {
                Block::Figure(_) => 1,
                Block::FigureGrid(g) => g.len(),
                _ => 0,
            })
            .sum();
        assert_eq!(
            figures,
            SYMPTOM_FIGURES,
            "{:#?}",
            section.blocks.iter().filter(|b| matches!(b, Block::Note { .. })).collect::<Vec<_>>()
        );
        let Some(Block::Table(t)) = section.blocks.get(1) else { panic!("no table") };
        let spikes = t.rows.iter().find(|r| r[0].starts_with("high-frequency share")).unwrap();
        let num = |s: &str| s.parse::<f64>().unwrap();
        assert!(num(&spikes[2]) > 5.0 * num(&spikes[3]), "{spikes:?}");
        let html = render(&b, &d, &evidence(&b, &d), &[]);
        assert!(html.contains("id=\"symptoms\"") && html.contains("Symptoms"));
        assert!(!html.contains("not drawn") && !html.contains("is not shown"), "a plot failed");
        // The whole page for `scripts/check-report` (figure count printed).
        if let Some(dir) = std::env::var_os("CEILFARM_SYMPTOMS_REPORT") {
            std::fs::write(std::path::Path::new(&dir).join("report.html"), &html).unwrap();
            println!("figures on the page: {}", html.matches("<figure").count());
        }
    }

    #[test]
    fn a_reason_shared_by_all_columns_is_spelled_out_once() {
        let (b, d) = pounding_diagnosis(true, false);
        let section = symptoms_section(&evidence(&b, &d));
        let Some(Block::Table(t)) = section.blocks.get(1) else { panic!("no table") };
        let spikes = t.rows.iter().find(|r| r[0].starts_with("high-frequency share")).unwrap();
        assert!(spikes[2].starts_with("not computable: no displacement sensor"), "{spikes:?}");
        assert_eq!(spikes[3], "not computable: the same");
        assert_eq!(spikes[4], "not computable: the same");
    }
}
