//! FE runs in flight per stage: how many parameter points each stage of a
//! diagnosis hands the executor at once. A lab's farm of w workers is busy
//! only while a stage hands it batches of w or more; a stage that submits
//! one point at a time (a line search's trial) leaves the others idle. The
//! meter sits between the diagnosis and its executor and counts, for the
//! stage last announced through the progress callback, every batch and its
//! points, whether the executor runs them or finds them in its store (so a
//! re-diagnosis from the store reports the same loads).

use super::cause::Demand;
use super::executor::{ExecutorError, FeExecutor, Sims};
use super::fit::Evaluation;
use std::cell::RefCell;
use std::rc::Rc;

/// The FE load one stage put on the executor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StageLoad {
    /// The stage, as the progress callback names it.
    pub stage: String,
    /// Parameter points it asked for (each all the calibration or
    /// validation runs of one model).
    pub fe_runs: usize,
    /// Batches it asked for them in.
    pub batches: usize,
    /// The largest batch.
    pub widest: usize,
}

impl StageLoad {
    /// Mean parameter points per batch: the runs in flight while the
    /// stage waits on the executor.
    pub fn mean_in_flight(&self) -> f64 {
        self.fe_runs as f64 / self.batches.max(1) as f64
    }
}

/// The farm a stage should keep busy: 8 workers (a lab's 8-core machine).
pub const FARM_WORKERS: usize = 8;

/// One line on `loads`: the FE runs and batches in all, the mean in flight,
/// and the stages whose mean is below [`FARM_WORKERS`] with theirs.
pub fn summary(loads: &[StageLoad]) -> String {
    let runs: usize = loads.iter().map(|l| l.fe_runs).sum();
    let batches: usize = loads.iter().map(|l| l.batches).sum();
    let mean = runs as f64 / batches.max(1) as f64;
    let narrow: Vec<String> = (loads.iter())
        .filter(|l| l.mean_in_flight() < FARM_WORKERS as f64)
        .map(|l| format!("{} {:.1}", l.stage, l.mean_in_flight()))
        .collect();
    let head =
        format!("{runs} FE runs asked for in {batches} batches ({mean:.1} in flight on average)");
    match narrow.len() {
        0 => format!("{head}; every stage {FARM_WORKERS} or more"),
        n => format!(
            "{head}; {n} of {} stages below {FARM_WORKERS} on average: {}",
            loads.len(),
            narrow.join(", ")
        ),
    }
}

/// The stage a diagnosis is in, shared by its progress callback (which
/// names it) and the [`LoadMeter`] (which charges batches to it).
pub type CurrentStage = Rc<RefCell<String>>;

/// An executor that charges every batch it passes on to the current stage.
pub struct LoadMeter<'e> {
    inner: &'e mut dyn FeExecutor,
    current: CurrentStage,
    loads: Vec<StageLoad>,
}

impl<'e> LoadMeter<'e> {
    /// A meter over `inner`, reading the stage from `current`.
    pub fn new(inner: &'e mut dyn FeExecutor, current: CurrentStage) -> Self {
        LoadMeter { inner, current, loads: Vec::new() }
    }

    /// Every stage's load, in the order the stages first asked for FE runs.
    pub fn into_loads(self) -> Vec<StageLoad> {
        self.loads
    }

    /// Charges a batch of `n` points to the current stage.
    fn charge(&mut self, n: usize) {
        if n == 0 {
            return;
        }
        let stage = self.current.borrow();
        let at = match self.loads.iter().position(|l| l.stage == *stage) {
            Some(k) => k,
            None => {
                let stage = stage.clone();
                self.loads.push(StageLoad { stage, fe_runs: 0, batches: 0, widest: 0 });
                self.loads.len() - 1
            }
        };
        let load = &mut self.loads[at];
        load.fe_runs += n;
        load.batches += 1;
        load.widest = load.widest.max(n);
    }
}

impl FeExecutor for LoadMeter<'_> {
    fn simulate(
        &mut self,
        ev: &Evaluation<'_>,
        thetas: &[Vec<f64>],
    ) -> Result<Vec<Sims>, ExecutorError> {
        self.charge(thetas.len());
        self.inner.simulate(ev, thetas)
    }

    fn demand(
        &mut self,
        ev: &Evaluation<'_>,
        theta: &[f64],
    ) -> Result<Result<Demand, String>, ExecutorError> {
        self.charge(1);
        self.inner.demand(ev, theta)
    }

    fn simulated(&self) -> usize {
        self.inner.simulated()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batches_are_charged_to_the_stage_named_last() {
        let current: CurrentStage = Rc::new(RefCell::new("design".into()));
        let mut inner = super::super::executor::ThreadExecutor::new(1);
        let mut meter = LoadMeter::new(&mut inner, current.clone());
        meter.charge(8);
        meter.charge(8);
        *current.borrow_mut() = "line search".into();
        meter.charge(1);
        meter.charge(0);
        *current.borrow_mut() = "design".into();
        meter.charge(2);
        let loads = meter.into_loads();
        let want = |stage: &str, fe_runs, batches, widest| StageLoad {
            stage: stage.into(),
            fe_runs,
            batches,
            widest,
        };
        assert_eq!(loads, vec![want("design", 18, 3, 8), want("line search", 1, 1, 1)]);
        assert_eq!(loads[0].mean_in_flight(), 6.0);
        assert_eq!(
            summary(&loads),
            "19 FE runs asked for in 4 batches (4.8 in flight on average); 2 of 2 stages below 8 \
             on average: design 6.0, line search 1.0"
        );
    }
}
