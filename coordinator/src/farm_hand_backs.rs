//! How often a task may be handed back before a hand-back counts as a
//! failed attempt of that task.

use protocol::{TaskId, WorkerId};
use std::collections::HashMap;

/// Hand-backs of one task in one batch that cost no try.
///
/// An honest worker hands a task back only when it stops while holding it,
/// so a task is handed back once per worker that stopped holding it: a
/// rolling restart of a lab gives one or two. Beyond this bound, and on a
/// second hand-back of one task by one worker (an honest worker stops
/// once), a hand-back is a failed attempt. A worker that hands everything
/// back, broken or hostile, so costs each task at most
/// `(MAX_FREE_HAND_BACKS_PER_TASK + 1) * (max_retries + 1)` sends instead of
/// an endless loop (issue 56: 65 000 resends in 12 s).
pub const MAX_FREE_HAND_BACKS_PER_TASK: usize = 3;

/// What one hand-back costs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum HandBackVerdict {
    /// Within the bound: the task goes back to the queue, no try counted.
    Free,
    /// Over the bound: the hand-back is a failed attempt, with this reason.
    FailedAttempt(String),
}

/// The workers that handed each task back, in this batch.
#[derive(Debug, Default)]
pub struct HandBacks {
    by_task: HashMap<TaskId, Vec<WorkerId>>,
}

impl HandBacks {
    /// Records that `worker` handed `task` back and says what it costs.
    pub fn record(&mut self, task: TaskId, worker: WorkerId) -> HandBackVerdict {
        let seen = self.by_task.entry(task).or_default();
        if seen.contains(&worker) {
            return HandBackVerdict::FailedAttempt(format!("{worker} handed {task} back twice"));
        }
        if seen.len() >= MAX_FREE_HAND_BACKS_PER_TASK {
            let n = MAX_FREE_HAND_BACKS_PER_TASK;
            return HandBackVerdict::FailedAttempt(format!(
                "{task} handed back more than {n} times"
            ));
        }
        seen.push(worker);
        HandBackVerdict::Free
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_hand_back_per_worker_and_a_few_per_task_are_free() {
        let mut h = HandBacks::default();
        let t = TaskId(1);
        assert_eq!(h.record(t, WorkerId(0)), HandBackVerdict::Free);
        assert!(matches!(h.record(t, WorkerId(0)), HandBackVerdict::FailedAttempt(_)));
        for w in 1..MAX_FREE_HAND_BACKS_PER_TASK as u64 {
            assert_eq!(h.record(t, WorkerId(w)), HandBackVerdict::Free);
        }
        assert!(matches!(h.record(t, WorkerId(99)), HandBackVerdict::FailedAttempt(_)));
        assert_eq!(h.record(TaskId(2), WorkerId(0)), HandBackVerdict::Free);
    }
}
