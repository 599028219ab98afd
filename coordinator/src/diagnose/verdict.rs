//! `diagnosis.json`, format `ceiling-diagnosis/2`: the fields of
//! `ceiling-diagnosis/1` (spec page `measured-bundle.md`: the cause, every
//! candidate with its MDL and validation error, and the gain on the
//! validation runs), a `cause` that may join several effects' names with
//! `+` and their list `causes`, and `classes`: every class tried with its
//! evidence, posterior probability and validation error. A reader of `/1`
//! reads `/2` (every field of `/1` is there, spelt the same) but for a
//! `cause` of several effects, which only `--verdict evidence` names;
//! optionally the symptoms (an extra field).

use super::evidence::{Evidence, Reading};
use super::linear_stage::report::LinearJson;
use super::pipeline::{Diagnosis, VerdictRule};
use serde::Serialize;

/// Format string of the verdict.
pub const FORMAT: &str = "ceiling-diagnosis/2";

/// One class tried, as `classes` lists it: the summary a reader compares
/// classes by (the candidate's own entry has the rest).
#[derive(Debug, Clone, Serialize)]
pub struct ClassJson {
    /// Its name: the effects joined by `+`, or `none`.
    pub cause: String,
    /// Its effects (empty for `none`).
    pub causes: Vec<&'static str>,
    /// Calibrated parameters.
    pub k: usize,
    /// ln p(data | class) (nat; null without `--evidence` or when it could
    /// not be computed).
    pub ln_evidence: Option<f64>,
    /// Its standard error (nat).
    pub ln_evidence_sd: Option<f64>,
    /// Whether the evidence settled (null without one): only a settled
    /// evidence takes a share of the probability.
    pub settled: Option<bool>,
    /// When the evidence did not settle but an annealing bounded it below:
    /// the value it is counted at (the bound less two standard errors,
    /// nat); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_evidence_at_least: Option<f64>,
    /// When so bounded, and bounded above too: the most it may be (the
    /// upper bound plus two standard errors, nat); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_evidence_at_most: Option<f64>,
    /// Posterior probability among the classes tried (null without an
    /// evidence, or one neither settled nor bounded). A bounded class
    /// enters at its counted bound: against settled classes its
    /// probability is a lower bound; against another bounded class the
    /// two bounds do not order the classes (see docs/diagnosis.md).
    pub probability: Option<f64>,
    /// Mean validation error beyond the noise of its prediction.
    pub validation_error: f64,
    /// Whether the verdict names it (with `unexplained`: the model found
    /// wanting).
    pub selected: bool,
}

impl ClassJson {
    /// The summary of candidate `c` of class `cause`.
    fn of(cause: super::cause::Cause, c: &CandidateJson) -> Self {
        let e = c.evidence.as_ref();
        ClassJson {
            cause: c.cause.clone(),
            causes: cause.effects().map(|e| e.name()).collect(),
            k: c.k,
            ln_evidence: e.and_then(|e| e.ln_evidence),
            ln_evidence_sd: e.and_then(|e| e.ln_evidence_sd),
            settled: e.and_then(|e| e.converged),
            ln_evidence_at_least: e.and_then(|e| e.ln_evidence_at_least),
            ln_evidence_at_most: e.and_then(|e| e.ln_evidence_at_most),
            probability: e.and_then(|e| e.probability).filter(|p| p.is_finite()),
            validation_error: c.validation_error,
            selected: c.selected,
        }
    }
}

/// One candidate as written.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateJson {
    /// Cause spelling.
    pub cause: String,
    /// MDL (nats); null when the calibration failed.
    pub mdl: Option<f64>,
    /// Mean normalised error on the validation runs, in excess of the
    /// sensor noise (0: the model misses by the noise alone), of the
    /// variant's prediction: the pointwise median of its histories over
    /// `prediction_members` parameter points around the estimate.
    pub validation_error: f64,
    /// Parameter points whose validation histories made the prediction.
    pub prediction_members: usize,
    /// Mean raw NRMSE on the validation runs (sensor noise included).
    pub validation_nrmse: f64,
    /// Whether it was chosen.
    pub selected: bool,
    /// Mean normalised error on the calibration runs.
    pub calibration_error: f64,
    /// The same in excess of the sensor noise (as `validation_error`).
    pub calibration_excess_error: f64,
    /// MDL of the candidate's linear part (nats), which it must beat to be
    /// chosen; absent when it has none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linear_part_mdl: Option<f64>,
    /// MDL terms: fit, parametric, geometric (nats).
    pub mdl_terms: Option<[f64; 3]>,
    /// `committed` when its springs are damped on their committed tangent
    /// rather than their initial stiffness (`super::damping_form`); absent
    /// otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_stiffness: Option<String>,
    /// Parameters k.
    pub k: usize,
    /// FE parameter points spent.
    pub fe_points: usize,
    /// Calibrated values by name.
    pub parameters: std::collections::BTreeMap<String, f64>,
    /// Its frequencies at the estimate against `modal.csv`, on which it
    /// was calibrated too; absent without one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub modal: Option<ModalJson>,
    /// The variational posterior (chosen variant only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub posterior: Option<PosteriorJson>,
    /// Its evidence and posterior probability among the classes
    /// (`diagnose --evidence`); absent when not asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub evidence: Option<EvidenceJson>,
}

/// A class's evidence as written (`super::class_odds`).
#[derive(Debug, Clone, Serialize)]
pub struct EvidenceJson {
    /// How it was computed.
    pub method: String,
    /// The likelihood integrated: `band` (Whittle over the model's band) or
    /// `time` (Gaussian under the channel weights).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub likelihood: Option<&'static str>,
    /// ln p(data | class) (nats).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_evidence: Option<f64>,
    /// Its standard error (nats).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_evidence_sd: Option<f64>,
    /// Posterior probability among the classes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub probability: Option<f64>,
    /// The prior probability of each effect the probability is under, when
    /// not the default 0.5 (equal prior odds for every class).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effect_prior: Option<f64>,
    /// Pareto k̂ of the last FE correction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub k_hat: Option<f64>,
    /// Whether its rounds met their stop rule.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub converged: Option<bool>,
    /// The ln Z it is counted at when not settled but bounded below
    /// ([`super::class_evidence::ClassEvidence::counted_ln_evidence`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_evidence_at_least: Option<f64>,
    /// The most ln Z may be when not settled but bounded above
    /// ([`super::class_evidence::ClassEvidence::ln_evidence_at_most`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_evidence_at_most: Option<f64>,
    /// The Laplace approximation at the estimate (nats), for comparison.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub laplace_ln_evidence: Option<f64>,
    /// The factor the scale check put on the search's curvature before the
    /// rounds (absent when 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curvature_scale: Option<f64>,
    /// FE parameter points the evidence ran.
    pub fe_points: usize,
    /// Times the calibration's search resumed from higher ground the
    /// evidence's checks found (absent when none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub restarts: Option<usize>,
    /// The annealing from the last round's emulated posterior to the FE
    /// posterior, when the rounds did not settle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub annealed: Option<AnnealedJson>,
    /// Each round: emulated ln Z, corrected ln Z, its standard error, k̂
    /// (null where every check failed).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rounds: Vec<[Option<f64>; 4]>,
    /// Why there is no evidence.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_computable: Option<String>,
}

/// An annealed evidence as written.
#[derive(Debug, Clone, Serialize)]
pub struct AnnealedJson {
    /// ln Z (nat; null when it did not reach the FE posterior).
    pub ln_evidence: Option<f64>,
    /// Its standard error.
    pub ln_evidence_sd: Option<f64>,
    /// Stages run.
    pub stages: usize,
    /// FE runs of its moves.
    pub fe_points: usize,
    /// The temperature reached (1: the FE posterior).
    pub beta: f64,
    /// When it stopped short of the FE posterior: ln Z bounded below from
    /// the temperature reached, and the bound's standard error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_evidence_lower: Option<[f64; 2]>,
    /// When it stopped short: ln Z bounded above from the temperature
    /// reached by the highest ln L/L̃ its particles held, and the bound's
    /// standard error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_evidence_upper: Option<[f64; 2]>,
}

/// One round as written: emulated ln Z, then the corrected ln Z, its
/// error and k̂ (null where every check failed).
fn round_json(r: &super::class_evidence::EvidenceRound) -> [Option<f64>; 4] {
    let c = r.corrected.as_ref();
    [Some(r.emulated.0), c.map(|c| c.ln_evidence), c.map(|c| c.ln_evidence_sd), c.map(|c| c.k_hat)]
}

/// The method line of a class evidence.
pub const EVIDENCE_METHOD: &str = "tempered SMC on an emulator of ln L (a quadratic, the \
    Laplace form at the estimate refitted to the FE runs, plus a GP of the residual), corrected by \
    FE runs at its posterior draws until two rounds agree";

fn evidence_json(o: &Option<Result<super::class_odds::ClassOdds, String>>) -> Option<EvidenceJson> {
    let method = EVIDENCE_METHOD.to_string();
    Some(match o.as_ref()? {
        Ok(o) => {
            let e = &o.evidence;
            EvidenceJson {
                method,
                likelihood: Some(e.likelihood.as_str()),
                ln_evidence: Some(e.ln_evidence),
                ln_evidence_sd: Some(e.ln_evidence_sd),
                probability: Some(o.probability),
                effect_prior: (o.effect_prior != 0.5).then_some(o.effect_prior),
                k_hat: Some(e.k_hat),
                converged: Some(e.converged),
                ln_evidence_at_least: (!e.converged).then(|| e.counted_ln_evidence()).flatten(),
                ln_evidence_at_most: (!e.converged).then(|| e.ln_evidence_at_most()).flatten(),
                laplace_ln_evidence: Some(e.laplace_ln_evidence),
                curvature_scale: (e.curvature_scale != 1.0).then_some(e.curvature_scale),
                fe_points: e.fe_points,
                restarts: (e.restarts > 0).then_some(e.restarts),
                annealed: e.annealed.as_ref().map(|a| AnnealedJson {
                    ln_evidence: a.estimate.map(|e| e.0),
                    ln_evidence_sd: a.estimate.map(|e| e.1),
                    stages: a.stages,
                    fe_points: a.fe_points,
                    beta: a.beta,
                    ln_evidence_lower: a.lower.map(|(b, sd)| [b, sd]),
                    ln_evidence_upper: a.upper.map(|(b, sd)| [b, sd]),
                }),
                rounds: e.rounds.iter().map(round_json).collect(),
                not_computable: None,
            }
        }
        Err(why) => EvidenceJson {
            method,
            likelihood: None,
            ln_evidence: None,
            ln_evidence_sd: None,
            probability: None,
            effect_prior: None,
            k_hat: None,
            converged: None,
            ln_evidence_at_least: None,
            ln_evidence_at_most: None,
            laplace_ln_evidence: None,
            curvature_scale: None,
            fe_points: 0,
            restarts: None,
            annealed: None,
            rounds: vec![],
            not_computable: Some(why.clone()),
        },
    })
}

/// A candidate's frequencies against the identified ones.
#[derive(Debug, Clone, Serialize)]
pub struct ModalJson {
    /// Mode numbers.
    pub modes: Vec<u32>,
    /// Measured frequencies (Hz).
    pub measured_hz: Vec<f64>,
    /// The model's at the estimate, as integrated (Hz; [`super::modal_fit::as_integrated_hz`]).
    pub model_hz: Vec<f64>,
    /// The model's eigenfrequencies at the estimate (Hz).
    pub eigen_hz: Vec<f64>,
    /// The step the runs are integrated at (s).
    pub step_s: f64,
    /// The estimated model-discrepancy sd (Hz).
    pub discrepancy_sd_hz: f64,
    /// −log L of the frequencies (nats; part of the MDL's fit term).
    pub neg_log_lik: f64,
}

/// A variant's posterior as written: per parameter mean, sd and central
/// 95 % interval (prior units), or why it could not be had.
#[derive(Debug, Clone, Serialize)]
pub struct PosteriorJson {
    /// How it was obtained.
    pub method: String,
    /// Per parameter: mean, sd, 2.5 % and 97.5 % quantiles.
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub parameters: std::collections::BTreeMap<String, [f64; 4]>,
    /// BBVI iterations.
    pub iterations: usize,
    /// Whether BBVI converged.
    pub converged: bool,
    /// Relative change of q's last two window averages.
    pub rel_change: Option<f64>,
    /// The emulator checked by FE runs at q's mean and draws.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub emulator_check: Option<EmulatorCheckJson>,
    /// Why there is no posterior.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_computable: Option<String>,
}

/// How the posterior's emulator fared against the FE model.
#[derive(Debug, Clone, Serialize)]
pub struct EmulatorCheckJson {
    /// FE parameter points the checks ran.
    pub fe_points: usize,
    /// Largest |FE − emulated| excess −log L at the posterior's probes
    /// (nats; each side capped at 100 above the best).
    pub gap_nats: f64,
    /// Whether the gap is within the check's tolerance (5 nats).
    pub confirmed: bool,
}

/// The method line of a posterior.
pub const POSTERIOR_METHOD: &str = "BBVI (full-rank Gaussian on the logit of the prior box) on \
    an emulator of -log L: Gauss-Newton quadratic at the estimate plus a GP through the \
    FE-evaluated misfits near it, checked by FE runs at q's mean and draws";

fn posterior_json(
    p: &Option<Result<super::posterior::VariationalPosterior, String>>,
) -> Option<PosteriorJson> {
    let method = POSTERIOR_METHOD.to_string();
    match p.as_ref()? {
        Ok(p) => Some(PosteriorJson {
            method,
            parameters: (0..p.names.len())
                .map(|k| (p.names[k].clone(), [p.mean[k], p.sd[k], p.q025[k], p.q975[k]]))
                .collect(),
            iterations: p.iterations,
            converged: p.converged,
            rel_change: Some(p.rel_change),
            emulator_check: p.check.map(|c| EmulatorCheckJson {
                fe_points: c.fe_points,
                gap_nats: c.gap_nats,
                confirmed: c.confirmed,
            }),
            not_computable: None,
        }),
        Err(why) => Some(PosteriorJson {
            method,
            parameters: Default::default(),
            iterations: 0,
            converged: false,
            rel_change: None,
            emulator_check: None,
            not_computable: Some(why.clone()),
        }),
    }
}

/// The verdict as written.
#[derive(Debug, Clone, Serialize)]
pub struct VerdictJson {
    /// `ceiling-diagnosis/2`.
    pub format: String,
    /// Bundle name.
    pub bundle: String,
    /// The cause named: a candidate's, or `unexplained` when the data show
    /// something no model explains ([`UnexplainedJson`]).
    pub cause: String,
    /// The effects of the class named, in the registry's order (empty for
    /// `none` and for `unexplained`; an extra field, which the format
    /// allows): `cause` is them joined by `+`.
    pub causes: Vec<&'static str>,
    /// The rule that named it when not the MDL's: `evidence` (the class of
    /// highest posterior probability; an extra field, which the format
    /// allows).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict_rule: Option<&'static str>,
    /// What no model explains (with `cause = "unexplained"`; an extra
    /// field, which the format allows).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unexplained: Option<UnexplainedJson>,
    /// Every candidate, the baseline first.
    pub candidates: Vec<CandidateJson>,
    /// Every class tried, in the candidates' order: its evidence, posterior
    /// probability and validation error ([`ClassJson`]).
    pub classes: Vec<ClassJson>,
    /// Baseline error on the validation runs.
    pub baseline_validation_error: f64,
    /// Chosen variant's error on the validation runs.
    pub extended_validation_error: f64,
    /// 1 − extended / baseline.
    pub gain: f64,
    /// Calibration run ids.
    pub calibration_runs: Vec<String>,
    /// Validation run ids.
    pub validation_runs: Vec<String>,
    /// FE parameter points spent in all.
    pub fe_points: usize,
    /// On a double-layer ceiling, whether every model calibrates the
    /// carrying channels (an extra field, which the format allows).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline_channels: Option<ChannelsJson>,
    /// The linear stage's fit of the specimen's linear form, which every
    /// model held (an extra field, which the format allows).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linear_stage: Option<LinearJson>,
    /// The symptoms, when given ([`VerdictJson::with_symptoms`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub symptoms: Vec<SymptomJson>,
    /// The FE load of each stage, in order (an extra field, which the
    /// format allows; [`super::stage_load`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<StageJson>,
}

/// One stage's FE load, as written.
#[derive(Debug, Clone, Serialize)]
pub struct StageJson {
    /// The stage.
    pub stage: String,
    /// Parameter points it asked for.
    pub fe_runs: usize,
    /// Batches it asked for them in.
    pub batches: usize,
    /// The largest batch.
    pub widest: usize,
    /// Mean points per batch: the runs in flight while it waited.
    pub mean_in_flight: f64,
}

/// The verdict's word when no model explains the data.
pub const UNEXPLAINED: &str = "unexplained";

/// What no model explains, as written.
#[derive(Debug, Clone, Serialize)]
pub struct UnexplainedJson {
    /// The model the MDL chose, which the check found wanting.
    pub model: String,
    /// Its mean validation error beyond the noise.
    pub validation_error: f64,
    /// Each channel missed by more than the explained error.
    pub misses: Vec<MissJson>,
    /// The classes the evidence does not order, the named one first
    /// (absent when it orders them).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub undecided: Vec<String>,
}

/// One missed channel as written.
#[derive(Debug, Clone, Serialize)]
pub struct MissJson {
    /// `calibration run` or `validation run`.
    pub at: String,
    /// Run id.
    pub run: String,
    /// Sensor id.
    pub sensor: String,
    /// Error beyond the noise, as a share of the signal's RMS.
    pub excess_error: f64,
}

/// The choice of the carrying channels as written.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelsJson {
    /// Whether the channels (`channel_mass_kg_per_m`, `channel_beam_factor`)
    /// are calibrated.
    pub calibrated: bool,
    /// The baseline's MDL without them (nats, under the mid-point weights).
    pub mdl_without: f64,
    /// The baseline's MDL with them.
    pub mdl_with: f64,
}

/// One symptom as written: its numbers on the focus run (null when not
/// computable, the reason in `not_computable`).
#[derive(Debug, Clone, Serialize)]
pub struct SymptomJson {
    /// Machine name, e.g. `spike_share`.
    pub name: String,
    /// Unit of the numbers ("-" for ratios).
    pub unit: String,
    /// Run the numbers come from.
    pub run: Option<String>,
    /// On the measurement (null also when the measurement is the reference).
    pub measured: Option<f64>,
    /// On the calibrated baseline's simulation.
    pub baseline: Option<f64>,
    /// On the chosen extension's simulation.
    pub extended: Option<f64>,
    /// Why a number is missing, per column ("measured: ...").
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_computable: Vec<String>,
}

impl VerdictJson {
    /// The verdict with the symptoms of `e`.
    pub fn with_symptoms(mut self, e: &Evidence) -> Self {
        self.symptoms = e
            .symptoms
            .iter()
            .map(|s| SymptomJson {
                name: s.key.into(),
                unit: s.unit.into(),
                run: e.focus_run.clone(),
                measured: s.readings[0].value(),
                baseline: s.readings[1].value(),
                extended: s.readings[2].value(),
                not_computable: ["measured", "baseline", "extended"]
                    .iter()
                    .zip(&s.readings)
                    .filter_map(|(col, r)| match r {
                        Reading::NotComputable(why) => Some(format!("{col}: {why}")),
                        _ => None,
                    })
                    .collect(),
            })
            .collect();
        self
    }
}

/// The verdict of a diagnosis; `run_ids` names the bundle's runs.
pub fn verdict(d: &Diagnosis, run_ids: &[String]) -> VerdictJson {
    let mut v = verdict_fields(d, run_ids);
    v.classes =
        (d.candidates.iter().zip(&v.candidates)).map(|(r, c)| ClassJson::of(r.cause, c)).collect();
    v
}

/// Every field of the verdict but `classes` (empty).
fn verdict_fields(d: &Diagnosis, run_ids: &[String]) -> VerdictJson {
    let ids = |v: &[usize]| v.iter().map(|k| run_ids[*k].clone()).collect();
    VerdictJson {
        format: FORMAT.into(),
        bundle: d.bundle.clone(),
        cause: if d.unexplained.is_some() { UNEXPLAINED.into() } else { d.cause.as_str().into() },
        causes: match d.unexplained {
            Some(_) => vec![],
            None => d.cause.effects().map(|e| e.name()).collect(),
        },
        verdict_rule: (d.rule != VerdictRule::Mdl).then_some(d.rule.as_str()),
        unexplained: d.unexplained.as_ref().map(|u| UnexplainedJson {
            model: d.cause.as_str().into(),
            validation_error: u.validation_error,
            misses: u
                .misses
                .iter()
                .map(|m| MissJson {
                    at: m.at.as_str().into(),
                    run: m.run.clone(),
                    sensor: m.sensor.clone(),
                    excess_error: m.excess_error,
                })
                .collect(),
            undecided: u.undecided.iter().map(|c| c.as_str().to_string()).collect(),
        }),
        candidates: d
            .candidates
            .iter()
            .map(|c| CandidateJson {
                cause: c.cause.as_str().into(),
                mdl: c.mdl.as_ref().map(|m| m.total),
                validation_error: c.validation_error,
                prediction_members: c.prediction_members,
                validation_nrmse: c.validation_nrmse,
                selected: c.selected,
                calibration_error: c.calibration_error,
                calibration_excess_error: c.calibration_excess_error,
                linear_part_mdl: c.linear_part_mdl,
                mdl_terms: c.mdl.as_ref().map(|m| [m.fit, m.parametric, m.geometric]),
                damping_stiffness: (c.committed_share > 0.0).then(|| "committed".into()),
                k: c.k,
                fe_points: c.fe_points,
                parameters: c.estimates.iter().map(|e| (e.name.clone(), e.value)).collect(),
                modal: c.modal.as_ref().map(|m| ModalJson {
                    modes: m.modes.clone(),
                    measured_hz: m.measured_hz.clone(),
                    model_hz: m.model_hz.clone(),
                    eigen_hz: m.eigen_hz.clone(),
                    step_s: m.step_s,
                    discrepancy_sd_hz: m.discrepancy_var_hz2.sqrt(),
                    neg_log_lik: m.neg_log_lik,
                }),
                posterior: posterior_json(&c.posterior),
                evidence: evidence_json(&c.odds),
            })
            .collect(),
        classes: vec![],
        baseline_validation_error: d.baseline_validation_error,
        extended_validation_error: d.extended_validation_error,
        gain: d.gain,
        calibration_runs: ids(&d.calibration_runs),
        validation_runs: ids(&d.validation_runs),
        fe_points: d.fe_points,
        baseline_channels: d.channels.map(|f| ChannelsJson {
            calibrated: f.calibrated,
            mdl_without: f.mdl_without,
            mdl_with: f.mdl_with,
        }),
        linear_stage: d.linear.as_ref().map(|l| LinearJson::of(run_ids, l)),
        symptoms: vec![],
        stages: (d.stage_loads.iter())
            .map(|l| StageJson {
                stage: l.stage.clone(),
                fe_runs: l.fe_runs,
                batches: l.batches,
                widest: l.widest,
                mean_in_flight: l.mean_in_flight(),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::cause::Cause;
    use crate::diagnose::evidence::evidence;
    use crate::diagnose::testkit::pounding_diagnosis;

    #[test]
    fn the_symptoms_go_into_diagnosis_json_with_nulls_and_reasons() {
        let (b, d) = pounding_diagnosis(true, false);
        let ids: Vec<String> = b.runs.iter().map(|r| r.id.clone()).collect();
        let plain = serde_json::to_value(verdict(&d, &ids)).unwrap();
        assert!(plain.get("symptoms").is_none(), "no symptoms unless given");
        let v = serde_json::to_value(verdict(&d, &ids).with_symptoms(&evidence(&b, &d))).unwrap();
        let rows = v["symptoms"].as_array().unwrap();
        let row = |name: &str| rows.iter().find(|r| r["name"] == name).unwrap().clone();
        let f = row("apparent_frequency_strong_over_weak");
        assert!(f["measured"].as_f64().unwrap() > 2.0 && f["run"] == "strong", "{f}");
        assert!(f.get("not_computable").is_none(), "{f}");
        // No displacement sensor: null and the reason, per column.
        let s = row("spike_share");
        assert!(s["measured"].is_null() && s["baseline"].is_null(), "{s}");
        let why = s["not_computable"].as_array().unwrap();
        assert_eq!(why.len(), 3);
        assert!(why[0].as_str().unwrap().starts_with("measured: no displacement sensor"), "{s}");
        assert!(row("residual_energy_db")["measured"].is_null());
    }

    #[test]
    fn causes_list_the_named_class_effects_and_join_into_cause() {
        let (b, mut d) = pounding_diagnosis(true, false);
        let ids: Vec<String> = b.runs.iter().map(|r| r.id.clone()).collect();
        for (cause, want) in [
            (Cause::NONE, vec![]),
            (Cause::PERIMETER_POUNDING, vec!["perimeter-pounding"]),
            (
                Cause::PERIMETER_FRICTION.with(0).with(2),
                vec!["perimeter-pounding", "perimeter-friction", "connection-hysteresis"],
            ),
        ] {
            d.cause = cause;
            d.unexplained = None;
            let v = verdict(&d, &ids);
            assert_eq!(v.causes, want);
            let joined = if want.is_empty() { "none".to_string() } else { want.join("+") };
            assert_eq!(v.cause, joined);
        }
    }

    #[test]
    fn classes_list_every_candidate_with_its_effects_and_validation_error() {
        let (b, d) = pounding_diagnosis(true, false);
        let ids: Vec<String> = b.runs.iter().map(|r| r.id.clone()).collect();
        let v = serde_json::to_value(verdict(&d, &ids)).unwrap();
        assert_eq!(v["format"], "ceiling-diagnosis/2");
        let classes = v["classes"].as_array().unwrap();
        assert_eq!(classes.len(), d.candidates.len());
        for (c, r) in classes.iter().zip(&d.candidates) {
            assert_eq!(c["cause"], r.cause.as_str());
            assert_eq!(c["causes"].as_array().unwrap().len(), r.cause.size());
            // NaN (not computed) is written as null.
            let e = r.validation_error;
            assert_eq!(c["validation_error"].as_f64(), e.is_finite().then_some(e));
            assert_eq!(c["selected"], r.selected);
            // No --evidence: no evidence, no probability.
            assert!(c["ln_evidence"].is_null() && c["probability"].is_null(), "{c}");
        }
        // Every field a reader of ceiling-diagnosis/1 reads is there.
        for key in ["bundle", "cause", "candidates", "baseline_validation_error", "gain"] {
            assert!(v.get(key).is_some(), "{key}");
        }
    }
}
