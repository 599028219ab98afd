//! The farm as a diagnosis's FE executor: every batch of points becomes
//! tasks of the evaluation's `ceiling-campaign` study (one study per model
//! variant, run set and purpose; its hash names it; one task per point and
//! run), run on any transport. With an evaluation store, each run's result
//! is stored as it arrives and one already stored is not run again: a
//! diagnosis killed at any moment
//! and started again re-uses what it had and reaches the same verdict (its
//! sequence of points depends only on the results).

use super::campaign::{self, campaign_study, merge_runs, run_tasks, task_params};
use super::campaign::{CampaignStudy, Purpose};
use super::cause::Demand;
use super::executor::{ExecutorError, FeExecutor, Sims};
use super::fit::Evaluation;
use crate::evaluations::EvaluationStore;
use crate::farm::{FarmSession, FarmSettings, ResultSink, Silent};
use crate::study::TransportKind;
use protocol::{Outcome, Task, TaskId, TaskResult};
use std::path::PathBuf;

/// Where and how the farm runs.
#[derive(Debug, Clone)]
pub struct FarmPlan {
    /// Transport to the workers.
    pub transport: TransportKind,
    /// Worker threads (in-process) or the count a remote transport expects.
    pub workers: usize,
    /// Zenoh endpoint or iceoryx2 service prefix.
    pub endpoint: Option<String>,
    /// Leases and retries.
    pub settings: FarmSettings,
    /// The evaluation store (none: nothing kept, nothing re-used).
    pub store: Option<PathBuf>,
    /// Zenoh's security (`--zenoh-config`, `--insecure`).
    pub zenoh: crate::transports::ZenohSecurity,
}

/// Each task's outcome (or why it could not be set up) and whether it was
/// simulated now.
type TaskOutcomes = (Vec<Result<Outcome, String>>, Vec<bool>);

/// Runs FE evaluations on the farm, keeping them in the store.
pub struct FarmExecutor {
    plan: FarmPlan,
    store: Option<EvaluationStore>,
    /// The study being served (its hash) and its session: the workers stay
    /// joined while consecutive batches belong to one study.
    session: Option<(String, FarmSession)>,
    /// Task ids are unique over the executor's life, so that a late answer
    /// can never pass for another batch's.
    next_task: u64,
    /// Points with at least one run simulated now.
    simulated: usize,
    /// Points whose runs all came from the store or an earlier task.
    reused: usize,
    /// Run tasks simulated now.
    tasks_run: usize,
}

impl FarmExecutor {
    /// Opens (or creates) the plan's store.
    pub fn new(plan: FarmPlan) -> Result<Self, ExecutorError> {
        let store = plan.store.as_deref().map(EvaluationStore::open_or_create).transpose()?;
        let (simulated, reused, tasks_run) = (0, 0, 0);
        Ok(FarmExecutor { plan, store, session: None, next_task: 0, simulated, reused, tasks_run })
    }

    /// Evaluations (points) taken from the store instead of being simulated.
    pub fn reused(&self) -> usize {
        self.reused
    }

    /// Run tasks simulated (one per point and run; the store's rows).
    pub fn tasks_run(&self) -> usize {
        self.tasks_run
    }

    /// The outcome of every point over `n_runs` runs: each point's run
    /// tasks, stored or run on the farm, merged in run order.
    fn point_outcomes(
        &mut self,
        study: &CampaignStudy,
        points: &[Result<Vec<f64>, String>],
        n_runs: usize,
    ) -> Result<Vec<Result<Outcome, String>>, ExecutorError> {
        let n_runs = n_runs.max(1);
        let tasks: Vec<Result<Vec<f64>, String>> = points
            .iter()
            .flat_map(|p| match p {
                Ok(params) => run_tasks(params, n_runs).into_iter().map(Ok).collect(),
                Err(e) => vec![Err(e.clone()); n_runs],
            })
            .collect();
        let (outcomes, ran) = self.outcomes(study, &tasks)?;
        let mut out = Vec::with_capacity(points.len());
        for (point, (runs, ran)) in
            points.iter().zip(outcomes.chunks(n_runs).zip(ran.chunks(n_runs)))
        {
            if point.is_ok() {
                if ran.iter().any(|r| *r) {
                    self.simulated += 1;
                } else {
                    self.reused += 1;
                }
            }
            let merged: Result<Vec<Outcome>, String> = runs.iter().cloned().collect();
            out.push(merged.map(merge_runs));
        }
        Ok(out)
    }

    /// The outcome of every task, stored, else run on the farm (and
    /// stored), and whether it was run now.
    fn outcomes(
        &mut self,
        study: &CampaignStudy,
        tasks: &[Result<Vec<f64>, String>],
    ) -> Result<TaskOutcomes, ExecutorError> {
        if let Some(store) = &self.store {
            store.add_study(&study.hash, &study.spec)?;
        }
        let mut out: Vec<Option<Result<Outcome, String>>> = Vec::with_capacity(tasks.len());
        let mut missing: Vec<(usize, Vec<f64>)> = Vec::new();
        // Points repeated within the batch: (batch index, index of the first).
        let mut repeats: Vec<(usize, usize)> = Vec::new();
        for (k, p) in tasks.iter().enumerate() {
            let earlier = p.as_ref().ok().and_then(|params| {
                missing.iter().find(|(_, q)| same_point(q, params)).map(|(first, _)| *first)
            });
            if let Some(first) = earlier {
                repeats.push((k, first));
                out.push(None);
                continue;
            }
            let stored = match (p, &self.store) {
                (Ok(params), Some(store)) => store.get(&study.hash, params)?,
                _ => None,
            };
            match (p, stored) {
                (Err(e), _) => out.push(Some(Err(e.clone()))),
                (Ok(_), Some(o)) => out.push(Some(Ok(o))),
                (Ok(params), None) => {
                    missing.push((k, params.clone()));
                    out.push(None);
                }
            }
        }
        let mut ran = vec![false; tasks.len()];
        for (k, result) in self.run(study, &missing)? {
            out[k] = Some(Ok(result.outcome));
            ran[k] = true;
        }
        for (k, first) in repeats {
            out[k] = out[first].clone();
        }
        let out = out
            .into_iter()
            .map(|o| o.unwrap_or_else(|| Err("the farm returned no result".into())))
            .collect();
        Ok((out, ran))
    }

    /// Runs `missing` (batch index, parameters) on the farm.
    fn run(
        &mut self,
        study: &CampaignStudy,
        missing: &[(usize, Vec<f64>)],
    ) -> Result<Vec<(usize, TaskResult)>, ExecutorError> {
        if missing.is_empty() {
            return Ok(vec![]);
        }
        let base = self.next_task;
        self.next_task += missing.len() as u64;
        let tasks: Vec<Task> = (missing.iter().enumerate())
            .map(|(j, (_, p))| Task { id: TaskId(base + j as u64), params: p.clone() })
            .collect();
        let store = self.store.as_mut();
        let session = session_for(&mut self.session, &self.plan, study)?;
        let mut sink = Collect { store, study, missing, base, results: vec![] };
        let outcome = session.run(tasks, &mut sink, &mut Silent);
        self.tasks_run += sink.results.len();
        let results = sink.results;
        if outcome.is_err() {
            // A transport that failed is not used again.
            self.session = None;
        }
        outcome?;
        Ok(results)
    }
}

/// Whether two parameter vectors are the same point, bit for bit (as the
/// store keys them).
fn same_point(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The session serving `study`, started (and any other one ended) if needed.
fn session_for<'s>(
    current: &'s mut Option<(String, FarmSession)>,
    plan: &FarmPlan,
    study: &CampaignStudy,
) -> Result<&'s mut FarmSession, ExecutorError> {
    if current.as_ref().is_some_and(|(hash, _)| *hash != study.hash) {
        *current = None;
    }
    if current.is_none() {
        let transport = crate::transports::coordinator_transport_secured(
            plan.transport,
            plan.workers.max(1),
            plan.endpoint.as_deref(),
            &plan.zenoh,
        )?;
        let session =
            FarmSession::start(transport, &study.hash, &study.spec, plan.settings.clone())?;
        *current = Some((study.hash.clone(), session));
    }
    match current {
        Some((_, session)) => Ok(session),
        None => Err(ExecutorError::Model("no farm session".into())),
    }
}

/// Keeps each final result (in the store, and for the caller).
struct Collect<'a> {
    store: Option<&'a mut EvaluationStore>,
    study: &'a CampaignStudy,
    missing: &'a [(usize, Vec<f64>)],
    base: u64,
    results: Vec<(usize, TaskResult)>,
}

impl ResultSink for Collect<'_> {
    fn accept(&mut self, results: &[TaskResult]) -> Result<(), String> {
        let mut keyed = Vec::with_capacity(results.len());
        for r in results {
            let (k, params) = self
                .missing
                .get(r.id.0.wrapping_sub(self.base) as usize)
                .ok_or_else(|| format!("result for unknown task {}", r.id.0))?;
            keyed.push((*k, params.as_slice(), r));
        }
        if let Some(store) = self.store.as_deref_mut() {
            // The farm's own failures (timeouts, lost tasks) are retried on resume.
            let rows: Vec<(&[f64], &TaskResult)> = (keyed.iter())
                .filter(|(_, _, r)| !crate::farm::farm_failure(r))
                .map(|(_, p, r)| (*p, *r))
                .collect();
            store.record(&self.study.hash, &rows).map_err(|e| e.to_string())?;
        }
        self.results.extend(keyed.into_iter().map(|(k, _, r)| (k, r.clone())));
        Ok(())
    }
}

impl FeExecutor for FarmExecutor {
    fn simulate(
        &mut self,
        ev: &Evaluation<'_>,
        thetas: &[Vec<f64>],
    ) -> Result<Vec<Sims>, ExecutorError> {
        let study = campaign_study(ev, Purpose::Histories).map_err(ExecutorError::Model)?;
        let points: Vec<_> = thetas.iter().map(|t| task_params(ev, &study, t)).collect();
        let outcomes = self.point_outcomes(&study, &points, ev.runs.len())?;
        outcomes
            .into_iter()
            .map(|o| match o {
                Ok(Outcome::Ok(out)) => campaign::simulated(ev, &out).map(Ok).map_err(|message| {
                    ExecutorError::Outputs { what: format!("study {}", &study.hash[..12]), message }
                }),
                Ok(Outcome::Failed { reason }) => Ok(Err(reason)),
                Err(e) => Ok(Err(e)),
            })
            .collect()
    }

    fn demand(
        &mut self,
        ev: &Evaluation<'_>,
        theta: &[f64],
    ) -> Result<Result<Demand, String>, ExecutorError> {
        let study = campaign_study(ev, Purpose::Demand).map_err(ExecutorError::Model)?;
        let point = task_params(ev, &study, theta);
        let outcome = self.point_outcomes(&study, &[point], ev.runs.len())?.pop();
        match outcome {
            Some(Ok(Outcome::Ok(out))) => campaign::demand(ev, &out).map(Ok).map_err(|message| {
                ExecutorError::Outputs { what: format!("study {}", &study.hash[..12]), message }
            }),
            Some(Ok(Outcome::Failed { reason })) => Ok(Err(reason)),
            Some(Err(e)) => Ok(Err(e)),
            None => Ok(Err("the farm returned no result".into())),
        }
    }

    fn simulated(&self) -> usize {
        self.simulated
    }
}
