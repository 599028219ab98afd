//! The zenoh session's configuration: the lab's own zenoh JSON5 file (TLS
//! with mutual authentication, access control) when one is given, with the
//! farm's settings on top (mode, endpoint, no multicast scouting, the
//! message size limit), and the rule that a coordinator listens beyond the
//! loopback address only over TLS with mutual authentication unless it is
//! told `insecure`.
//!
//! Security is zenoh's, configured: this module never checks a certificate
//! itself; it only refuses a set-up that would let a stranger in.

use std::path::{Path, PathBuf};

/// Where a coordinator listens and workers connect when nothing says otherwise.
pub const DEFAULT_ENDPOINT: &str = "tcp/127.0.0.1:7447";

/// How a zenoh session is secured.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ZenohSecurity {
    /// A zenoh JSON5 configuration file (TLS, mTLS, access control, endpoints).
    pub config: Option<PathBuf>,
    /// Listen on a non-loopback address without mutual TLS all the same.
    pub insecure: bool,
}

/// Which end of the farm a session serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The coordinator: a peer that listens.
    Listen,
    /// A worker: a client that connects.
    Connect,
}

/// Why a zenoh configuration cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ZenohConfigError {
    /// The configuration file cannot be read or parsed.
    #[error("zenoh configuration {path}: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// zenoh's reason.
        message: String,
    },
    /// A setting the farm makes was refused by zenoh.
    #[error("zenoh setting {key} = {value}: {message}")]
    Setting {
        /// The configuration key.
        key: String,
        /// The value tried.
        value: String,
        /// zenoh's reason.
        message: String,
    },
    /// The coordinator would listen beyond loopback without mutual TLS.
    #[error(
        "refusing to listen on {endpoint} without TLS with mutual authentication: anyone who \
         reaches it could join the sweep. Give --zenoh-config FILE with a tls/ endpoint and \
         enable_mtls (see `ceilfarm farm certs`), listen on 127.0.0.1, or pass --insecure"
    )]
    Exposed {
        /// The endpoint refused.
        endpoint: String,
    },
}

/// The session configuration of `role` at `endpoint` (else the file's
/// endpoints, else [`DEFAULT_ENDPOINT`]) under `security`.
pub fn session_config(
    role: Role,
    endpoint: Option<&str>,
    security: &ZenohSecurity,
) -> Result<zenoh::Config, ZenohConfigError> {
    let mut cfg = match &security.config {
        Some(path) => read(path)?,
        None => zenoh::Config::default(),
    };
    let side = match role {
        Role::Listen => "listen/endpoints",
        Role::Connect => "connect/endpoints",
    };
    // zenoh's own defaults (a peer listens on every address) never count.
    let mut endpoints = match &security.config {
        Some(_) => endpoints_of(&cfg, side),
        None => Vec::new(),
    };
    if let Some(ep) = endpoint {
        endpoints = vec![ep.to_string()];
    }
    if endpoints.is_empty() {
        endpoints = vec![DEFAULT_ENDPOINT.to_string()];
    }
    let list = serde_json::to_string(&endpoints).unwrap_or_else(|_| "[]".into());
    match role {
        Role::Listen => {
            set(&mut cfg, "mode", "\"peer\"")?;
            set(&mut cfg, side, &list)?;
            if !security.insecure {
                let mtls = flag(&cfg, "transport/link/tls/enable_mtls");
                if let Some(ep) = endpoints.iter().find(|ep| !is_protected(ep, mtls)) {
                    return Err(ZenohConfigError::Exposed { endpoint: ep.clone() });
                }
            }
        }
        Role::Connect => {
            set(&mut cfg, "mode", "\"client\"")?;
            set(&mut cfg, side, &list)?;
            // Keep trying while the coordinator is not up yet, or restarts.
            set(&mut cfg, "connect/timeout_ms", "-1")?;
            set(&mut cfg, "connect/exit_on_failure", "false")?;
        }
    }
    set(&mut cfg, "scouting/multicast/enabled", "false")?;
    // zenoh reassembles fragments up to 1 GiB by default; no message of ours
    // is larger than the codec accepts.
    let max = crate::codec::MAX_MESSAGE_BYTES.to_string();
    set(&mut cfg, "transport/link/rx/max_message_size", &max)?;
    Ok(cfg)
}

fn read(path: &Path) -> Result<zenoh::Config, ZenohConfigError> {
    zenoh::Config::from_file(path)
        .map_err(|e| ZenohConfigError::Read { path: path.to_path_buf(), message: e.to_string() })
}

fn set(cfg: &mut zenoh::Config, key: &str, value: &str) -> Result<(), ZenohConfigError> {
    cfg.insert_json5(key, value).map_err(|e| ZenohConfigError::Setting {
        key: key.into(),
        value: value.into(),
        message: e.to_string(),
    })
}

fn flag(cfg: &zenoh::Config, key: &str) -> bool {
    cfg.get_json(key).is_ok_and(|v| v.trim() == "true")
}

/// The endpoints a configuration lists at `key` for this farm's side: a
/// plain list, or the peer's (listen) / client's (connect) list of a
/// mode-dependent value.
fn endpoints_of(cfg: &zenoh::Config, key: &str) -> Vec<String> {
    let Ok(json) = cfg.get_json(key) else { return Vec::new() };
    let value: serde_json::Value = serde_json::from_str(&json).unwrap_or_default();
    let mode = if key.starts_with("listen") { "peer" } else { "client" };
    let list = match &value {
        serde_json::Value::Object(by_mode) => by_mode.get(mode).cloned().unwrap_or_default(),
        other => other.clone(),
    };
    let items = list.as_array().cloned().unwrap_or_default();
    items.iter().filter_map(|v| v.as_str().map(str::to_string)).collect()
}

/// Whether listening on `endpoint` keeps strangers out: a loopback
/// address or a Unix socket, or TLS with mutual authentication (`mtls`).
pub fn is_protected(endpoint: &str, mtls: bool) -> bool {
    let (proto, rest) = endpoint.split_once('/').unwrap_or(("", endpoint));
    let address = rest.split(['?', '#']).next().unwrap_or(rest);
    match proto {
        "unixsock-stream" => true,
        "tls" if mtls => true,
        _ => is_loopback(address),
    }
}

/// Whether `address` (`host:port`) names this machine only.
fn is_loopback(address: &str) -> bool {
    if let Ok(socket) = address.parse::<std::net::SocketAddr>() {
        return socket.ip().is_loopback();
    }
    address.rsplit_once(':').is_some_and(|(host, _)| host.eq_ignore_ascii_case("localhost"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_and_unix_sockets_are_protected_without_tls() {
        for ep in ["tcp/127.0.0.1:7447", "tcp/127.9.9.9:1", "tcp/[::1]:7447", "tcp/localhost:7447"]
        {
            assert!(is_protected(ep, false), "{ep}");
        }
        assert!(is_protected("unixsock-stream//tmp/farm.sock", false));
    }

    #[test]
    fn a_lan_or_wildcard_address_needs_mutual_tls() {
        for ep in ["tcp/0.0.0.0:7447", "tcp/10.0.0.5:7447", "tcp/[::]:7447", "tcp/lab-pc:7447"] {
            assert!(!is_protected(ep, false), "{ep}");
            assert!(!is_protected(ep, true), "{ep}: tcp is never TLS");
        }
        assert!(!is_protected("tls/0.0.0.0:7447", false), "TLS without client certificates");
        assert!(is_protected("tls/0.0.0.0:7447", true));
        assert!(!is_protected("tcp/0.0.0.0:7447?x=1", false));
    }

    #[test]
    fn listening_on_the_lan_in_the_clear_is_refused_naming_address_and_flag() {
        let plain = ZenohSecurity::default();
        let err = session_config(Role::Listen, Some("tcp/0.0.0.0:7447"), &plain).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("tcp/0.0.0.0:7447") && text.contains("--insecure"), "{text}");
        let insecure = ZenohSecurity { config: None, insecure: true };
        assert!(session_config(Role::Listen, Some("tcp/0.0.0.0:7447"), &insecure).is_ok());
        assert!(session_config(Role::Listen, None, &plain).is_ok(), "default is loopback");
    }

    #[test]
    fn the_files_endpoints_are_used_unless_one_is_given() {
        let dir = std::env::temp_dir().join(format!("ceilfarm-zcfg-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("c.json5");
        let text = r#"{ listen: { endpoints: ["tcp/0.0.0.0:7999"] } }"#;
        std::fs::write(&file, text).unwrap();
        let sec = ZenohSecurity { config: Some(file.clone()), insecure: false };
        let err = session_config(Role::Listen, None, &sec).unwrap_err();
        assert!(err.to_string().contains("tcp/0.0.0.0:7999"), "{err}");
        let cfg = session_config(Role::Listen, Some("tcp/127.0.0.1:7999"), &sec).unwrap();
        assert!(cfg.get_json("listen/endpoints").unwrap().contains("127.0.0.1:7999"));
        let missing = ZenohSecurity { config: Some(dir.join("none.json5")), insecure: false };
        let err = session_config(Role::Connect, None, &missing).unwrap_err();
        assert!(err.to_string().contains("none.json5"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
