//! A worker's name under mutual TLS: the common name of the certificate its
//! zenoh configuration presents. The coordinator's access control (as
//! `ceilfarm farm certs` writes it) lets a certificate serve only the task
//! key of the worker its common name names, and announce only that
//! worker's liveliness ([`crate::zenoh_keys::own_task_keys`]), so a worker
//! must announce that name: it takes it from the certificate, and refuses
//! a `--name` that differs before it connects, instead of joining and
//! never being heard.
//!
//! The common name is read as zenoh's TLS link reads it for the access
//! control: the first common name of the first certificate presented
//! (`connect_certificate_base64`, else the file `connect_certificate`).

use crate::membership::safe_name;
use crate::zenoh_config::ZenohSecurity;
use base64::Engine;
use std::path::{Path, PathBuf};

/// Where a worker's configuration holds its certificate: inline, then as a file.
const CERTIFICATE_KEYS: [&str; 2] =
    ["transport/link/tls/connect_certificate_base64", "transport/link/tls/connect_certificate"];

/// Why a worker's name cannot be settled.
#[derive(Debug, thiserror::Error)]
pub enum IdentityError {
    /// The configuration file cannot be read or parsed.
    #[error("zenoh configuration {path}: {message}")]
    Read {
        /// The configuration file.
        path: PathBuf,
        /// zenoh's or the file system's reason.
        message: String,
    },
    /// The certificate the configuration names is no PEM X.509 certificate.
    #[error("zenoh configuration {path}: {key}: {message}")]
    Certificate {
        /// The configuration file.
        path: PathBuf,
        /// The configuration key holding the certificate.
        key: &'static str,
        /// What is wrong with it.
        message: String,
    },
    /// The certificate's common name cannot be a worker's name.
    #[error(
        "zenoh configuration {path}: the certificate's common name {name:?} cannot name a \
         worker (letters, digits, '-', '_' and '.' only): the access control grants a \
         certificate the task key of its common name"
    )]
    UnusableName {
        /// The configuration file.
        path: PathBuf,
        /// The common name.
        name: String,
    },
    /// `--name` differs from the certificate's common name.
    #[error(
        "--name {requested}: the certificate in {path} is worker {certified}'s, and the \
         coordinator lets it serve only that worker's tasks; leave out --name or give \
         --name {certified}"
    )]
    NameMismatch {
        /// The name asked for.
        requested: String,
        /// The certificate's common name.
        certified: String,
        /// The configuration file.
        path: PathBuf,
    },
}

/// The name a worker under `security` announces: its certificate's common
/// name when its configuration presents one (`requested`, if given, must
/// equal it), else `requested` (`None`: the caller's default).
pub fn worker_name(
    security: &ZenohSecurity,
    requested: Option<&str>,
) -> Result<Option<String>, IdentityError> {
    let Some(path) = &security.config else { return Ok(requested.map(str::to_string)) };
    let Some(certified) = certificate_name(path)? else {
        return Ok(requested.map(str::to_string));
    };
    match requested {
        Some(name) if name != certified => Err(IdentityError::NameMismatch {
            requested: name.to_string(),
            certified,
            path: path.clone(),
        }),
        _ => Ok(Some(certified)),
    }
}

/// The common name of the certificate the configuration at `path`
/// presents when it connects, if it presents one.
pub fn certificate_name(path: &Path) -> Result<Option<String>, IdentityError> {
    let read = |message: String| IdentityError::Read { path: path.to_path_buf(), message };
    let cfg = zenoh::Config::from_file(path).map_err(|e| read(e.to_string()))?;
    let Some((key, value)) = CERTIFICATE_KEYS.iter().find_map(|key| {
        let json = cfg.get_json(key).ok()?;
        let value: Option<String> = serde_json::from_str(&json).ok()?;
        value.map(|v| (*key, v))
    }) else {
        return Ok(None);
    };
    let bad =
        |message: String| IdentityError::Certificate { path: path.to_path_buf(), key, message };
    let pem = match key.ends_with("_base64") {
        true => base64::engine::general_purpose::STANDARD
            .decode(value.trim())
            .map_err(|e| bad(format!("not base64: {e}")))?,
        false => std::fs::read(&value).map_err(|e| bad(format!("{value}: {e}")))?,
    };
    let name = common_name(&pem).map_err(bad)?;
    if safe_name(&name) != name || name.is_empty() {
        return Err(IdentityError::UnusableName { path: path.to_path_buf(), name });
    }
    Ok(Some(name))
}

/// The first common name of the first certificate in `pem`.
fn common_name(pem: &[u8]) -> Result<String, String> {
    use x509_parser::pem::Pem;
    let first = Pem::iter_from_buffer(pem).next().ok_or("no PEM certificate")?;
    let first = first.map_err(|e| format!("not PEM: {e}"))?;
    let cert = first.parse_x509().map_err(|e| format!("not an X.509 certificate: {e}"))?;
    let name = cert.subject().iter_common_name().next().and_then(|cn| cn.as_str().ok());
    name.map(str::to_string).ok_or_else(|| "the certificate has no common name".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A self-signed certificate whose common name is `common_name`, PEM.
    fn certificate(common_name: &str) -> String {
        let key = rcgen::KeyPair::generate().unwrap();
        let mut params = rcgen::CertificateParams::new(Vec::<String>::new()).unwrap();
        params.distinguished_name.push(rcgen::DnType::CommonName, common_name);
        params.self_signed(&key).unwrap().pem()
    }

    fn config(dir: &Path, name: &str, tls: &str) -> ZenohSecurity {
        let path = dir.join(name);
        std::fs::write(&path, format!("{{ transport: {{ link: {{ tls: {{ {tls} }} }} }} }}"))
            .unwrap();
        ZenohSecurity { config: Some(path), insecure: false }
    }

    fn inline(dir: &Path, name: &str, pem: &str) -> ZenohSecurity {
        let b64 = base64::engine::general_purpose::STANDARD.encode(pem);
        config(dir, name, &format!(r#"connect_certificate_base64: "{b64}""#))
    }

    #[test]
    fn the_certificates_common_name_is_the_workers_name() {
        let dir = tempfile::tempdir().unwrap();
        let pem = certificate("ceilfarm-worker-7");
        let inline = inline(dir.path(), "inline.json5", &pem);
        let pem_file = dir.path().join("w7.pem");
        std::fs::write(&pem_file, &pem).unwrap();
        let tls = format!(r#"connect_certificate: "{}""#, pem_file.display());
        let file = config(dir.path(), "file.json5", &tls);
        for sec in [&inline, &file] {
            assert_eq!(worker_name(sec, None).unwrap().as_deref(), Some("ceilfarm-worker-7"));
            let same = worker_name(sec, Some("ceilfarm-worker-7")).unwrap();
            assert_eq!(same.as_deref(), Some("ceilfarm-worker-7"));
        }
        let err = worker_name(&inline, Some("ceilfarm-worker-1")).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, IdentityError::NameMismatch { .. }), "{text}");
        assert!(text.contains("--name ceilfarm-worker-1") && text.contains("ceilfarm-worker-7"));
    }

    #[test]
    fn without_a_certificate_the_requested_name_stands() {
        let dir = tempfile::tempdir().unwrap();
        let plain = config(dir.path(), "plain.json5", "enable_mtls: false");
        assert_eq!(worker_name(&plain, Some("lab-pc")).unwrap().as_deref(), Some("lab-pc"));
        assert_eq!(worker_name(&plain, None).unwrap(), None);
        let none = ZenohSecurity::default();
        assert_eq!(worker_name(&none, Some("x")).unwrap().as_deref(), Some("x"));
    }

    #[test]
    fn a_broken_certificate_or_an_unusable_name_is_refused_with_its_file() {
        let dir = tempfile::tempdir().unwrap();
        let pem = "-----BEGIN CERTIFICATE-----\nAAAA\n-----END CERTIFICATE-----\n";
        let garbled = inline(dir.path(), "g.json5", pem);
        let err = worker_name(&garbled, None).unwrap_err().to_string();
        assert!(err.contains("connect_certificate_base64") && err.contains("g.json5"), "{err}");
        let missing = config(dir.path(), "m.json5", r#"connect_certificate: "/nonexistent/w.pem""#);
        let err = worker_name(&missing, None).unwrap_err().to_string();
        assert!(err.contains("/nonexistent/w.pem"), "{err}");
        let spaced = inline(dir.path(), "s.json5", &certificate("lab pc 3"));
        let err = worker_name(&spaced, None).unwrap_err();
        assert!(matches!(err, IdentityError::UnusableName { ref name, .. } if name == "lab pc 3"));
    }
}
