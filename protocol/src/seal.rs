//! A MAC on every message of a sweep. The coordinator's transport makes a
//! random 32-byte key per sweep ([`SweepKey::random`]) and hands it to the
//! workers it admits inside the Welcome; every task and every worker
//! message after it travels sealed: the encoded message (version header and
//! bincode, as [`crate::codec`]), the lease's sequence number (`u64`,
//! little-endian), and an HMAC-SHA256 tag over a label, the direction, the
//! sweep's id, the sequence number and the encoded message.
//!
//! So a message is accepted only under its sweep's key (a message of
//! another sweep, or forged without the key, fails), only in its direction,
//! and only for its lease: a transport compares the sequence number with
//! the lease it issued, so a reply replayed onto another task or attempt is
//! refused. The tag is checked in constant time before anything is decoded.
//! Whoever holds the key can seal: the key is only as secret as the channel
//! that carried the Welcome (zenoh with mutual TLS; any local process on
//! iceoryx2; anyone on an `--insecure` zenoh farm).
//!
//! A [`SweepKey`] overwrites its bytes with zeros when dropped (the
//! `zeroize` crate: volatile writes the optimiser keeps). That covers the
//! key the transports hold, not copies made of it on the way: the encoded
//! Welcome in the transports' buffers, moves the compiler makes, and the
//! HMAC's per-message key schedule (the `hmac` crate does not zeroize).

use crate::codec::{self, CodecError};
use hmac::{Hmac, Mac};
use serde::{de::DeserializeOwned, Deserialize, Serialize};
use sha2::Sha256;
use zeroize::{Zeroize, ZeroizeOnDrop};

/// Length of a sweep's key (bytes).
pub const KEY_BYTES: usize = 32;
/// Length of a message's tag (bytes).
pub const TAG_BYTES: usize = 32;
/// Length of the sequence number after the message (bytes).
const SEQ_BYTES: usize = 8;
/// What the MAC covers first: the scheme and its version.
const LABEL: &[u8] = b"ceilfarm-mac/1";

/// Which way a message travels; part of what its tag covers, so a task
/// cannot be passed off as a reply or back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Coordinator to worker.
    ToWorker,
    /// Worker to coordinator.
    FromWorker,
}

/// A sweep's message key: random, one per sweep; zeroed when dropped.
#[derive(Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SweepKey([u8; KEY_BYTES]);

impl Zeroize for SweepKey {
    fn zeroize(&mut self) {
        self.0.zeroize();
    }
}

impl Drop for SweepKey {
    fn drop(&mut self) {
        self.zeroize();
    }
}

impl ZeroizeOnDrop for SweepKey {}

impl std::fmt::Debug for SweepKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SweepKey(..)")
    }
}

impl SweepKey {
    /// A fresh key from the operating system's random source (through
    /// rand's thread generator, a CSPRNG seeded by it).
    pub fn random() -> Self {
        use rand::RngCore;
        // Filled in place: no stray copy of the bytes on the stack.
        let mut key = Self([0u8; KEY_BYTES]);
        rand::rng().fill_bytes(&mut key.0);
        key
    }

    /// A key of given bytes (tests, and an attacker's guess in them).
    pub fn from_bytes(key: [u8; KEY_BYTES]) -> Self {
        Self(key)
    }
}

/// Seals and opens the messages of one sweep.
#[derive(Debug, Clone)]
pub struct SweepMac {
    key: SweepKey,
    sweep: String,
}

impl SweepMac {
    /// The sealer of sweep `sweep` (its study hash) under `key`.
    pub fn new(key: SweepKey, sweep: &str) -> Self {
        Self { key, sweep: sweep.to_string() }
    }

    /// The key, for the Welcome.
    pub fn key(&self) -> &SweepKey {
        &self.key
    }

    /// `msg` encoded, followed by `seq` and its tag.
    pub fn seal<T: Serialize>(
        &self,
        direction: Direction,
        seq: u64,
        msg: &T,
    ) -> Result<Vec<u8>, CodecError> {
        let mut out = codec::encode(msg)?;
        out.extend_from_slice(&seq.to_le_bytes());
        let tag = self.mac(direction, &out).finalize().into_bytes();
        out.extend_from_slice(&tag);
        if out.len() > codec::MAX_MESSAGE_BYTES {
            return Err(CodecError::TooLarge { len: out.len(), limit: codec::MAX_MESSAGE_BYTES });
        }
        Ok(out)
    }

    /// The sequence number and message of a sealed frame: its version is
    /// checked first (so another build is named as such), then its tag in
    /// constant time, and only then is the message decoded.
    pub fn open<T: DeserializeOwned>(
        &self,
        direction: Direction,
        bytes: &[u8],
    ) -> Result<(u64, T), CodecError> {
        if bytes.len() > codec::MAX_MESSAGE_BYTES {
            return Err(CodecError::TooLarge { len: bytes.len(), limit: codec::MAX_MESSAGE_BYTES });
        }
        let found = codec::peek_version(bytes)?;
        if found != crate::PROTOCOL_VERSION {
            return Err(CodecError::Version { found, expected: crate::PROTOCOL_VERSION });
        }
        let Some(body_len) = bytes.len().checked_sub(TAG_BYTES + SEQ_BYTES) else {
            return Err(CodecError::Unsealed { len: bytes.len() });
        };
        let (signed, tag) = bytes.split_at(body_len + SEQ_BYTES);
        self.mac(direction, signed).verify_slice(tag).map_err(|_| CodecError::BadMac)?;
        let (message, seq) = signed.split_at(body_len);
        let seq = u64::from_le_bytes(seq.try_into().map_err(|_| CodecError::BadMac)?);
        Ok((seq, codec::decode(message)?))
    }

    /// The MAC state over the label, direction and sweep id, then `signed`.
    fn mac(&self, direction: Direction, signed: &[u8]) -> Hmac<Sha256> {
        // HMAC takes keys of any length; 32 bytes never fail.
        let mut mac = <Hmac<Sha256> as Mac>::new_from_slice(&self.key.0)
            .unwrap_or_else(|_| unreachable!("HMAC accepts any key length"));
        mac.update(LABEL);
        mac.update(&[direction as u8]);
        mac.update(&(self.sweep.len() as u64).to_le_bytes());
        mac.update(self.sweep.as_bytes());
        mac.update(signed);
        mac
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FromWorker, Task, TaskId, ToWorker};

    fn mac(key: u8, sweep: &str) -> SweepMac {
        SweepMac::new(SweepKey::from_bytes([key; KEY_BYTES]), sweep)
    }

    fn task() -> ToWorker {
        ToWorker::Task(Task { id: TaskId(4), params: vec![0.25] })
    }

    #[test]
    fn a_sealed_message_opens_with_its_sequence_number() {
        let m = mac(1, "abc");
        let bytes = m.seal(Direction::ToWorker, 17, &task()).unwrap();
        let (seq, back): (u64, ToWorker) = m.open(Direction::ToWorker, &bytes).unwrap();
        assert_eq!((seq, back), (17, task()));
    }

    #[test]
    fn another_key_sweep_or_direction_fails_the_mac() {
        let bytes = mac(1, "abc").seal(Direction::ToWorker, 1, &task()).unwrap();
        for (other, dir) in [
            (mac(2, "abc"), Direction::ToWorker),
            (mac(1, "abd"), Direction::ToWorker),
            (mac(1, "abc"), Direction::FromWorker),
        ] {
            let err = other.open::<ToWorker>(dir, &bytes).unwrap_err();
            assert!(matches!(err, CodecError::BadMac), "{err}");
        }
    }

    #[test]
    fn every_flipped_bit_fails_the_mac_and_plain_messages_are_refused() {
        let m = mac(1, "abc");
        let bytes = m.seal(Direction::FromWorker, 9, &FromWorker::Goodbye).unwrap();
        for i in 2..bytes.len() {
            for bit in 0..8 {
                let mut forged = bytes.clone();
                forged[i] ^= 1 << bit;
                let err = m.open::<FromWorker>(Direction::FromWorker, &forged).unwrap_err();
                assert!(matches!(err, CodecError::BadMac), "byte {i} bit {bit}: {err}");
            }
        }
        let plain = codec::encode(&FromWorker::Goodbye).unwrap();
        assert!(m.open::<FromWorker>(Direction::FromWorker, &plain).is_err());
    }

    #[test]
    fn another_version_is_named_before_the_mac() {
        let mut bytes = mac(1, "abc").seal(Direction::ToWorker, 1, &task()).unwrap();
        bytes[0] = 99;
        let err = mac(1, "abc").open::<ToWorker>(Direction::ToWorker, &bytes).unwrap_err();
        assert!(matches!(err, CodecError::Version { found: 99, .. }), "{err}");
    }

    #[test]
    fn a_key_is_zeroed_when_dropped() {
        let mut slot = std::mem::MaybeUninit::new(SweepKey::from_bytes([0xA5; KEY_BYTES]));
        // SAFETY: `slot` holds an initialised key, dropped once here and
        // never used as a key again; its bytes stay initialised (a `u8`
        // array is valid for any bytes), so reading them after is sound.
        let after = unsafe {
            std::ptr::drop_in_place(slot.as_mut_ptr());
            std::ptr::read(slot.as_ptr().cast::<[u8; KEY_BYTES]>())
        };
        assert_eq!(after, [0; KEY_BYTES]);
        let mut key = SweepKey::random();
        key.zeroize();
        assert_eq!(key, SweepKey::from_bytes([0; KEY_BYTES]));
    }

    #[test]
    fn keys_are_random_and_never_printed() {
        assert_ne!(SweepKey::random(), SweepKey::random());
        assert_eq!(format!("{:?}", SweepKey::random()), "SweepKey(..)");
    }
}
