//! Messages between the ceilfarm coordinator and its workers, their binary
//! codec, and the [`Transport`] interface every transport implements.
//!
//! Roles: the coordinator turns a design into [`Task`]s; a worker runs the
//! study's model on each and answers with a [`TaskResult`] whose
//! [`Outcome`] is either [`Outputs`] (named scalars and time histories) or a
//! failure with its reason. Nothing here knows the physics of any model or
//! which transport carries the bytes.
//!
//! ```
//! use protocol::{codec, Task, TaskId, ToWorker};
//! let msg = ToWorker::Task(Task { id: TaskId(7), params: vec![0.5, 1.0] });
//! let bytes = codec::encode(&msg).unwrap();
//! let back: ToWorker = codec::decode(&bytes).unwrap();
//! assert_eq!(back, msg);
//! ```

pub mod codec;
#[cfg(feature = "iceoryx2")]
pub mod iceoryx2_transport;
pub mod in_process;
pub mod link;
pub mod membership;
pub mod messages;
pub mod raw_f64;
pub mod seal;
pub mod task_reply;
pub mod transport;
#[cfg(feature = "zenoh")]
pub mod zenoh_config;
#[cfg(feature = "zenoh")]
pub mod zenoh_identity;
pub mod zenoh_keys;
#[cfg(feature = "zenoh")]
pub mod zenoh_transport;

pub use messages::*;
pub use transport::{Transport, TransportError, TransportEvent, WorkerId};

/// Version of the message layout; peers with another version are refused.
/// 2: iceoryx2 welcomes and worker messages carry node ids.
/// 3: the Welcome carries the sweep's key; tasks and worker messages are sealed.
/// 4: the seal's MAC is keyed BLAKE3 (`ceilfarm-mac/2`), no longer HMAC-SHA256.
pub const PROTOCOL_VERSION: u16 = 4;
