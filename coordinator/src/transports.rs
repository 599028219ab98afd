//! Choosing a transport: in-process threads, iceoryx2 shared memory or
//! zenoh, each behind its cargo feature. The farm never matches on which.

use crate::study::TransportKind;
use protocol::in_process::InProcess;
use protocol::Transport;

/// Default zenoh endpoint of a coordinator.
pub const DEFAULT_ZENOH_ENDPOINT: &str = "tcp/127.0.0.1:7447";

/// Why a transport cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum TransportChoiceError {
    /// This binary was built without the transport's feature.
    #[error("transport {0} is not built into this binary (cargo feature `{0}`)")]
    NotBuilt(&'static str),
}

/// Builds the coordinator's end of the chosen transport.
pub fn coordinator_transport(
    kind: TransportKind,
    workers: usize,
    endpoint: Option<&str>,
) -> Result<Box<dyn Transport>, TransportChoiceError> {
    let _ = endpoint; // unused when neither remote transport is built
    match kind {
        TransportKind::InProcess => {
            Ok(Box::new(InProcess::new(workers, worker::LocalRunner::factory())))
        }
        #[cfg(feature = "zenoh")]
        TransportKind::Zenoh => Ok(Box::new(protocol::zenoh_transport::ZenohCoordinator::new(
            endpoint.unwrap_or(DEFAULT_ZENOH_ENDPOINT),
        ))),
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

/// Builds the worker's end of the chosen transport.
pub fn worker_link(
    kind: TransportKind,
    endpoint: Option<&str>,
) -> Result<Box<dyn protocol::link::WorkerLink>, anyhow::Error> {
    let _ = endpoint;
    match kind {
        TransportKind::InProcess => {
            anyhow::bail!("in-process workers run inside `ceilfarm run`; choose zenoh or iceoryx2")
        }
        #[cfg(feature = "zenoh")]
        TransportKind::Zenoh => Ok(Box::new(protocol::zenoh_transport::ZenohWorker::connect(
            endpoint.unwrap_or(DEFAULT_ZENOH_ENDPOINT),
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
