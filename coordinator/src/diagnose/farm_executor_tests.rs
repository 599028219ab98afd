//! The farm executor against plain threads on a tiny campaign (2.4 m x
//! 2.4 m, three 2 s runs at 50 Hz, pounding hidden), with a reduced budget:
//! the in-process farm gives the same diagnosis bit for bit, and a
//! diagnosis stopped midway then started again on the same store runs only
//! the evaluations it had not stored and reaches the same diagnosis.

use super::calibrate::Budget;
use super::cause::{Cause, Demand};
use super::class_evidence::EvidencePolicy;
use super::executor::{ExecutorError, FeExecutor, Sims, ThreadExecutor};
use super::farm_executor::{FarmExecutor, FarmPlan};
use super::fit::Evaluation;
use super::pipeline::{diagnose_with, DiagnoseOptions, Diagnosis};
use crate::bundle::{read_bundle, Bundle};
use crate::farm::FarmSettings;
use crate::study::TransportKind;

/// The tiny campaign (the demo's, shrunk).
pub(crate) const TINY: &str = include_str!("../../../configs/synth/tiny-test.toml");

/// The tiny campaign's bundle, written under `dir`.
pub(crate) fn tiny_bundle(dir: &std::path::Path) -> Bundle {
    let spec = dir.join("campaign.toml");
    std::fs::write(&spec, TINY).unwrap();
    let out = dir.join("bundle");
    crate::synth::synth_to_dir(&spec, &out, &dir.join("answer.json"), &mut |_| {}).unwrap();
    read_bundle(&out).unwrap()
}

/// A budget of a few FE points per variant, and each class's evidence
/// (400 particles a run), which names the cause.
pub(crate) fn tiny_options() -> DiagnoseOptions {
    DiagnoseOptions {
        budget: Budget {
            per_dim: 1,
            extra: 1,
            rounds: 1,
            per_round: 1,
            local: 5,
            threads: 2,
            seed: 3,
            valley_walks: 1,
            refine_walks: 1,
            damping_path: super::damping_path::DampingPathUse::Never,
            trims: super::campaign_size::SizeTrims::NONE,
        },
        candidates: vec![Cause::NONE, Cause::PERIMETER_POUNDING, Cause::PERIMETER_FRICTION],
        linear_stage: false,
        evidence: Some(EvidencePolicy {
            smc: stats::evidence::SmcOptions { particles: 400, ..Default::default() },
            ..EvidencePolicy::default()
        }),
        rule: super::pipeline::VerdictRule::Evidence,
        combine: true,
    }
}

fn in_process(store: Option<std::path::PathBuf>) -> FarmExecutor {
    FarmExecutor::new(FarmPlan {
        transport: TransportKind::InProcess,
        workers: 2,
        endpoint: None,
        settings: FarmSettings::default(),
        store,
        zenoh: Default::default(),
    })
    .unwrap()
}

/// Every number of a diagnosis (Debug prints each float's shortest
/// round-trip text: equal text, equal bits).
fn fingerprint(d: &Diagnosis) -> String {
    format!("{d:?}")
}

/// Delegates to an executor until `left` evaluations are spent, then stops.
struct StopAfter<'a> {
    inner: &'a mut dyn FeExecutor,
    left: usize,
}

impl StopAfter<'_> {
    fn spend(&mut self, n: usize) -> Result<(), ExecutorError> {
        if n > self.left {
            return Err(ExecutorError::Stopped("killed".into()));
        }
        self.left -= n;
        Ok(())
    }
}

impl FeExecutor for StopAfter<'_> {
    fn simulate(
        &mut self,
        ev: &Evaluation<'_>,
        t: &[Vec<f64>],
    ) -> Result<Vec<Sims>, ExecutorError> {
        // The batch is started (and stored) before the kill lands.
        let out = self.inner.simulate(ev, t)?;
        self.spend(t.len())?;
        Ok(out)
    }
    fn demand(
        &mut self,
        ev: &Evaluation<'_>,
        theta: &[f64],
    ) -> Result<Result<Demand, String>, ExecutorError> {
        let out = self.inner.demand(ev, theta)?;
        self.spend(1)?;
        Ok(out)
    }
    fn simulated(&self) -> usize {
        self.inner.simulated()
    }
}

#[test]
fn farm_matches_threads_and_a_stopped_diagnosis_resumes_from_its_store() {
    let dir = tempfile::tempdir().unwrap();
    let b = tiny_bundle(dir.path());
    let opts = tiny_options();
    let t0 = std::time::Instant::now();
    let mut threads = ThreadExecutor::new(2);
    let want = diagnose_with(&b, &opts, &mut threads, &mut |_, _, _| {}).unwrap();
    let total = threads.simulated();
    // Every batch is charged to a stage, the first the channel weights'.
    let metered: usize = want.stage_loads.iter().map(|l| l.fe_runs).sum();
    assert_eq!(metered, total, "{:?}", want.stage_loads);
    assert_eq!(want.stage_loads[0].fe_runs, 1, "{:?}", want.stage_loads[0]);
    eprintln!("load: {}", crate::diagnose::stage_load::summary(&want.stage_loads));
    for c in &want.candidates {
        let odds = c.odds.as_ref().expect("asked for").as_ref().expect("computed");
        eprintln!("{}: {odds:?}", c.cause.as_str());
    }
    let t_threads = t0.elapsed().as_secs_f64();

    let t0 = std::time::Instant::now();
    let mut farm = in_process(Some(dir.path().join("whole.db")));
    let got = diagnose_with(&b, &opts, &mut farm, &mut |_, _, _| {}).unwrap();
    let t_farm = t0.elapsed().as_secs_f64();
    assert_eq!(fingerprint(&got), fingerprint(&want), "in-process farm differs from threads");
    assert_eq!(got.stage_loads, want.stage_loads, "a store changes no stage's load");
    // A point asked for twice runs once: the second time it is in the store.
    let distinct = farm.simulated();
    assert_eq!(distinct + farm.reused(), total);

    let store = dir.path().join("out").join("evaluations.db");
    let mut first = in_process(Some(store.clone()));
    let mut killed = StopAfter { inner: &mut first, left: total / 2 };
    let e = diagnose_with(&b, &opts, &mut killed, &mut |_, _, _| {}).err().unwrap();
    assert!(e.to_string().contains("stopped: killed"), "{e}");
    let stored = crate::evaluations::EvaluationStore::open(&store).unwrap().len().unwrap();
    assert_eq!(stored, first.tasks_run(), "every run task simulated is stored");
    let first_points = first.simulated();
    assert!(first_points > 0 && first_points < distinct, "{first_points} run of {distinct}");
    drop(first);

    let mut resumed = in_process(Some(store.clone()));
    let again = diagnose_with(&b, &opts, &mut resumed, &mut |_, _, _| {}).unwrap();
    assert_eq!(fingerprint(&again), fingerprint(&want), "resumed diagnosis differs");
    assert_eq!(again.stage_loads, want.stage_loads, "resumed loads differ");
    assert_eq!(resumed.simulated(), distinct - first_points, "only the missing evaluations run");
    assert_eq!(resumed.simulated() + resumed.reused(), total);
    eprintln!(
        "{total} FE evaluations ({distinct} distinct); threads {t_threads:.2} s, \
         in-process farm {t_farm:.2} s; stopped with {stored} stored, resume ran {} and re-used {}",
        resumed.simulated(),
        resumed.reused()
    );
}

/// A point repeated within one batch runs once and both entries get its
/// result, with a store and without.
#[test]
fn a_point_repeated_in_a_batch_runs_once() {
    let dir = tempfile::tempdir().unwrap();
    let b = tiny_bundle(dir.path());
    let priors = Cause::NONE.priors();
    let runs = [0usize];
    let ev = Evaluation::baseline(&b, &priors, &runs);
    let (p, q) = (vec![15.0, 0.05], vec![20.0, 0.04]);
    for store in [None, Some(dir.path().join("e.db"))] {
        let mut farm = in_process(store);
        let out = farm.simulate(&ev, &[p.clone(), q.clone(), p.clone()]).unwrap();
        assert_eq!((farm.simulated(), farm.reused()), (2, 1));
        assert_eq!(out[0], out[2]);
        assert_ne!(out[0], out[1]);
    }
}

/// An evaluation damped on the committed tangent reaches the farm's
/// workers as such: the farm gives what `Evaluation::simulate` gives.
#[test]
fn the_committed_share_reaches_the_farm() {
    let dir = tempfile::tempdir().unwrap();
    let b = tiny_bundle(dir.path());
    let priors = Cause::PERIMETER_FRICTION.priors();
    let runs = [0usize];
    let ev = Evaluation {
        bundle: &b,
        cause: Cause::PERIMETER_FRICTION,
        priors: &priors,
        runs: &runs,
        demand: None,
        committed_share: 1.0,
    };
    let theta: Vec<f64> = priors.iter().map(|p| p.at(0.5)).collect();
    assert!(ev.assignments(&theta).contains(&("damping_committed_share", 1.0)));
    let mut farm = in_process(None);
    let out = farm.simulate(&ev, std::slice::from_ref(&theta)).unwrap();
    assert_eq!(out[0].as_ref().unwrap(), &ev.simulate(&theta).unwrap());
}

/// A calibration that frees the damping's mass share sends it to the farm's
/// workers: the farm gives what `Evaluation::simulate` gives, and another
/// share gives other histories.
#[test]
fn the_mass_share_reaches_the_farm() {
    let dir = tempfile::tempdir().unwrap();
    let b = tiny_bundle(dir.path());
    let mut priors = Cause::NONE.priors();
    priors.push(crate::diagnose::damping_share::MASS_SHARE);
    let runs = [0usize];
    let ev = Evaluation::baseline(&b, &priors, &runs);
    let at = |share: f64| -> Vec<f64> {
        let mut theta: Vec<f64> = priors.iter().map(|p| p.at(0.5)).collect();
        *theta.last_mut().unwrap() = share;
        theta
    };
    let (heavy, pair) = (at(0.9), at(0.5));
    assert!(ev.assignments(&heavy).contains(&("damping_mass_share", 0.9)));
    assert_eq!(ev.setup(&heavy).unwrap().2.damping_mass_share, 0.9);
    let mut farm = in_process(None);
    let out = farm.simulate(&ev, &[heavy.clone(), pair]).unwrap();
    assert_eq!(out[0].as_ref().unwrap(), &ev.simulate(&heavy).unwrap());
    assert_ne!(out[0], out[1]);
}
