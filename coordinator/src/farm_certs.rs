//! A lab's certificates for the zenoh farm (`ceilfarm farm certs`): a
//! certificate authority made for the lab, a coordinator certificate (its
//! host names and addresses as subject alternative names, so workers check
//! whom they reach) and one certificate per worker, each named by its
//! common name, which the coordinator's access control lists. The CA's
//! private key is never written: to add workers, make the set again.
//!
//! Keys are ECDSA P-256 (rcgen's default). Every certificate of a set, the
//! CA's too, is valid for `--days` days from its making
//! ([`DEFAULT_VALIDITY_DAYS`]; a day earlier too, for clocks running
//! behind): the CA's key is gone once the set is written, so it signs
//! nothing later. zenoh's TLS refuses an expired certificate at the
//! handshake and, as the coordinator's configuration asks
//! (`close_link_on_expiration`), closes a link when its certificate
//! expires. A lab revokes certificates early by making a new set.

use crate::farm_zenoh_config::{coordinator_config, worker_config};
use rcgen::{
    BasicConstraints, CertificateParams, DnType, ExtendedKeyUsagePurpose, IsCa, Issuer, KeyPair,
    KeyUsagePurpose,
};
use std::path::{Path, PathBuf};

/// Common name of the coordinator's certificate.
pub const COORDINATOR_NAME: &str = "ceilfarm-coordinator";

/// Most worker certificates one set holds.
pub const MAX_WORKERS: usize = 1000;

/// Days a set's certificates are valid when `--days` is not given.
pub const DEFAULT_VALIDITY_DAYS: u32 = 365;

/// Longest validity `--days` accepts (ten years), in days.
pub const MAX_VALIDITY_DAYS: u32 = 3650;

/// How long before its making a certificate is valid already (clocks
/// running behind), in seconds.
const CLOCK_GRACE_S: i64 = 24 * 3600;

/// Why a lab's certificates could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum CertsError {
    /// rcgen refused a key or certificate.
    #[error("certificate for {name}: {source}")]
    Rcgen {
        /// The certificate's common name.
        name: String,
        /// rcgen's error.
        source: rcgen::Error,
    },
    /// A file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A file of the set exists already (a lab's keys are never overwritten).
    #[error("{path} exists already: choose an empty --out folder")]
    Exists {
        /// The file.
        path: PathBuf,
    },
    /// The worker count is out of range.
    #[error("--workers {0}: expected 1 to {MAX_WORKERS}")]
    Workers(usize),
    /// The validity is out of range.
    #[error("--days {0}: expected 1 to {MAX_VALIDITY_DAYS}")]
    Days(u32),
}

/// When a certificate is valid: from a day before `start` to `days` days
/// after it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Validity {
    /// When the set is made.
    pub start: std::time::SystemTime,
    /// Days it stays valid after `start`.
    pub days: u32,
}

impl Validity {
    /// `days` days from now.
    pub fn from_now(days: u32) -> Self {
        Self { start: std::time::SystemTime::now(), days }
    }

    /// rcgen's (not before, not after).
    fn window(&self) -> (time::OffsetDateTime, time::OffsetDateTime) {
        let start = time::OffsetDateTime::from(self.start);
        let not_before = start - time::Duration::seconds(CLOCK_GRACE_S);
        (not_before, start + time::Duration::days(i64::from(self.days)))
    }

    fn set(&self, params: &mut CertificateParams) {
        (params.not_before, params.not_after) = self.window();
    }
}

/// A certificate and its private key, both PEM.
#[derive(Debug, Clone)]
pub struct Identity {
    /// The certificate's common name (the access control's subject).
    pub common_name: String,
    /// The certificate, PEM.
    pub cert_pem: String,
    /// The private key, PEM (PKCS #8).
    pub key_pem: String,
}

/// A lab's certificate authority, held in memory only.
pub struct LabCa {
    issuer: Issuer<'static, KeyPair>,
    pem: String,
}

fn rcgen_err(name: &str) -> impl FnOnce(rcgen::Error) -> CertsError + '_ {
    move |source| CertsError::Rcgen { name: name.to_string(), source }
}

impl LabCa {
    /// A new CA named `name` with a fresh key, valid over `validity`.
    pub fn new(name: &str, validity: &Validity) -> Result<Self, CertsError> {
        let key = KeyPair::generate().map_err(rcgen_err(name))?;
        let mut params = CertificateParams::new(Vec::<String>::new()).map_err(rcgen_err(name))?;
        validity.set(&mut params);
        params.distinguished_name.push(DnType::CommonName, name);
        params.is_ca = IsCa::Ca(BasicConstraints::Constrained(0));
        params.key_usages = vec![KeyUsagePurpose::KeyCertSign, KeyUsagePurpose::CrlSign];
        let cert = params.self_signed(&key).map_err(rcgen_err(name))?;
        Ok(Self { issuer: Issuer::new(params, key), pem: cert.pem() })
    }

    /// The CA's certificate, PEM (every member trusts it).
    pub fn cert_pem(&self) -> &str {
        &self.pem
    }

    /// A certificate for `common_name`, valid over `validity` for the host
    /// names and IP addresses in `hosts` (none for a worker, which only
    /// connects).
    pub fn issue(
        &self,
        common_name: &str,
        hosts: &[String],
        validity: &Validity,
    ) -> Result<Identity, CertsError> {
        let err = rcgen_err(common_name);
        let key = KeyPair::generate().map_err(rcgen_err(common_name))?;
        let mut params = CertificateParams::new(hosts.to_vec()).map_err(err)?;
        validity.set(&mut params);
        params.distinguished_name.push(DnType::CommonName, common_name);
        params.key_usages = vec![KeyUsagePurpose::DigitalSignature];
        params.extended_key_usages =
            vec![ExtendedKeyUsagePurpose::ServerAuth, ExtendedKeyUsagePurpose::ClientAuth];
        let cert = params.signed_by(&key, &self.issuer).map_err(rcgen_err(common_name))?;
        Ok(Identity {
            common_name: common_name.to_string(),
            cert_pem: cert.pem(),
            key_pem: key.serialize_pem(),
        })
    }
}

/// What `ceilfarm farm certs` makes.
#[derive(Debug, Clone)]
pub struct LabSettings {
    /// Worker certificates to make (`ceilfarm-worker-1` ...).
    pub workers: usize,
    /// The coordinator's host names and addresses; workers connect to the first.
    pub hosts: Vec<String>,
    /// The coordinator's TCP port.
    pub port: u16,
    /// Days the certificates are valid (`--days`, default
    /// [`DEFAULT_VALIDITY_DAYS`]).
    pub validity_days: u32,
}

/// Common name of worker `k` (from 1).
pub fn worker_name(k: usize) -> String {
    format!("ceilfarm-worker-{k}")
}

/// Writes a lab's set into `out`: `ca.pem`, `coordinator.json5` and
/// `worker-K.json5` (zenoh configurations holding their certificate and key
/// inline, readable by their owner only). Returns the files written.
pub fn write_lab(out: &Path, s: &LabSettings) -> Result<Vec<PathBuf>, CertsError> {
    if s.workers == 0 || s.workers > MAX_WORKERS {
        return Err(CertsError::Workers(s.workers));
    }
    if s.validity_days == 0 || s.validity_days > MAX_VALIDITY_DAYS {
        return Err(CertsError::Days(s.validity_days));
    }
    let validity = Validity::from_now(s.validity_days);
    let ca = LabCa::new("ceilfarm lab CA", &validity)?;
    let coordinator = ca.issue(COORDINATOR_NAME, &s.hosts, &validity)?;
    let names: Vec<String> = (1..=s.workers).map(worker_name).collect();
    let host = s.hosts.first().map_or("127.0.0.1", String::as_str);
    let mut files = vec![
        ("ca.pem".to_string(), ca.cert_pem().to_string()),
        (
            "coordinator.json5".to_string(),
            coordinator_config(
                ca.cert_pem(),
                &coordinator,
                &format!("tls/0.0.0.0:{}", s.port),
                &names,
            ),
        ),
    ];
    let connect = format!("tls/{}:{}", bracket_ipv6(host), s.port);
    for (k, name) in names.iter().enumerate() {
        let id = ca.issue(name, &[], &validity)?;
        files
            .push((format!("worker-{}.json5", k + 1), worker_config(ca.cert_pem(), &id, &connect)));
    }
    std::fs::create_dir_all(out)
        .map_err(|source| CertsError::Io { path: out.to_path_buf(), source })?;
    if let Some(path) = files.iter().map(|(n, _)| out.join(n)).find(|p| p.exists()) {
        return Err(CertsError::Exists { path });
    }
    files.iter().map(|(name, text)| write_private(&out.join(name), text)).collect()
}

/// `[addr]` for an IPv6 address, as endpoints write it; anything else as is.
fn bracket_ipv6(host: &str) -> String {
    match host.parse::<std::net::Ipv6Addr>() {
        Ok(_) => format!("[{host}]"),
        Err(_) => host.to_string(),
    }
}

/// Writes a new file readable by its owner only.
fn write_private(path: &Path, text: &str) -> Result<PathBuf, CertsError> {
    use std::io::Write;
    let io = |source| CertsError::Io { path: path.to_path_buf(), source };
    let mut opts = std::fs::OpenOptions::new();
    opts.write(true).create_new(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut opts, 0o600);
    let mut file = opts.open(path).map_err(io)?;
    file.write_all(text.as_bytes()).map_err(io)?;
    Ok(path.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_holds_the_ca_the_coordinator_and_each_worker_once() {
        let dir = tempfile::tempdir().unwrap();
        let s = LabSettings {
            workers: 2,
            hosts: vec!["10.0.0.5".into()],
            port: 7447,
            validity_days: DEFAULT_VALIDITY_DAYS,
        };
        let files = write_lab(dir.path(), &s).unwrap();
        let names: Vec<_> =
            files.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(names, ["ca.pem", "coordinator.json5", "worker-1.json5", "worker-2.json5"]);
        let worker = std::fs::read_to_string(dir.path().join("worker-2.json5")).unwrap();
        assert!(worker.contains("tls/10.0.0.5:7447"), "{worker}");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let meta = std::fs::metadata(dir.path().join("worker-1.json5")).unwrap();
            assert_eq!(meta.permissions().mode() & 0o777, 0o600);
        }
        let again = write_lab(dir.path(), &s).unwrap_err();
        assert!(again.to_string().contains("exists already"), "{again}");
    }

    #[test]
    fn worker_counts_and_validities_out_of_range_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let s = LabSettings { workers: 0, hosts: vec![], port: 7447, validity_days: 365 };
        assert!(matches!(write_lab(dir.path(), &s), Err(CertsError::Workers(0))));
        for days in [0, MAX_VALIDITY_DAYS + 1] {
            let s = LabSettings { workers: 1, hosts: vec![], port: 7447, validity_days: days };
            let err = write_lab(dir.path(), &s).unwrap_err();
            assert!(matches!(err, CertsError::Days(d) if d == days), "{err}");
            assert!(err.to_string().contains("--days"), "{err}");
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing written");
    }

    #[test]
    fn a_validity_runs_from_a_day_before_its_start_for_its_days() {
        let start = std::time::UNIX_EPOCH + std::time::Duration::from_secs(1_800_000_000);
        let (from, to) = Validity { start, days: 30 }.window();
        assert_eq!(from.unix_timestamp(), 1_800_000_000 - 86_400);
        assert_eq!(to.unix_timestamp(), 1_800_000_000 + 30 * 86_400);
    }
}
