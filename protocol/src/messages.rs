//! The task and result messages exchanged between coordinator and workers.

use serde::{Deserialize, Serialize};

/// Identifier of one design point within a study (its row in the design).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct TaskId(pub u64);

impl std::fmt::Display for TaskId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "task {}", self.0)
    }
}

/// What a worker needs to build the study's model once, before any task.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSpec {
    /// Registry name of the model kind (`"borehole"`, `"ceiling-modal"`, ...).
    pub kind: String,
    /// The study's `[model]` options as JSON text (kind-specific).
    pub options_json: String,
    /// Parameter names, in the order of every task's `params`.
    pub param_names: Vec<String>,
    /// Output names the study keeps (empty = all the model produces).
    pub outputs: Vec<String>,
}

#[cfg(test)]
impl ModelSpec {
    /// The transports' tests' model: kind `noop`, one parameter `x`.
    pub(crate) fn noop() -> Self {
        ModelSpec {
            kind: "noop".into(),
            options_json: "{}".into(),
            param_names: vec!["x".into()],
            outputs: vec![],
        }
    }
}

/// One run to do: a parameter set in physical units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Task {
    /// The design point this run evaluates.
    pub id: TaskId,
    /// Parameter values in the order of [`ModelSpec::param_names`].
    pub params: Vec<f64>,
}

/// Named time histories sharing one time step, stored row-major.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct History {
    /// Name of the group (e.g. `"sensors"`).
    pub name: String,
    /// Sampling step in seconds.
    pub dt_s: f64,
    /// Channel names, one per column (units in the name, e.g. `A13_accel_m_s2`).
    pub channels: Vec<String>,
    /// Samples, `n_samples x channels.len()`, row-major (one byte blob on the wire).
    #[serde(with = "crate::raw_f64")]
    pub data: Vec<f64>,
}

impl History {
    /// Number of time samples (rows).
    pub fn n_samples(&self) -> usize {
        if self.channels.is_empty() {
            0
        } else {
            self.data.len() / self.channels.len()
        }
    }

    /// One channel as a column vector, or `None` if the name is unknown.
    pub fn channel(&self, name: &str) -> Option<Vec<f64>> {
        let c = self.channels.iter().position(|n| n == name)?;
        let w = self.channels.len();
        Some(self.data.chunks_exact(w).map(|row| row[c]).collect())
    }
}

/// What a successful run produced.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Outputs {
    /// Named scalar results (e.g. `f1_hz`), in the model's order.
    pub scalars: Vec<(String, f64)>,
    /// Time histories, if the model records any.
    pub histories: Vec<History>,
}

impl Outputs {
    /// Value of a named scalar.
    pub fn scalar(&self, name: &str) -> Option<f64> {
        self.scalars.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }

    /// Why these outputs cannot be kept as numbers: the first NaN or
    /// infinite scalar, else the first such sample of a history; `None`
    /// when every value is finite.
    pub fn non_finite(&self) -> Option<String> {
        if let Some((name, v)) = self.scalars.iter().find(|(_, v)| !v.is_finite()) {
            return Some(format!("non-finite output: {name} = {v}"));
        }
        self.histories.iter().find_map(History::non_finite)
    }
}

impl History {
    /// The first NaN or infinite sample, named by channel and row.
    fn non_finite(&self) -> Option<String> {
        // Blocks checked without a branch per sample; only a block that
        // holds a non-finite sample is searched for its first one.
        let block = self.data.chunks(BLOCK).position(|c| !all_finite(c))?;
        let i = block * BLOCK + self.data[block * BLOCK..].iter().position(|v| !v.is_finite())?;
        let width = self.channels.len().max(1);
        let channel = self.channels.get(i % width).map(String::as_str).unwrap_or("?");
        let (name, row, v) = (&self.name, i / width, self.data[i]);
        Some(format!("non-finite output: history {name}, channel {channel}, sample {row} = {v}"))
    }
}

/// Samples per block of the non-finite scan.
const BLOCK: usize = 256;

/// Whether every value of `block` is finite: `x * 0.0` is zero for a finite
/// `x` and NaN for an infinite or NaN one, and a NaN in any of the eight
/// running sums (independent, so the compiler vectorises them) stays NaN.
fn all_finite(block: &[f64]) -> bool {
    let mut sums = [0.0f64; 8];
    let mut lanes = block.chunks_exact(8);
    for eight in &mut lanes {
        for (s, v) in sums.iter_mut().zip(eight) {
            *s += v * 0.0;
        }
    }
    let rest: f64 = lanes.remainder().iter().map(|v| v * 0.0).sum();
    sums.iter().sum::<f64>() + rest == 0.0
}

impl Outcome {
    /// This outcome with non-finite outputs turned into a failure that
    /// names the first one (a NaN is a failed run, not a number to keep).
    pub fn finite_or_failed(self) -> Outcome {
        match &self {
            Outcome::Ok(out) => match out.non_finite() {
                Some(reason) => Outcome::Failed { reason },
                None => self,
            },
            Outcome::Failed { .. } => self,
        }
    }
}

/// The result of one run: outputs, or a failure kept as data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Outcome {
    /// The model ran to the end.
    Ok(Outputs),
    /// The model reported an error, panicked or timed out.
    Failed {
        /// Human-readable reason, e.g. `"newton: no convergence at t = 3.2 s"`.
        reason: String,
    },
}

/// A worker's answer to one task.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskResult {
    /// Which task this answers.
    pub id: TaskId,
    /// What happened.
    pub outcome: Outcome,
    /// Wall time the model took, in seconds.
    pub wall_s: f64,
    /// Host name of the worker.
    pub host: String,
}

/// Messages from the coordinator to a worker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ToWorker {
    /// Accepts the worker into a sweep and tells it the model to build.
    Welcome {
        /// Hash of the study's result-affecting keys (hex).
        study_hash: String,
        /// The model every following task runs.
        model: ModelSpec,
        /// The sweep's message key: every later message is sealed with it.
        key: crate::seal::SweepKey,
    },
    /// Refuses the worker, with the reason (e.g. a version mismatch).
    Refuse {
        /// Why the worker is not accepted.
        reason: String,
    },
    /// Run this task.
    Task(Task),
    /// Finish the current task, then exit.
    Shutdown,
}

/// Messages from a worker to the coordinator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum FromWorker {
    /// Announces a worker, its protocol version and how many tasks it may hold.
    Hello {
        /// Protocol version the worker was built with.
        proto: u16,
        /// Worker's name (unique per process).
        name: String,
        /// How many tasks it runs at once.
        threads: u32,
        /// The study it is pinned to (hash prefix), if any.
        study: Option<String>,
    },
    /// The answer to a task.
    Result(TaskResult),
    /// A task given back unrun (the worker is stopping); run it elsewhere.
    HandBack {
        /// The task.
        id: TaskId,
        /// Why.
        reason: String,
    },
    /// The worker stops; tasks it held are handed back.
    Goodbye,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outputs(y: f64, samples: Vec<f64>) -> Outputs {
        let history = History {
            name: "sensors".into(),
            dt_s: 0.01,
            channels: vec!["a".into(), "b".into()],
            data: samples,
        };
        Outputs { scalars: vec![("x".into(), 1.0), ("y".into(), y)], histories: vec![history] }
    }

    #[test]
    fn finite_outputs_stay_ok() {
        let ok = Outcome::Ok(outputs(2.0, vec![0.0, 1.0, 2.0, 3.0]));
        assert_eq!(ok.clone().finite_or_failed(), ok);
    }

    #[test]
    fn nan_scalar_is_a_failure_naming_it() {
        let out = Outcome::Ok(outputs(f64::NAN, vec![0.0; 4])).finite_or_failed();
        assert_eq!(out, Outcome::Failed { reason: "non-finite output: y = NaN".into() });
    }

    #[test]
    fn infinite_sample_is_a_failure_naming_channel_and_row() {
        let out =
            Outcome::Ok(outputs(1.0, vec![0.0, 1.0, 2.0, f64::NEG_INFINITY])).finite_or_failed();
        let reason = "non-finite output: history sensors, channel b, sample 1 = -inf";
        assert_eq!(out, Outcome::Failed { reason: reason.into() });
    }

    /// The scan goes by blocks of 256 samples: the first non-finite sample
    /// is found in any block, at either end of one, and before a later one.
    #[test]
    fn the_first_non_finite_sample_is_named_in_any_block() {
        for (at, later) in [(255, None), (256, None), (511, Some(600)), (1000, Some(1001))] {
            let mut data = vec![0.5; 1030];
            data[at] = f64::NAN;
            if let Some(j) = later {
                data[j] = f64::INFINITY;
            }
            let out = Outcome::Ok(outputs(1.0, data)).finite_or_failed();
            let (channel, row) = (["a", "b"][at % 2], at / 2);
            let reason = format!(
                "non-finite output: history sensors, channel {channel}, sample {row} = NaN"
            );
            assert_eq!(out, Outcome::Failed { reason }, "NaN at {at}");
        }
        let ok = Outcome::Ok(outputs(1.0, vec![0.5; 1030]));
        assert_eq!(ok.clone().finite_or_failed(), ok);
    }
}
