//! Progress for long sweeps: an indicatif bar with rate and ETA on a
//! terminal (hidden with `--quiet` or when stderr is not a TTY), and
//! tracing logs for retries, failures and membership.

use crate::farm::FarmObserver;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use protocol::{Outcome, TaskId, TaskResult, WorkerId};
use std::io::IsTerminal;

/// A progress bar over `total` tasks, `already` of them done before.
pub fn bar(total: u64, already: u64, quiet: bool, what: &str) -> ProgressBar {
    let target = if quiet || !std::io::stderr().is_terminal() {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    };
    let pb = ProgressBar::with_draw_target(Some(total), target);
    let style = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} {per_sec} ETA {eta}")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    pb.set_style(style);
    pb.set_message(what.to_string());
    pb.set_position(already);
    pb.reset_eta();
    pb
}

/// Farm observer that moves a bar and logs events.
pub struct SweepProgress {
    /// The bar.
    pub bar: ProgressBar,
    /// Failures so far.
    pub failed: usize,
}

impl FarmObserver for SweepProgress {
    fn finished(&mut self, r: &TaskResult) {
        if let Outcome::Failed { reason } = &r.outcome {
            self.failed += 1;
            tracing::warn!(task = r.id.0, %reason, "run failed");
        }
        self.bar.inc(1);
    }
    fn retrying(&mut self, task: TaskId, reason: &str) {
        tracing::info!(task = task.0, %reason, "retrying");
    }
    fn membership(&mut self, joined: bool, worker: WorkerId, detail: &str) {
        if joined {
            tracing::debug!(worker = worker.0, %detail, "worker joined");
        } else {
            tracing::info!(worker = worker.0, %detail, "worker left");
        }
    }
    // Rejected messages: the farm logs them itself (tracing warn).
}
