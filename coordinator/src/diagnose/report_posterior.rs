//! The report's posterior section: the chosen variant's variational
//! posterior ([`super::posterior`]) as a table (mean, sd, central 95 %
//! interval beside the best FE-evaluated point) and one marginal histogram
//! per parameter.

use super::pipeline::Diagnosis;
use super::posterior::EmulatorCheck;
use super::verdict::POSTERIOR_METHOD;
use crate::report::{
    histogram, Block, Figure, Histogram, Marker, NoteKind, PlotSize, Section, Table,
};

/// The posterior of the selected candidate.
pub fn posterior_section(d: &Diagnosis) -> Section {
    let c = d.candidates.iter().find(|c| c.selected).unwrap_or(&d.candidates[0]);
    let heading = format!("Posterior of {}", c.cause.as_str());
    let mut blocks = vec![Block::Paragraph(format!("{POSTERIOR_METHOD}."))];
    match &c.posterior {
        None => blocks.push(note("No posterior was computed.".into())),
        Some(Err(why)) => blocks.push(note(format!("No posterior: {why}."))),
        Some(Ok(p)) => {
            let rows = (0..p.names.len())
                .map(|k| {
                    let best = c.estimates.get(k).map_or(f64::NAN, |e| e.value);
                    vec![
                        p.names[k].clone(),
                        p.units[k].clone(),
                        format!("{best:.4}"),
                        format!("{:.4}", p.mean[k]),
                        format!("{:.2e}", p.sd[k]),
                        format!("{:.4} – {:.4}", p.q025[k], p.q975[k]),
                    ]
                })
                .collect();
            blocks.push(Block::Table(Table {
                caption: format!(
                    "{} BBVI iterations ({}, last relative change of q {:.1e}); GP correction \
                     trained on {} FE evaluations.{}",
                    p.iterations,
                    if p.converged { "converged" } else { "iteration limit" },
                    p.rel_change,
                    p.emulator_points,
                    check_sentence(p.check)
                ),
                header: [
                    "parameter",
                    "unit",
                    "best FE point",
                    "posterior mean",
                    "sd",
                    "95 % interval",
                ]
                .map(String::from)
                .to_vec(),
                rows,
                highlight_row: None,
            }));
            blocks.push(Block::FigureGrid(marginals(p, c)));
        }
    }
    Section { id: "posterior".into(), heading, blocks }
}

fn note(text: String) -> Block {
    Block::Note { kind: NoteKind::Info, text }
}

/// One marginal histogram per parameter (plots that fail are left out of
/// the grid; the table above holds their numbers).
fn marginals(
    p: &super::posterior::VariationalPosterior,
    c: &super::pipeline::CandidateResult,
) -> Vec<Figure> {
    (0..p.names.len())
        .filter_map(|k| {
            let mut markers = vec![Marker { label: "posterior mean".into(), x: p.mean[k] }];
            if let Some(e) = c.estimates.get(k) {
                markers.push(Marker { label: "best FE point".into(), x: e.value });
            }
            let svg = histogram(&Histogram {
                title: p.names[k].clone(),
                x_label: format!("{} ({})", p.names[k], p.units[k]),
                samples: p.draws[k].clone(),
                bins: None,
                prior: None,
                markers,
                size: PlotSize { width_px: 320, height_px: 220 },
            })
            .ok()?;
            Some(Figure { caption: format!("Posterior marginal of {}.", p.names[k]), svg })
        })
        .collect()
}

/// What the FE checks of the emulator found, as a sentence.
fn check_sentence(check: Option<EmulatorCheck>) -> String {
    match check {
        None => String::new(),
        Some(c) if c.confirmed => format!(
            " The FE model at q's mean and draws ({} FE runs) agrees with the emulator within \
             {:.1} nats.",
            c.fe_points, c.gap_nats
        ),
        Some(c) => format!(
            " Not confirmed: after {} FE runs at q's mean and draws, the FE model still differs \
             from the emulator by {:.1} nats there; read these intervals as rough.",
            c.fe_points, c.gap_nats
        ),
    }
}
