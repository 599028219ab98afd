//! Who the workers of a sweep are, on a transport that sees them through
//! liveliness tokens (zenoh): a token makes a worker only when its name was
//! admitted by a Hello first; a token alone is rejected, so it can never be
//! leased a task, and so can never lose one.

use crate::transport::{TransportEvent, WorkerId};
use std::collections::{HashMap, HashSet};

/// Most worker names one sweep admits (bounds memory against a flood of Hellos).
pub const MAX_ADMITTED: usize = 4096;

/// Most tasks one worker may announce it holds at once.
pub const MAX_SLOTS: usize = 1024;

/// Why a Hello was not admitted.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AdmitError {
    /// Already [`MAX_ADMITTED`] names.
    #[error("too many workers in this sweep ({0} admitted)")]
    Full(usize),
}

/// A key-expression-safe worker name.
pub fn safe_name(name: &str) -> String {
    name.chars()
        .map(
            |c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' { c } else { '_' },
        )
        .collect()
}

/// Admitted names, joined workers and their ids.
#[derive(Debug, Default)]
pub struct Members {
    admitted: HashSet<String>,
    by_name: HashMap<String, WorkerId>,
    names: HashMap<WorkerId, String>,
    next_id: u64,
}

impl Members {
    /// Admits a worker that said Hello as `name`; its token carries [`safe_name`] of it.
    pub fn admit(&mut self, name: &str) -> Result<(), AdmitError> {
        let name = safe_name(name);
        if !self.admitted.contains(&name) && self.admitted.len() >= MAX_ADMITTED {
            return Err(AdmitError::Full(self.admitted.len()));
        }
        self.admitted.insert(name);
        Ok(())
    }

    /// A liveliness token `<name>/<slots>` appeared: the worker joins if
    /// admitted, is rejected if not, and nothing happens if already joined.
    pub fn appeared(&mut self, key: &str) -> Option<TransportEvent> {
        let Some((name, slots)) = key.split_once('/') else {
            return Some(rejected(format!("liveliness token {key:?} is not <name>/<slots>")));
        };
        if !self.admitted.contains(name) {
            return Some(rejected(format!("liveliness token of {name:?} without a Hello")));
        }
        if self.by_name.contains_key(name) {
            return None;
        }
        let slots = slots.parse::<usize>().unwrap_or(1).clamp(1, MAX_SLOTS);
        let worker = WorkerId(self.next_id);
        self.next_id += 1;
        self.by_name.insert(name.to_string(), worker);
        self.names.insert(worker, name.to_string());
        Some(TransportEvent::Joined { worker, name: name.to_string(), slots })
    }

    /// A liveliness token `<name>/<slots>` vanished: a joined worker leaves.
    pub fn vanished(&mut self, key: &str) -> Option<TransportEvent> {
        let name = key.split_once('/').map_or(key, |(name, _)| name);
        let worker = self.by_name.remove(name)?;
        self.names.remove(&worker);
        Some(TransportEvent::Left { worker, reason: "liveliness lost".into() })
    }

    /// The key-safe name of a joined worker.
    pub fn name(&self, worker: WorkerId) -> Option<&str> {
        self.names.get(&worker).map(String::as_str)
    }

    /// Forgets a joined worker until its token appears again.
    pub fn forget(&mut self, worker: WorkerId) {
        if let Some(name) = self.names.remove(&worker) {
            self.by_name.remove(&name);
        }
    }
}

fn rejected(reason: String) -> TransportEvent {
    TransportEvent::Rejected { reason }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_token_without_a_hello_is_rejected() {
        let mut m = Members::default();
        for i in 0..100 {
            let ev = m.appeared(&format!("fake{i}/1"));
            assert!(matches!(ev, Some(TransportEvent::Rejected { .. })), "{ev:?}");
        }
        assert_eq!(m.name(WorkerId(0)), None);
        assert_eq!(m.vanished("fake1/1"), None);
    }

    #[test]
    fn a_token_after_a_hello_joins_once_and_leaves() {
        let mut m = Members::default();
        m.admit("host a:1").unwrap();
        let ev = m.appeared("host_a_1/4");
        let joined =
            TransportEvent::Joined { worker: WorkerId(0), name: "host_a_1".into(), slots: 4 };
        assert_eq!(ev, Some(joined));
        assert_eq!(m.appeared("host_a_1/4"), None);
        assert_eq!(m.name(WorkerId(0)), Some("host_a_1"));
        assert!(matches!(m.vanished("host_a_1/4"), Some(TransportEvent::Left { .. })));
        assert_eq!(m.name(WorkerId(0)), None);
    }

    #[test]
    fn hostile_slots_are_clamped_and_admission_is_bounded() {
        let mut m = Members::default();
        m.admit("w").unwrap();
        let ev = m.appeared("w/99999999999999999999");
        assert!(matches!(ev, Some(TransportEvent::Joined { slots: 1, .. })), "{ev:?}");
        for i in 1..MAX_ADMITTED {
            m.admit(&format!("w{i}")).unwrap();
        }
        assert_eq!(m.admit("one-more"), Err(AdmitError::Full(MAX_ADMITTED)));
        assert_eq!(m.admit("w"), Ok(()));
    }
}
