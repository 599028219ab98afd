//! The zenoh farm's key layout, one place for the transport that uses the
//! keys and the access control that guards them (`ceilfarm farm certs`).
//!
//! Under a sweep's prefix `ceilfarm/<first 16 hex digits of its study hash>`:
//!
//! | key | who declares / sends | what |
//! |---|---|---|
//! | `welcome` | the coordinator's queryable, its replies | a worker's Hello (a query on [`WELCOME_KEYS`]) and the Welcome |
//! | `task/<worker>` | the worker's queryable, its replies; the coordinator's queries | a sealed task and its sealed result |
//! | `alive/<worker>/<slots>` | the worker's liveliness token | membership |
//! | `coordinator` | the coordinator's liveliness token | workers see it leave |
//!
//! The `*_KEYS` patterns match a key of any sweep; the access control
//! grants each role exactly these, and a worker's own task and liveliness
//! keys only to the certificate of its name ([`own_task_keys`],
//! [`own_alive_keys`]).

/// First chunk of every key of the farm.
pub const ROOT: &str = "ceilfarm";

/// Every sweep's Welcome key: the coordinator's queryable and replies, and
/// what a worker queries to join.
pub const WELCOME_KEYS: &str = "ceilfarm/*/welcome";
/// Every worker's task key of every sweep (workers' queryables and
/// replies, the coordinator's queries).
pub const TASK_KEYS: &str = "ceilfarm/*/task/*";
/// Every worker's liveliness key of every sweep.
pub const ALIVE_KEYS: &str = "ceilfarm/*/alive/*/*";
/// Every sweep's coordinator liveliness key.
pub const COORDINATOR_KEYS: &str = "ceilfarm/*/coordinator";

/// Worker `name`'s task key of every sweep: what the access control lets
/// the certificate whose common name is `name` serve and answer, and the
/// only task queries it passes to it.
pub fn own_task_keys(name: &str) -> String {
    format!("{ROOT}/*/task/{name}")
}

/// Worker `name`'s liveliness keys of every sweep (any slot count): the
/// only tokens the certificate whose common name is `name` may declare.
pub fn own_alive_keys(name: &str) -> String {
    format!("{ROOT}/*/alive/{name}/*")
}

/// Key prefix of a sweep: the first 16 hex digits of its study hash.
pub fn sweep_prefix(study_hash: &str) -> String {
    format!("{ROOT}/{}", &study_hash[..study_hash.len().min(16)])
}

/// The Welcome key of the sweep at `prefix`.
pub fn welcome_key(prefix: &str) -> String {
    format!("{prefix}/welcome")
}

/// The task key of worker `name` (a [`crate::membership::safe_name`]).
pub fn task_key(prefix: &str, name: &str) -> String {
    format!("{prefix}/task/{name}")
}

/// The liveliness key of worker `name_slots` (`<name>/<slots>`).
pub fn alive_key(prefix: &str, name_slots: &str) -> String {
    format!("{prefix}/alive/{name_slots}")
}

/// Every liveliness key of the sweep's workers (the coordinator's subscriber).
pub fn alive_keys(prefix: &str) -> String {
    format!("{prefix}/alive/**")
}

/// The coordinator's liveliness key of the sweep at `prefix`.
pub fn coordinator_key(prefix: &str) -> String {
    format!("{prefix}/coordinator")
}

#[cfg(all(test, feature = "zenoh"))]
mod tests {
    use super::*;
    use zenoh::key_expr::KeyExpr;

    fn includes(pattern: &str, key: &str) -> bool {
        let p = KeyExpr::try_from(pattern.to_string()).unwrap();
        p.includes(&KeyExpr::try_from(key.to_string()).unwrap())
    }

    #[test]
    fn each_pattern_holds_its_own_keys_and_no_other_roles() {
        let prefix = sweep_prefix(&"ab12".repeat(16));
        assert_eq!(prefix, "ceilfarm/ab12ab12ab12ab12");
        let keys = [
            (WELCOME_KEYS, welcome_key(&prefix)),
            (TASK_KEYS, task_key(&prefix, "lab-pc_7")),
            (ALIVE_KEYS, alive_key(&prefix, "lab-pc_7/4")),
            (COORDINATOR_KEYS, coordinator_key(&prefix)),
        ];
        for (i, (pattern, _)) in keys.iter().enumerate() {
            for (j, (_, key)) in keys.iter().enumerate() {
                assert_eq!(includes(pattern, key), i == j, "{pattern} vs {key}");
            }
        }
        assert!(!includes(TASK_KEYS, &alive_keys(&prefix)));
    }

    #[test]
    fn a_workers_own_keys_hold_its_keys_and_no_other_workers() {
        let prefix = sweep_prefix(&"ab12".repeat(16));
        let (own, other) = ("ceilfarm-worker-1", "ceilfarm-worker-2");
        assert!(includes(&own_task_keys(own), &task_key(&prefix, own)));
        assert!(includes(&own_alive_keys(own), &alive_key(&prefix, &format!("{own}/4"))));
        for key in [task_key(&prefix, other), task_key(&prefix, "ceilfarm-worker-10")] {
            assert!(!includes(&own_task_keys(own), &key), "{key}");
        }
        assert!(!includes(&own_task_keys(own), TASK_KEYS), "a wildcard is not its own key");
        assert!(!includes(&own_alive_keys(own), &alive_key(&prefix, &format!("{other}/4"))));
        assert!(includes(TASK_KEYS, &own_task_keys(own)));
        assert!(includes(ALIVE_KEYS, &own_alive_keys(own)));
    }
}
