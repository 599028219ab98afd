//! Binary codec: a little-endian `u16` protocol version, then bincode 2
//! (standard configuration) of the message, with a decode size limit.

use crate::PROTOCOL_VERSION;
use serde::{de::DeserializeOwned, Serialize};

/// Largest message accepted on decode (bytes): 1 GiB.
pub const MAX_MESSAGE_BYTES: usize = 1 << 30;

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
    /// The bytes after the header are not a valid message.
    #[error("malformed message: {0}")]
    Malformed(String),
    /// Bytes left over after the message.
    #[error("{extra} trailing bytes after the message")]
    Trailing {
        /// How many bytes were left.
        extra: usize,
    },
}

fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<MAX_MESSAGE_BYTES>()
}

/// Encodes a message with its version header.
pub fn encode<T: Serialize>(msg: &T) -> Result<Vec<u8>, CodecError> {
    let mut out = PROTOCOL_VERSION.to_le_bytes().to_vec();
    bincode::serde::encode_into_std_write(msg, &mut out, config())
        .map_err(|e| CodecError::Malformed(e.to_string()))?;
    Ok(out)
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
    let (msg, used) = bincode::serde::decode_from_slice(body, config())
        .map_err(|e| CodecError::Malformed(e.to_string()))?;
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

    #[test]
    fn trailing_bytes_are_refused() {
        let mut bytes = encode(&ToWorker::Shutdown).unwrap();
        bytes.push(0);
        assert!(matches!(decode::<ToWorker>(&bytes), Err(CodecError::Trailing { extra: 1 })));
    }
}
