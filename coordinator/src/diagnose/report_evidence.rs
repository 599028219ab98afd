//! The report's class-evidence section (`diagnose --evidence`): each
//! calibrated class's ln p(data | class) against the best, its error, its
//! posterior probability and how the estimate settled, as a table and a
//! bar chart of the log Bayes factors against the best class.

use super::class_evidence::ClassEvidence;
use super::class_odds::ClassOdds;
use super::likelihood::LikelihoodKind;
use super::pipeline::{Diagnosis, VerdictRule};
use super::verdict::EVIDENCE_METHOD;
use crate::report::{bar_chart, BarChart, BarGroup, Block, PlotSize, Section, Table};

/// The section, when any class's evidence was asked for.
pub fn evidence_section(d: &Diagnosis) -> Option<Section> {
    let odds: Vec<Option<&Result<ClassOdds, String>>> =
        d.candidates.iter().map(|c| c.odds.as_ref()).collect();
    if odds.iter().all(Option::is_none) {
        return None;
    }
    let best = (odds.iter().flatten().filter_map(|o| o.as_ref().ok()))
        .map(|o| o.evidence.ln_evidence)
        .fold(f64::NEG_INFINITY, f64::max);
    let rows =
        d.candidates.iter().zip(&odds).map(|(c, o)| row(c.cause.as_str(), *o, best)).collect();
    let factors: Vec<f64> = odds
        .iter()
        .map(|o| {
            o.and_then(|o| o.as_ref().ok()).map_or(f64::NAN, |o| o.evidence.ln_evidence - best)
        })
        .collect();
    let chart = bar_chart(&BarChart {
        title: "Evidence of each model class against the best".into(),
        x_label: "model class".into(),
        y_label: "ln Z − ln Z(best) (nats)".into(),
        categories: d.candidates.iter().map(|c| c.cause.as_str().into()).collect(),
        groups: vec![BarGroup { name: "ln Bayes factor".into(), values: factors }],
        highlight: d.candidates.iter().position(|c| c.selected),
        size: PlotSize::default(),
    });
    let blocks = vec![
        Block::Paragraph(format!(
            "{EVIDENCE_METHOD}. ln L: {}. {} {}",
            likelihood_words(&odds),
            prior_words(&odds),
            match d.rule {
                VerdictRule::Evidence => "The verdict above is the most probable class.",
                VerdictRule::Mdl => "The verdict above does not use them (the MDL rules name it).",
            }
        )),
        Block::Table(Table {
            caption: "ln Z relative to the best class (nats); sd its standard error; k̂ the Pareto \
                      shape of the last FE correction (above 0.7 with ratios that vary: not \
                      trusted)."
                .into(),
            header: [
                "class",
                "ln Z − best",
                "sd",
                "probability",
                "k̂",
                "settled",
                "Laplace − best",
                "FE points",
            ]
            .map(String::from)
            .to_vec(),
            rows,
            highlight_row: d.candidates.iter().position(|c| c.selected),
        }),
        Block::figure("Log Bayes factor of each class against the best.", chart),
    ];
    Some(Section { id: "evidence".into(), heading: "Model classes: evidence".into(), blocks })
}

/// How the classes' prior was set, in a sentence.
fn prior_words(odds: &[Option<&Result<ClassOdds, String>>]) -> String {
    let p = odds.iter().flatten().find_map(|o| o.as_ref().ok()).map_or(0.5, |o| o.effect_prior);
    if p == 0.5 {
        "Probabilities under equal prior odds.".into()
    } else {
        format!("Probabilities with each effect acting with prior probability {p}, independently.")
    }
}

/// What the classes' ln L is, in words.
fn likelihood_words(odds: &[Option<&Result<ClassOdds, String>>]) -> &'static str {
    let kind = odds.iter().flatten().find_map(|o| o.as_ref().ok()).map(|o| o.evidence.likelihood);
    match kind {
        Some(LikelihoodKind::Time) => {
            "the time-domain Gaussian under each channel's effective sample size (its nats grow \
             with the sampling rate)"
        }
        Some(LikelihoodKind::Band) => {
            "the Gaussian of the residuals within the model's band (to 40 Hz) under their in-band \
             degrees of freedom (its nats do not grow with the sampling rate)"
        }
        Some(LikelihoodKind::Whittle) => {
            "the Whittle likelihood of the residuals over the model's band (to 40 Hz), its level \
             profiled per 2 Hz sub-band (every bin alike: an out-of-phase impact costs as much as a \
             missed resonance)"
        }
        None => "none computed",
    }
}

/// Whether an evidence settled and how: by its rounds, by the annealing
/// (its stages), or not (its rounds, and the temperature the annealing
/// reached); after how many restarts of its calibration's search.
fn settled_words(e: &ClassEvidence) -> String {
    let how = match (&e.annealed, e.converged) {
        (None, true) => "yes".to_string(),
        (None, false) => format!("no ({} rounds)", e.rounds.len()),
        (Some(a), true) => format!("yes (annealed, {} stages)", a.stages),
        (Some(a), false) => match a.estimate {
            Some((_, sd)) => format!("no (annealed, error {sd:.2} nat)"),
            None => {
                let reached =
                    format!("no ({} rounds; annealing reached β = {:.3})", e.rounds.len(), a.beta);
                match (e.counted_ln_evidence(), e.ln_evidence_at_most()) {
                    (Some(z), Some(top)) => {
                        format!("{reached}: counted at ln Z ≥ {z:.1}, at most {top:.1}")
                    }
                    (Some(z), None) => format!("{reached}: counted at ln Z ≥ {z:.1}"),
                    (None, _) => reached,
                }
            }
        },
    };
    match e.restarts {
        0 => how,
        k => format!("{how}, after {k} restarts"),
    }
}

/// One table row.
fn row(cause: &str, o: Option<&Result<ClassOdds, String>>, best: f64) -> Vec<String> {
    let why = match o {
        Some(Ok(o)) => {
            let e = &o.evidence;
            let settled = settled_words(e);
            return vec![
                cause.into(),
                format!("{:.2}", e.ln_evidence - best),
                format!("{:.2}", e.ln_evidence_sd),
                format!("{:.3}", o.probability),
                format!("{:.2}", e.k_hat),
                settled,
                format!("{:.2}", e.laplace_ln_evidence - best),
                e.fe_points.to_string(),
            ];
        }
        Some(Err(why)) => format!("not computable: {why}"),
        None => "not computed".into(),
    };
    [cause.to_string(), why].into_iter().chain(std::iter::repeat_n("–".to_string(), 6)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::cause::Cause;
    use crate::diagnose::pipeline::CandidateResult;

    fn odds(ln_z: f64, p: f64) -> ClassOdds {
        let mut o = crate::diagnose::testkit::class_odds(ln_z, true);
        o.evidence.laplace_ln_evidence = ln_z - 0.2;
        o.evidence.fe_points = 80;
        ClassOdds { probability: p, ..o }
    }

    #[test]
    fn the_section_lists_each_class_against_the_best_and_is_absent_unasked() {
        let (_, mut d) = crate::diagnose::testkit::pounding_diagnosis(true, false);
        assert!(evidence_section(&d).is_none());
        d.candidates = vec![
            CandidateResult {
                odds: Some(Ok(odds(100.0, 0.0))),
                ..CandidateResult::unassessed(Cause::NONE, None)
            },
            CandidateResult {
                odds: Some(Ok(odds(130.0, 1.0))),
                ..CandidateResult::unassessed(Cause::PERIMETER_POUNDING, None)
            },
            CandidateResult {
                odds: Some(Err("no Gauss–Newton matrix".into())),
                ..CandidateResult::unassessed(Cause::PERIMETER_FRICTION, None)
            },
        ];
        let s = evidence_section(&d).expect("asked for");
        let Block::Table(t) = &s.blocks[1] else { panic!("{:?}", s.blocks[1]) };
        assert_eq!(t.rows[0][1], "-30.00");
        assert_eq!(t.rows[1][1], "0.00");
        assert_eq!(t.rows[1][3], "1.000");
        assert!(t.rows[2][1].contains("no Gauss–Newton matrix"), "{:?}", t.rows[2]);
        assert!(t.rows.iter().all(|r| r.len() == t.header.len()));
    }

    #[test]
    fn the_settled_column_says_how_and_after_how_many_restarts() {
        use crate::diagnose::class_evidence::Annealed;
        let mut e = odds(1.0, 1.0).evidence;
        assert_eq!(settled_words(&e), "yes");
        e.converged = false;
        assert_eq!(settled_words(&e), "no (0 rounds)");
        let a = Annealed {
            estimate: None,
            stages: 8,
            fe_points: 600,
            beta: 0.0625,
            lower: None,
            upper: None,
        };
        e.annealed = Some(a.clone());
        e.restarts = 4;
        assert_eq!(
            settled_words(&e),
            "no (0 rounds; annealing reached β = 0.062), after 4 restarts"
        );
        e.annealed = Some(Annealed { lower: Some((500.0, 3.0)), ..a.clone() });
        assert_eq!(
            settled_words(&e),
            "no (0 rounds; annealing reached β = 0.062): counted at ln Z ≥ 494.0, after 4 restarts"
        );
        e.annealed = Some(Annealed { upper: Some((600.0, 0.5)), ..e.annealed.clone().unwrap() });
        assert!(
            settled_words(&e).ends_with("counted at ln Z ≥ 494.0, at most 601.0, after 4 restarts")
        );
        e.annealed = Some(Annealed { estimate: Some((1.0, 0.3)), stages: 2, beta: 1.0, ..a });
        e.converged = true;
        e.restarts = 0;
        assert_eq!(settled_words(&e), "yes (annealed, 2 stages)");
    }
}
