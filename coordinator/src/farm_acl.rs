//! The coordinator's access control, as `ceilfarm farm certs` writes it
//! into zenoh's configuration: everything is denied by default; the listed
//! worker certificates (by common name) share a worker's role
//! ([`ROLE_GRANTS`]: ask for a Welcome, watch the coordinator's
//! liveliness), and each may serve, answer and announce only the keys of
//! the worker its certificate names ([`OWN_GRANTS`]: `task/<name>`,
//! `alive/<name>/<slots>`), so a stolen listed certificate cannot answer
//! another worker's tasks. Only the coordinator answers a Hello or sends a
//! task: workers are zenoh clients of the coordinator's peer, so a message
//! from one worker to another passes both checks there, and the
//! coordinator's own session is no remote subject.
//!
//! zenoh's rules allow a message only when one of its subject's rules has
//! a key expression that includes the message's key
//! (`policy_decision_point`: `nodes_including`), so a wildcard declaration
//! such as `ceilfarm/*/task/*` is refused too.

use protocol::zenoh_keys as keys;
use serde_json::{json, Value};

/// The keys one grant covers.
#[derive(Clone, Copy)]
enum Keys {
    /// The same pattern for every listed worker.
    Role(&'static str),
    /// A pattern of the worker's own name (its certificate's common name).
    Own(fn(&str) -> String),
}

/// One use of the farm's keys the access control allows a listed worker.
struct Grant {
    /// `ingress`: the worker's own messages as the coordinator receives
    /// them; `egress`: what the coordinator passes on to a worker.
    flow: &'static str,
    /// zenoh's message kinds.
    messages: &'static [&'static str],
    /// The keys (see [`protocol::zenoh_keys`]).
    keys: Keys,
}

/// What every listed worker may do: ask for a Welcome and watch the
/// coordinator's liveliness; it hears only Welcomes and the coordinator's
/// liveliness.
const ROLE_GRANTS: [Grant; 4] = [
    Grant { flow: "ingress", messages: &["query"], keys: Keys::Role(keys::WELCOME_KEYS) },
    Grant {
        flow: "ingress",
        messages: &["declare_liveliness_subscriber"],
        keys: Keys::Role(keys::COORDINATOR_KEYS),
    },
    Grant {
        flow: "egress",
        messages: &["declare_queryable", "reply"],
        keys: Keys::Role(keys::WELCOME_KEYS),
    },
    Grant {
        flow: "egress",
        messages: &["liveliness_token"],
        keys: Keys::Role(keys::COORDINATOR_KEYS),
    },
];

/// What a listed worker may do on its own keys only: serve and answer the
/// task queries of its name, announce its liveliness under its name; it
/// hears only the task queries sent to its name.
const OWN_GRANTS: [Grant; 3] = [
    Grant {
        flow: "ingress",
        messages: &["declare_queryable", "reply"],
        keys: Keys::Own(keys::own_task_keys),
    },
    Grant {
        flow: "ingress",
        messages: &["liveliness_token"],
        keys: Keys::Own(keys::own_alive_keys),
    },
    Grant { flow: "egress", messages: &["query"], keys: Keys::Own(keys::own_task_keys) },
];

/// Subject id of every listed worker.
const WORKERS: &str = "workers";

/// Subject and policy id of the worker with certificate common name `name`.
fn own_subject(name: &str) -> String {
    format!("worker:{name}")
}

/// zenoh's rules for `grants` under ids `<prefix>-<flow>-<n>`, with `name`
/// filling the grants of a worker's own keys.
fn rules(grants: &[Grant], prefix: &str, name: &str) -> Vec<Value> {
    grants
        .iter()
        .enumerate()
        .map(|(n, g)| {
            let key = match g.keys {
                Keys::Role(pattern) => pattern.to_string(),
                Keys::Own(pattern) => pattern(name),
            };
            json!({
                "id": format!("{prefix}-{}-{}", g.flow, n + 1),
                "permission": "allow",
                "flows": [g.flow],
                "messages": g.messages,
                "key_exprs": [key],
            })
        })
        .collect()
}

fn ids(rules: &[Value]) -> Vec<String> {
    rules.iter().filter_map(|r| r["id"].as_str().map(str::to_string)).collect()
}

/// zenoh's `access_control` section for `workers` (certificate common
/// names, each a worker's name as [`protocol::membership::safe_name`]
/// leaves it): default deny, [`ROLE_GRANTS`] to them all and
/// [`OWN_GRANTS`] to each for its own name.
pub fn access_control(workers: &[String]) -> Value {
    let role = rules(&ROLE_GRANTS, "worker", "");
    let mut policies = vec![json!({ "id": WORKERS, "rules": ids(&role), "subjects": [WORKERS] })];
    let mut subjects = vec![json!({ "id": WORKERS, "cert_common_names": workers })];
    let mut all_rules = role;
    for name in workers {
        let subject = own_subject(name);
        let own = rules(&OWN_GRANTS, &subject, name);
        policies.push(json!({ "id": subject, "rules": ids(&own), "subjects": [subject] }));
        subjects.push(json!({ "id": subject, "cert_common_names": [name] }));
        all_rules.extend(own);
    }
    json!({
        "enabled": true,
        "default_permission": "deny",
        "rules": all_rules,
        "subjects": subjects,
        "policies": policies,
    })
}

#[cfg(all(test, feature = "zenoh"))]
mod tests {
    use super::*;
    use zenoh::key_expr::KeyExpr;

    fn ke(k: &str) -> KeyExpr<'static> {
        KeyExpr::try_from(k.to_string()).unwrap()
    }

    fn strings(v: &Value) -> Vec<String> {
        v.as_array().unwrap().iter().map(|s| s.as_str().unwrap().to_string()).collect()
    }

    /// Every (flow, message, key pattern) the section allows `name`.
    fn allowed(acl: &Value, name: &str) -> Vec<(String, String, String)> {
        let subjects: Vec<String> = acl["subjects"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|s| strings(&s["cert_common_names"]).iter().any(|n| n == name))
            .map(|s| s["id"].as_str().unwrap().to_string())
            .collect();
        let mut out = Vec::new();
        for policy in acl["policies"].as_array().unwrap() {
            if !strings(&policy["subjects"]).iter().any(|s| subjects.contains(s)) {
                continue;
            }
            for id in strings(&policy["rules"]) {
                let rule = acl["rules"].as_array().unwrap().iter().find(|r| r["id"] == id.as_str());
                let rule = rule.unwrap();
                assert_eq!(rule["permission"], "allow");
                for flow in strings(&rule["flows"]) {
                    for message in strings(&rule["messages"]) {
                        for key in strings(&rule["key_exprs"]) {
                            out.push((flow.clone(), message.clone(), key));
                        }
                    }
                }
            }
        }
        out
    }

    /// Whether `acl` lets `name` do `message` on `key` in `flow`, as zenoh
    /// decides: an allowing rule whose key expression includes the key.
    fn may(acl: &Value, name: &str, flow: &str, message: &str, key: &str) -> bool {
        allowed(acl, name)
            .iter()
            .any(|(f, m, k)| f == flow && m == message && ke(k).includes(&ke(key)))
    }

    #[test]
    fn a_worker_serves_and_announces_only_its_own_name() {
        let names: Vec<String> = (1..=3).map(|k| format!("ceilfarm-worker-{k}")).collect();
        let acl = access_control(&names);
        let prefix = keys::sweep_prefix(&"ab12".repeat(16));
        for me in &names {
            for them in &names {
                let own = me == them;
                let task = keys::task_key(&prefix, them);
                let alive = keys::alive_key(&prefix, &format!("{them}/2"));
                assert_eq!(may(&acl, me, "ingress", "declare_queryable", &task), own);
                assert_eq!(may(&acl, me, "ingress", "reply", &task), own);
                assert_eq!(may(&acl, me, "egress", "query", &task), own);
                assert_eq!(may(&acl, me, "ingress", "liveliness_token", &alive), own);
            }
            assert!(!may(&acl, me, "ingress", "declare_queryable", keys::TASK_KEYS));
            assert!(may(&acl, me, "ingress", "query", &keys::welcome_key(&prefix)));
            assert!(may(&acl, me, "egress", "reply", keys::WELCOME_KEYS));
        }
        assert!(allowed(&acl, "ceilfarm-visitor").is_empty());
        assert_eq!(acl["default_permission"], "deny");
    }

    #[test]
    fn no_worker_may_answer_a_hello_send_a_task_or_put() {
        let names = vec!["ceilfarm-worker-1".to_string()];
        let acl = access_control(&names);
        let (welcome, tasks) = (ke(keys::WELCOME_KEYS), ke(keys::TASK_KEYS));
        for (flow, message, key) in allowed(&acl, &names[0]) {
            let key = ke(&key);
            assert!(!["put", "delete"].contains(&message.as_str()), "{message} on {key}");
            if flow == "ingress" {
                let coordinators = ["reply", "declare_queryable"];
                let answers_hello =
                    coordinators.contains(&message.as_str()) && key.intersects(&welcome);
                let sends_task = message == "query" && key.intersects(&tasks);
                assert!(!answers_hello && !sends_task, "{message} on {key}");
            }
        }
    }

    #[test]
    fn rule_subject_and_policy_ids_are_unique() {
        let names: Vec<String> = (1..=20).map(|k| format!("ceilfarm-worker-{k}")).collect();
        let acl = access_control(&names);
        for section in ["rules", "subjects", "policies"] {
            let mut ids: Vec<&str> = acl[section]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v["id"].as_str().unwrap())
                .collect();
            let n = ids.len();
            ids.sort_unstable();
            ids.dedup();
            assert_eq!(ids.len(), n, "{section}");
        }
        assert_eq!(acl["policies"].as_array().unwrap().len(), 21);
    }
}
