//! Binary codec: a little-endian `u16` protocol version, then bincode 2
//! (standard configuration) of the message, with decode limits.
//!
//! Limits: a message holds at most [`MAX_MESSAGE_BYTES`] (zenoh's
//! `max_message_size` is set to the same), and every length field in it (a
//! string, a byte blob) is bounded by the bytes the message actually
//! holds: bincode's claimed-bytes limit is the smallest of
//! [`DECODE_LIMITS_BYTES`] not below the message's length, so a 13-byte
//! Hello claiming a 1 GiB name is refused before anything is allocated.
//! A sequence's claimed length never preallocates more than serde's
//! cautious 1 MiB before its elements are read.

use crate::PROTOCOL_VERSION;
use serde::{de::DeserializeOwned, Serialize};

/// Largest message accepted on decode or sent over zenoh (bytes): 64 MiB,
/// some twenty times the largest result we make (a ceiling run's sensor
/// histories, 30 s at 200 Hz on 40 channels: 1.9 MB).
pub const MAX_MESSAGE_BYTES: usize = 64 << 20;

/// The claimed-bytes limits decoding chooses from, smallest first.
pub const DECODE_LIMITS_BYTES: [usize; 5] = [1 << 10, 1 << 14, 1 << 18, 1 << 22, MAX_MESSAGE_BYTES];

/// Why a message could not be encoded or decoded.
#[derive(Debug, thiserror::Error)]
pub enum CodecError {
    /// Fewer than the two bytes of the version header.
    #[error("message of {len} bytes is too short for the 2-byte version header")]
    TooShort {
        /// Length received.
        len: usize,
    },
    /// The peer speaks another protocol version.
    #[error("protocol version {found} received, this build speaks {expected}")]
    Version {
        /// Version in the message.
        found: u16,
        /// Version of this build.
        expected: u16,
    },
    /// Message larger than [`MAX_MESSAGE_BYTES`].
    #[error("message of {len} bytes exceeds the limit of {limit} bytes")]
    TooLarge {
        /// Length received.
        len: usize,
        /// The limit.
        limit: usize,
    },
    /// A length field claims more bytes than the message holds.
    #[error(
        "a length field claims more than the {len} bytes of the message (limit {limit} bytes)"
    )]
    Overlong {
        /// Length of the message body.
        len: usize,
        /// The claimed-bytes limit applied.
        limit: usize,
    },
    /// The bytes after the header are not a valid message.
    #[error("malformed message: {0}")]
    Malformed(String),
    /// A sealed frame shorter than its sequence number and tag.
    #[error("message of {len} bytes is too short for a sealed message (sequence number and MAC)")]
    Unsealed {
        /// Length received.
        len: usize,
    },
    /// The MAC does not match: forged, altered, or of another sweep or direction.
    #[error("message authentication failed: the MAC does not match this sweep's key")]
    BadMac,
    /// Bytes left over after the message.
    #[error("{extra} trailing bytes after the message")]
    Trailing {
        /// How many bytes were left.
        extra: usize,
    },
    /// A message sealed into a buffer did not fill it exactly.
    #[error(
        "a sealed message does not fill its buffer of {expected} bytes exactly ({written} written)"
    )]
    SealedLength {
        /// The buffer's length.
        expected: usize,
        /// Bytes written when the seal stopped.
        written: usize,
    },
}

pub(crate) fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<MAX_MESSAGE_BYTES>()
}

/// Decodes `body` under the smallest claimed-bytes limit that fits it.
fn decode_body<T: DeserializeOwned>(body: &[u8]) -> Result<(T, usize), CodecError> {
    use bincode::serde::decode_from_slice as from;
    let std = bincode::config::standard();
    let [l0, l1, l2, l3, l4] = DECODE_LIMITS_BYTES;
    let (result, limit) = match body.len() {
        n if n <= l0 => (from(body, std.with_limit::<{ 1 << 10 }>()), l0),
        n if n <= l1 => (from(body, std.with_limit::<{ 1 << 14 }>()), l1),
        n if n <= l2 => (from(body, std.with_limit::<{ 1 << 18 }>()), l2),
        n if n <= l3 => (from(body, std.with_limit::<{ 1 << 22 }>()), l3),
        _ => (from(body, std.with_limit::<MAX_MESSAGE_BYTES>()), l4),
    };
    result.map_err(|e| match e {
        bincode::error::DecodeError::LimitExceeded => {
            CodecError::Overlong { len: body.len(), limit }
        }
        e => CodecError::Malformed(e.to_string()),
    })
}

/// Encodes a message with its version header; one larger than
/// [`MAX_MESSAGE_BYTES`] is refused (no peer would accept it). The buffer
/// is allocated once at the message's length ([`encoded_len`]), so a
/// megabyte result is neither copied by the buffer's growth nor left in a
/// buffer twice its size.
pub fn encode<T: Serialize>(msg: &T) -> Result<Vec<u8>, CodecError> {
    let mut out = Vec::with_capacity(encoded_len(msg)?);
    out.extend_from_slice(&PROTOCOL_VERSION.to_le_bytes());
    bincode::serde::encode_into_std_write(msg, &mut out, config())
        .map_err(|e| CodecError::Malformed(e.to_string()))?;
    Ok(out)
}

/// The length of `msg` encoded, version header included, measured without
/// copying anything (a byte blob, such as a history's samples, counts by
/// its length); a message larger than [`MAX_MESSAGE_BYTES`] is refused.
pub(crate) fn encoded_len<T: Serialize>(msg: &T) -> Result<usize, CodecError> {
    let mut size = bincode::enc::write::SizeWriter::default();
    encode_to(msg, &mut size)?;
    let len = size.bytes_written;
    if len > MAX_MESSAGE_BYTES {
        return Err(CodecError::TooLarge { len, limit: MAX_MESSAGE_BYTES });
    }
    Ok(len)
}

/// Writes `msg` with its version header to `out`, as [`encode`] lays it out.
pub(crate) fn encode_to<T: Serialize, W: bincode::enc::write::Writer>(
    msg: &T,
    out: &mut W,
) -> Result<(), CodecError> {
    let failed = |e: bincode::error::EncodeError| CodecError::Malformed(e.to_string());
    out.write(&PROTOCOL_VERSION.to_le_bytes()).map_err(failed)?;
    bincode::serde::encode_into_writer(msg, out, config()).map_err(failed)
}

/// Reads the version header of a message without decoding the rest.
pub fn peek_version(bytes: &[u8]) -> Result<u16, CodecError> {
    match bytes {
        [a, b, ..] => Ok(u16::from_le_bytes([*a, *b])),
        _ => Err(CodecError::TooShort { len: bytes.len() }),
    }
}

/// Decodes a message, checking version, size and that every byte is used.
pub fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, CodecError> {
    if bytes.len() > MAX_MESSAGE_BYTES {
        return Err(CodecError::TooLarge { len: bytes.len(), limit: MAX_MESSAGE_BYTES });
    }
    let found = peek_version(bytes)?;
    if found != PROTOCOL_VERSION {
        return Err(CodecError::Version { found, expected: PROTOCOL_VERSION });
    }
    let body = &bytes[2..];
    let (msg, used) = decode_body(body)?;
    if used != body.len() {
        return Err(CodecError::Trailing { extra: body.len() - used });
    }
    Ok(msg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::*;

    fn sample_result() -> FromWorker {
        FromWorker::Result(TaskResult {
            id: TaskId(3),
            outcome: Outcome::Ok(Outputs {
                scalars: vec![("f1_hz".into(), 7.5)],
                histories: vec![History {
                    name: "sensors".into(),
                    dt_s: 0.005,
                    channels: vec!["a".into(), "b".into()],
                    data: vec![1.0, 2.0, 3.0, 4.0],
                }],
            }),
            wall_s: 0.01,
            host: "h".into(),
        })
    }

    #[test]
    fn round_trip_preserves_every_field() {
        let msg = sample_result();
        let back: FromWorker = decode(&encode(&msg).unwrap()).unwrap();
        assert_eq!(back, msg);
    }

    #[test]
    fn other_version_is_refused() {
        let mut bytes = encode(&sample_result()).unwrap();
        bytes[0] = 9;
        let err = decode::<FromWorker>(&bytes).unwrap_err();
        assert!(matches!(err, CodecError::Version { found: 9, expected: PROTOCOL_VERSION }));
    }

    #[test]
    fn garbage_and_truncation_are_errors_not_panics() {
        let good = encode(&sample_result()).unwrap();
        for cut in 0..good.len() {
            assert!(decode::<FromWorker>(&good[..cut]).is_err(), "prefix {cut} decoded");
        }
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..2000 {
            let len = (state % 64) as usize;
            let mut bytes = PROTOCOL_VERSION.to_le_bytes().to_vec();
            for _ in 0..len {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                bytes.push(state as u8);
            }
            let _ = decode::<FromWorker>(&bytes);
            let _ = decode::<ToWorker>(&bytes);
        }
    }

    #[test]
    fn huge_declared_length_is_refused_without_allocating() {
        // Result variant, then a varint length of u64::MAX for the scalars vector.
        let mut bytes = PROTOCOL_VERSION.to_le_bytes().to_vec();
        bytes.extend_from_slice(&[1, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF]);
        bytes.extend_from_slice(&u64::MAX.to_le_bytes());
        assert!(decode::<FromWorker>(&bytes).is_err());
    }

    /// Regression (issue 56): a 13-byte Hello whose name claims 1 GiB made
    /// the coordinator allocate 1.3 GB (tests/it/decode_limits.rs measures the
    /// allocation).
    #[test]
    fn a_name_longer_than_its_message_is_refused() {
        let bytes = forged_hello();
        assert_eq!(bytes.len(), 13);
        let err = decode::<FromWorker>(&bytes).unwrap_err();
        assert!(matches!(err, CodecError::Overlong { len: 11, limit: 1024 }), "{err}");
    }

    /// Version, Hello, proto 2, a name of 1 GiB (varint 0xFC + u32) and 4 bytes of it.
    fn forged_hello() -> Vec<u8> {
        let mut bytes = PROTOCOL_VERSION.to_le_bytes().to_vec();
        bytes.extend_from_slice(&[0, 2, 0xFC]);
        bytes.extend_from_slice(&(1u32 << 30).to_le_bytes());
        bytes.extend_from_slice(b"evil");
        bytes
    }

    #[test]
    fn messages_of_every_size_tier_round_trip() {
        for samples in [10usize, 1000, 20_000, 400_000, 1_000_000] {
            let msg = FromWorker::Result(TaskResult {
                id: TaskId(1),
                outcome: Outcome::Ok(Outputs {
                    scalars: vec![("y".into(), 1.0)],
                    histories: vec![History {
                        name: "s".into(),
                        dt_s: 0.01,
                        channels: vec!["a".into()],
                        data: (0..samples).map(|i| i as f64).collect(),
                    }],
                }),
                wall_s: 0.0,
                host: "h".into(),
            });
            let back: FromWorker = decode(&encode(&msg).unwrap()).unwrap();
            assert_eq!(back, msg, "{samples} samples");
        }
    }

    #[test]
    fn a_message_above_the_limit_is_refused_unread() {
        let bytes = vec![0u8; MAX_MESSAGE_BYTES + 1];
        let err = decode::<FromWorker>(&bytes).unwrap_err();
        assert!(matches!(err, CodecError::TooLarge { limit: MAX_MESSAGE_BYTES, .. }), "{err}");
    }

    #[test]
    fn trailing_bytes_are_refused() {
        let mut bytes = encode(&ToWorker::Shutdown).unwrap();
        bytes.push(0);
        assert!(matches!(decode::<ToWorker>(&bytes), Err(CodecError::Trailing { extra: 1 })));
    }
}
