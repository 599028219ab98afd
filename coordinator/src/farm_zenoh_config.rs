//! The zenoh JSON5 configurations `ceilfarm farm certs` writes: the
//! coordinator's (a TLS listener demanding client certificates from the
//! lab's CA, and the access control of [`crate::farm_acl`]: everything
//! denied to anyone but the listed worker common names, and to each of
//! them everything but a worker's role on its own keys) and a worker's (a
//! TLS connection to the coordinator with its own certificate, checking
//! the coordinator's name; the worker's name is its certificate's common
//! name). Certificates and keys are inline (base64 of their PEM), so one
//! file is all a machine needs. JSON is JSON5, so the files are
//! serde_json's output under a comment header.

use crate::farm_acl::access_control;
use crate::farm_certs::Identity;
use base64::Engine;
use serde_json::{json, Value};

fn b64(pem: &str) -> String {
    base64::engine::general_purpose::STANDARD.encode(pem)
}

fn json5(header: &str, v: &Value) -> String {
    let body = serde_json::to_string_pretty(v).unwrap_or_default();
    format!("// {header}\n// Holds a private key: keep it readable by its owner only.\n{body}\n")
}

/// The coordinator's configuration: listen on `listen` (a `tls/` endpoint)
/// with mutual TLS; only `workers` (certificate common names) may use the
/// farm's keys, each only in a worker's role and on its own name's keys
/// ([`access_control`]); everyone else is denied.
pub fn coordinator_config(ca_pem: &str, id: &Identity, listen: &str, workers: &[String]) -> String {
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
        "access_control": access_control(workers),
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
/// its certificate, trusting the lab's CA and checking the coordinator's
/// name. The worker takes its name from the certificate's common name
/// (`protocol::zenoh_identity`).
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
    use zenoh::Wait;

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
        // zenoh checks the access control's ids and references when it opens.
        let local = session_config(Role::Listen, Some("tls/127.0.0.1:0"), &file(&cfile)).unwrap();
        let session = zenoh::open(local).wait().expect("zenoh accepts the access control");
        session.close().wait().unwrap();
        let wfile = dir.path().join("w.json5");
        std::fs::write(&wfile, worker_config(ca.cert_pem(), &w, "tls/localhost:7447")).unwrap();
        let cfg = session_config(Role::Connect, None, &file(&wfile)).unwrap();
        assert!(cfg.get_json("connect/endpoints").unwrap().contains("tls/localhost:7447"));
    }
}
