//! Choosing a transport: in-process threads, iceoryx2 shared memory or
//! zenoh, each behind its cargo feature. The farm never matches on which.

use crate::study::TransportKind;
use protocol::in_process::InProcess;
use protocol::Transport;

/// How a zenoh session is secured: a zenoh JSON5 configuration file (TLS,
/// mutual authentication, access control) and whether listening beyond
/// loopback without them is allowed.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ZenohSecurity {
    /// `--zenoh-config FILE`.
    pub config: Option<std::path::PathBuf>,
    /// `--insecure`.
    pub insecure: bool,
}

#[cfg(feature = "zenoh")]
impl From<&ZenohSecurity> for protocol::zenoh_config::ZenohSecurity {
    fn from(s: &ZenohSecurity) -> Self {
        Self { config: s.config.clone(), insecure: s.insecure }
    }
}

/// Why a transport cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum TransportChoiceError {
    /// This binary was built without the transport's feature.
    #[error("transport {0} is not built into this binary (cargo feature `{0}`)")]
    NotBuilt(&'static str),
    /// The transport's configuration is refused.
    #[error(transparent)]
    Setup(#[from] protocol::TransportError),
}

/// Builds the coordinator's end of the chosen transport, zenoh with no
/// configuration file (listening on loopback only, unless the endpoint is
/// refused when the transport starts).
pub fn coordinator_transport(
    kind: TransportKind,
    workers: usize,
    endpoint: Option<&str>,
) -> Result<Box<dyn Transport>, TransportChoiceError> {
    coordinator_transport_secured(kind, workers, endpoint, &ZenohSecurity::default())
}

/// Builds the coordinator's end of the chosen transport; zenoh under `security`.
pub fn coordinator_transport_secured(
    kind: TransportKind,
    workers: usize,
    endpoint: Option<&str>,
    security: &ZenohSecurity,
) -> Result<Box<dyn Transport>, TransportChoiceError> {
    let _ = (endpoint, security); // unused when neither remote transport is built
    match kind {
        TransportKind::InProcess => {
            Ok(Box::new(InProcess::new(workers, worker::LocalRunner::factory())))
        }
        #[cfg(feature = "zenoh")]
        TransportKind::Zenoh => Ok(Box::new(protocol::zenoh_transport::ZenohCoordinator::new(
            endpoint,
            &security.into(),
        )?)),
        #[cfg(not(feature = "zenoh"))]
        TransportKind::Zenoh => Err(TransportChoiceError::NotBuilt("zenoh")),
        #[cfg(feature = "iceoryx2")]
        TransportKind::Iceoryx2 => {
            Ok(Box::new(protocol::iceoryx2_transport::IceoryxCoordinator::new(endpoint)))
        }
        #[cfg(not(feature = "iceoryx2"))]
        TransportKind::Iceoryx2 => Err(TransportChoiceError::NotBuilt("iceoryx2")),
    }
}

/// The name a worker of transport `kind` announces: over zenoh, the common
/// name of the certificate its configuration presents, which `requested`
/// (`--name`) must equal, as the coordinator's access control lets that
/// certificate serve only that name's tasks; else `requested` (`None`: the
/// caller's default). Read before connecting, so a wrong name stops the
/// worker at once.
pub fn worker_name(
    kind: TransportKind,
    security: &ZenohSecurity,
    requested: Option<&str>,
) -> Result<Option<String>, anyhow::Error> {
    match kind {
        #[cfg(feature = "zenoh")]
        TransportKind::Zenoh => {
            Ok(protocol::zenoh_identity::worker_name(&security.into(), requested)?)
        }
        _ => {
            let _ = security;
            Ok(requested.map(str::to_string))
        }
    }
}

/// Builds the worker's end of the chosen transport; zenoh under `security`.
pub fn worker_link(
    kind: TransportKind,
    endpoint: Option<&str>,
    security: &ZenohSecurity,
) -> Result<Box<dyn protocol::link::WorkerLink>, anyhow::Error> {
    let _ = (endpoint, security);
    match kind {
        TransportKind::InProcess => {
            anyhow::bail!("in-process workers run inside `ceilfarm run`; choose zenoh or iceoryx2")
        }
        #[cfg(feature = "zenoh")]
        TransportKind::Zenoh => Ok(Box::new(protocol::zenoh_transport::ZenohWorker::connect(
            endpoint,
            &security.into(),
        )?)),
        #[cfg(not(feature = "zenoh"))]
        TransportKind::Zenoh => Err(TransportChoiceError::NotBuilt("zenoh").into()),
        #[cfg(feature = "iceoryx2")]
        TransportKind::Iceoryx2 => {
            Ok(Box::new(protocol::iceoryx2_transport::IceoryxWorker::new(endpoint)?))
        }
        #[cfg(not(feature = "iceoryx2"))]
        TransportKind::Iceoryx2 => Err(TransportChoiceError::NotBuilt("iceoryx2").into()),
    }
}
