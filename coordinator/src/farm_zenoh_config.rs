//! The zenoh JSON5 configurations `ceilfarm farm certs` writes: the
//! coordinator's (a TLS listener demanding client certificates from the
//! lab's CA, access control denying everything to anyone but the listed
//! worker common names, and to them everything but a worker's role, so no
//! worker can answer another's Hello or send a task) and a worker's (a TLS
//! connection to the coordinator with its own certificate, checking the
//! coordinator's name). Certificates
//! and keys are inline (base64 of their PEM), so one file is all a machine
//! needs. JSON is JSON5, so the files are serde_json's output under a
//! comment header.

use crate::farm_certs::Identity;
use base64::Engine;
use protocol::zenoh_keys as keys;
use serde_json::{json, Value};

/// One use of the farm's keys the access control allows a listed worker.
struct Grant {
    /// `ingress`: the worker's own messages as the coordinator receives
    /// them; `egress`: what the coordinator passes on to a worker.
    flow: &'static str,
    /// zenoh's message kinds.
    messages: &'static [&'static str],
    /// The keys (see [`protocol::zenoh_keys`]).
    key_expr: &'static str,
}

/// A worker's role, all it is granted: it may ask for a Welcome, serve and
/// answer task queries, announce its liveliness and watch the
/// coordinator's; it hears only Welcomes, task queries and the
/// coordinator's liveliness. Only the coordinator answers a Hello or sends
/// a task: workers are zenoh clients of the coordinator's peer, so a
/// message from one worker to another passes both checks there, and the
/// coordinator's own session is no remote subject.
const WORKER_GRANTS: [Grant; 7] = [
    Grant { flow: "ingress", messages: &["query"], key_expr: keys::WELCOME_KEYS },
    Grant { flow: "ingress", messages: &["declare_queryable", "reply"], key_expr: keys::TASK_KEYS },
    Grant { flow: "ingress", messages: &["liveliness_token"], key_expr: keys::ALIVE_KEYS },
    Grant {
        flow: "ingress",
        messages: &["declare_liveliness_subscriber"],
        key_expr: keys::COORDINATOR_KEYS,
    },
    Grant {
        flow: "egress",
        messages: &["declare_queryable", "reply"],
        key_expr: keys::WELCOME_KEYS,
    },
    Grant { flow: "egress", messages: &["query"], key_expr: keys::TASK_KEYS },
    Grant { flow: "egress", messages: &["liveliness_token"], key_expr: keys::COORDINATOR_KEYS },
];

/// The access control's rules, one per grant (`worker-<flow>-<n>`), and their ids.
fn worker_rules() -> (Vec<Value>, Vec<String>) {
    let rules: Vec<Value> = WORKER_GRANTS
        .iter()
        .enumerate()
        .map(|(n, g)| {
            json!({
                "id": format!("worker-{}-{}", g.flow, n + 1),
                "permission": "allow",
                "flows": [g.flow],
                "messages": g.messages,
                "key_exprs": [g.key_expr],
            })
        })
        .collect();
    let ids = rules.iter().filter_map(|r| r["id"].as_str().map(str::to_string)).collect();
    (rules, ids)
}

fn b64(pem: &str) -> String {
    base64::engine::general_purpose::STANDARD.encode(pem)
}

fn json5(header: &str, v: &Value) -> String {
    let body = serde_json::to_string_pretty(v).unwrap_or_default();
    format!("// {header}\n// Holds a private key: keep it readable by its owner only.\n{body}\n")
}

/// The coordinator's configuration: listen on `listen` (a `tls/` endpoint)
/// with mutual TLS; only `workers` (certificate common names) may use the
/// farm's keys, each only in a worker's role ([`WORKER_GRANTS`]); everyone
/// else is denied.
pub fn coordinator_config(ca_pem: &str, id: &Identity, listen: &str, workers: &[String]) -> String {
    let (rules, rule_ids) = worker_rules();
    let v = json!({
        "listen": { "endpoints": [listen] },
        "transport": { "link": {
            "protocols": ["tls"],
            "tls": {
                "root_ca_certificate_base64": b64(ca_pem),
                "listen_certificate_base64": b64(&id.cert_pem),
                "listen_private_key_base64": b64(&id.key_pem),
                "enable_mtls": true,
                "close_link_on_expiration": true,
            },
        }},
        "access_control": {
            "enabled": true,
            "default_permission": "deny",
            "rules": rules,
            "subjects": [{ "id": "workers", "cert_common_names": workers }],
            "policies": [{ "rules": rule_ids, "subjects": ["workers"] }],
        },
    });
    json5(
        &format!(
            "ceilfarm coordinator ({}): TLS, mutual authentication, access control",
            id.common_name
        ),
        &v,
    )
}

/// A worker's configuration: connect to `connect` (a `tls/` endpoint) with
/// its certificate, trusting the lab's CA and checking the coordinator's name.
pub fn worker_config(ca_pem: &str, id: &Identity, connect: &str) -> String {
    let v = json!({
        "connect": { "endpoints": [connect] },
        "transport": { "link": {
            "protocols": ["tls"],
            "tls": {
                "root_ca_certificate_base64": b64(ca_pem),
                "connect_certificate_base64": b64(&id.cert_pem),
                "connect_private_key_base64": b64(&id.key_pem),
                "enable_mtls": true,
                "verify_name_on_connect": true,
            },
        }},
    });
    json5(&format!("ceilfarm worker {}: TLS with its own certificate", id.common_name), &v)
}

#[cfg(all(test, feature = "zenoh"))]
mod tests {
    use super::*;
    use crate::farm_certs::{LabCa, Validity};
    use protocol::zenoh_config::{session_config, Role, ZenohSecurity};

    fn file(path: &std::path::Path) -> ZenohSecurity {
        ZenohSecurity { config: Some(path.to_path_buf()), insecure: false }
    }

    #[test]
    fn zenoh_reads_both_configurations_with_mtls_and_a_default_deny() {
        let v = Validity::from_now(1);
        let ca = LabCa::new("test CA", &v).unwrap();
        let c = ca.issue("ceilfarm-coordinator", &["localhost".into()], &v).unwrap();
        let w = ca.issue("ceilfarm-worker-1", &[], &v).unwrap();
        let workers = vec![w.common_name.clone()];
        let dir = tempfile::tempdir().unwrap();
        let cfile = dir.path().join("c.json5");
        std::fs::write(&cfile, coordinator_config(ca.cert_pem(), &c, "tls/0.0.0.0:7447", &workers))
            .unwrap();
        // Listening on 0.0.0.0 passes the exposure rule: TLS with mutual authentication.
        let cfg = session_config(Role::Listen, None, &file(&cfile)).unwrap();
        assert_eq!(cfg.get_json("transport/link/tls/enable_mtls").unwrap(), "true");
        assert_eq!(cfg.get_json("access_control/default_permission").unwrap(), "\"deny\"");
        let subjects = cfg.get_json("access_control/subjects").unwrap();
        assert!(subjects.contains("ceilfarm-worker-1"), "{subjects}");
        let wfile = dir.path().join("w.json5");
        std::fs::write(&wfile, worker_config(ca.cert_pem(), &w, "tls/localhost:7447")).unwrap();
        let cfg = session_config(Role::Connect, None, &file(&wfile)).unwrap();
        assert!(cfg.get_json("connect/endpoints").unwrap().contains("tls/localhost:7447"));
    }

    #[test]
    fn no_worker_may_answer_a_hello_send_a_task_or_put() {
        use zenoh::key_expr::KeyExpr;
        let ke = |k: &str| KeyExpr::try_from(k.to_string()).unwrap();
        let (welcome, tasks) = (ke(keys::WELCOME_KEYS), ke(keys::TASK_KEYS));
        let (rules, ids) = worker_rules();
        assert_eq!(ids.len(), WORKER_GRANTS.len());
        for rule in &rules {
            let flows: Vec<&str> =
                rule["flows"].as_array().unwrap().iter().map(|f| f.as_str().unwrap()).collect();
            let messages: Vec<&str> =
                rule["messages"].as_array().unwrap().iter().map(|m| m.as_str().unwrap()).collect();
            for key in rule["key_exprs"].as_array().unwrap() {
                let key = ke(key.as_str().unwrap());
                assert!(!messages.iter().any(|m| ["put", "delete"].contains(m)), "{rule}");
                if flows.contains(&"ingress") {
                    let coordinators = ["reply", "declare_queryable"];
                    let answers_hello = messages.iter().any(|m| coordinators.contains(m))
                        && key.intersects(&welcome);
                    let sends_task = messages.contains(&"query") && key.intersects(&tasks);
                    assert!(!answers_hello && !sends_task, "{rule}");
                }
            }
        }
    }
}
