//! A MAC on every message of a sweep. The coordinator's transport makes a
//! random 32-byte key per sweep ([`SweepKey::random`]) and hands it to the
//! workers it admits inside the Welcome; every task and every worker
//! message after it travels sealed: the encoded message (version header and
//! bincode, as [`crate::codec`]), the lease's sequence number (`u64`,
//! little-endian), and a 32-byte tag, BLAKE3 in its keyed mode
//! (`blake3::keyed_hash` under the sweep's key) over these bytes:
//!
//! ```text
//! b"ceilfarm-mac/2"          label: the scheme and its version (14 bytes)
//! direction                  1 byte: 0 to a worker, 1 from a worker
//! sweep id length            u64, little-endian
//! sweep id                   the study hash, UTF-8
//! message                    the encoded message, version header included
//! sequence number            u64, little-endian (the frame's own 8 bytes)
//! ```
//!
//! So a message is accepted only under its sweep's key (a message of
//! another sweep, or forged without the key, fails), only in its direction,
//! and only for its lease: a transport compares the sequence number with
//! the lease it issued, so a reply replayed onto another task or attempt is
//! refused. The tag is checked before anything is decoded, in constant
//! time: the comparison is `blake3::Hash`'s `PartialEq` with the received
//! 32 bytes, which the crate documents as constant-time
//! (`constant_time_eq_32`). Whoever holds the key can seal: the key is
//! only as secret as the channel that carried the Welcome (zenoh with
//! mutual TLS; any local process on iceoryx2; anyone on an `--insecure`
//! zenoh farm).
//!
//! Keyed BLAKE3 is a MAC as it stands (a keyed PRF, no HMAC construction
//! needed) and reads its input once with SIMD; it replaced HMAC-SHA256
//! (`ceilfarm-mac/1`, protocol version 3), which for a 1 MiB result cost
//! half to two thirds of zenoh's CPU per task (48 % and 65 % in two
//! measurements; docs/farm.md, "Cost of security").
//! A peer of version 3 is refused by the version header ("protocol version
//! 3 received, this build speaks 4") before any tag is read; it never
//! reaches the MAC.
//!
//! Sealing reads the message once: bincode's output goes to the frame and
//! to the hasher as it is written ([`SweepMac::seal_into`] writes it
//! straight into a loan of shared memory on iceoryx2, where the frame is
//! never built elsewhere first). Opening hashes the received bytes once and
//! decodes them once. A megabyte result thus costs one BLAKE3 pass on each
//! side (0.12 ms per MiB on this project's machine, docs/farm.md, "Cost of
//! security"), no copy of its own.
//!
//! A [`SweepKey`] overwrites its bytes with zeros when dropped (the
//! `zeroize` crate: volatile writes the optimiser keeps), and so does the
//! hasher's copy of the key after each tag, on every way out of a seal or
//! an open (blake3's `zeroize` feature, through `zeroize::Zeroizing`).
//! That covers the key the transports hold, not copies made of it on the
//! way: the encoded Welcome in the transports' buffers, moves the compiler
//! makes, and whatever BLAKE3's compression functions leave in registers
//! or on the stack.

use crate::codec::{self, CodecError};
use bincode::enc::write::Writer;
use bincode::error::EncodeError;
use serde::{de::DeserializeOwned, Deserialize, Serialize};
use std::mem::MaybeUninit;
use zeroize::{Zeroize, ZeroizeOnDrop, Zeroizing};

/// Length of a sweep's key (bytes): BLAKE3's key.
pub const KEY_BYTES: usize = blake3::KEY_LEN;
/// Length of a message's tag (bytes): BLAKE3's default output.
pub const TAG_BYTES: usize = blake3::OUT_LEN;
/// Length of the sequence number after the message (bytes).
const SEQ_BYTES: usize = 8;
/// What the MAC covers first: the scheme and its version.
const LABEL: &[u8] = b"ceilfarm-mac/2";

/// Which way a message travels; part of what its tag covers (as its
/// discriminant, one byte), so a task cannot be passed off as a reply or
/// back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Coordinator to worker.
    ToWorker = 0,
    /// Worker to coordinator.
    FromWorker = 1,
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

    /// `msg` encoded, followed by `seq` and its tag, in a buffer allocated
    /// once at its length ([`sealed_len`]).
    pub fn seal<T: Serialize>(
        &self,
        direction: Direction,
        seq: u64,
        msg: &T,
    ) -> Result<Vec<u8>, CodecError> {
        let mut out = Vec::with_capacity(sealed_len(msg)?);
        self.seal_onto(direction, seq, msg, &mut out)?;
        Ok(out)
    }

    /// [`Self::seal`] into `out`, a buffer of exactly [`sealed_len`] bytes
    /// that need not be initialised (a loan of shared memory): each byte is
    /// written once, and the tag is computed from the message's bytes as
    /// they are written, in one pass. When this returns `Ok`, every byte of
    /// `out` has been written; a message that does not fill `out` exactly
    /// is refused ([`CodecError::SealedLength`]).
    pub fn seal_into<T: Serialize>(
        &self,
        direction: Direction,
        seq: u64,
        msg: &T,
        out: &mut [MaybeUninit<u8>],
    ) -> Result<(), CodecError> {
        let expected = out.len();
        let mut slots = Slots { buf: out, at: 0, overflowed: false };
        let sealed = self.seal_onto(direction, seq, msg, &mut slots);
        if slots.overflowed || (sealed.is_ok() && slots.at != expected) {
            return Err(CodecError::SealedLength { expected, written: slots.at });
        }
        sealed
    }

    /// Writes `msg`'s encoding, `seq` and the tag to `out`, hashing each
    /// byte of the message as it is written (a byte blob, such as a
    /// history's samples, is read once for both).
    fn seal_onto<T: Serialize, O: Out>(
        &self,
        direction: Direction,
        seq: u64,
        msg: &T,
        out: &mut O,
    ) -> Result<(), CodecError> {
        let mut hasher = self.hasher(direction);
        let mut tee = Tee { out: &mut *out, hasher: &mut hasher };
        codec::encode_to(msg, &mut tee)?;
        tee.write(&seq.to_le_bytes()).map_err(|e| CodecError::Malformed(e.to_string()))?;
        let tag = hasher.finalize();
        out.put(tag.as_bytes()).map_err(|e| CodecError::Malformed(e.to_string()))
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
        let tag: &[u8; TAG_BYTES] = tag.try_into().map_err(|_| CodecError::BadMac)?;
        // `blake3::Hash == [u8; 32]` compares in constant time.
        if self.tag(direction, signed) != *tag {
            return Err(CodecError::BadMac);
        }
        let (message, seq) = signed.split_at(body_len);
        let seq = u64::from_le_bytes(seq.try_into().map_err(|_| CodecError::BadMac)?);
        Ok((seq, codec::decode(message)?))
    }

    /// The tag of `signed` (message and sequence number) in `direction`:
    /// keyed BLAKE3 over the label, direction, sweep id and `signed`.
    fn tag(&self, direction: Direction, signed: &[u8]) -> blake3::Hash {
        let mut hasher = self.hasher(direction);
        hasher.update(signed);
        hasher.finalize()
    }

    /// A keyed hasher that has read the label, direction and sweep id; its
    /// copy of the key is zeroed when it is dropped.
    fn hasher(&self, direction: Direction) -> Zeroizing<blake3::Hasher> {
        let mut hasher = Zeroizing::new(blake3::Hasher::new_keyed(&self.key.0));
        hasher.update(LABEL);
        hasher.update(&[direction as u8]);
        hasher.update(&(self.sweep.len() as u64).to_le_bytes());
        hasher.update(self.sweep.as_bytes());
        hasher
    }
}

/// The length of `msg` sealed: its encoding, sequence number and tag (the
/// buffer [`SweepMac::seal_into`] fills); refused above the message limit.
pub fn sealed_len<T: Serialize>(msg: &T) -> Result<usize, CodecError> {
    let len = codec::encoded_len(msg)? + SEQ_BYTES + TAG_BYTES;
    if len > codec::MAX_MESSAGE_BYTES {
        return Err(CodecError::TooLarge { len, limit: codec::MAX_MESSAGE_BYTES });
    }
    Ok(len)
}

/// Where a seal writes, at the end of what it has written so far.
trait Out {
    /// Appends `bytes`; an error if they do not fit.
    fn put(&mut self, bytes: &[u8]) -> Result<(), EncodeError>;
}

impl Out for Vec<u8> {
    fn put(&mut self, bytes: &[u8]) -> Result<(), EncodeError> {
        self.extend_from_slice(bytes);
        Ok(())
    }
}

/// A buffer that need not be initialised, written from its start.
struct Slots<'a> {
    buf: &'a mut [MaybeUninit<u8>],
    /// Bytes written so far.
    at: usize,
    /// Whether a write did not fit.
    overflowed: bool,
}

impl Out for Slots<'_> {
    fn put(&mut self, bytes: &[u8]) -> Result<(), EncodeError> {
        let Some(dst) = self.buf.get_mut(self.at..self.at + bytes.len()) else {
            self.overflowed = true;
            return Err(EncodeError::UnexpectedEnd);
        };
        // A byte-wise copy the compiler makes a `memcpy`.
        for (d, s) in dst.iter_mut().zip(bytes) {
            d.write(*s);
        }
        self.at += bytes.len();
        Ok(())
    }
}

/// What bincode writes, sent both to the output and to the tag's hasher.
struct Tee<'a, O> {
    out: &'a mut O,
    hasher: &'a mut blake3::Hasher,
}

impl<O: Out> Writer for Tee<'_, O> {
    fn write(&mut self, bytes: &[u8]) -> Result<(), EncodeError> {
        self.out.put(bytes)?;
        self.hasher.update(bytes);
        Ok(())
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

    /// Each thing the tag covers, changed on its own, is refused: a byte of
    /// the message, a byte of the sequence number, the direction, the sweep.
    #[test]
    fn a_changed_message_sequence_direction_or_sweep_fails_the_mac() {
        let m = mac(1, "abc");
        let bytes = m.seal(Direction::ToWorker, 17, &task()).unwrap();
        let seq_at = bytes.len() - TAG_BYTES - SEQ_BYTES;
        let mut message = bytes.clone();
        message[seq_at - 1] ^= 0x01;
        let mut seq = bytes.clone();
        seq[seq_at] ^= 0x01;
        for (what, forged, dir, sweep) in [
            ("message", &message, Direction::ToWorker, "abc"),
            ("sequence number", &seq, Direction::ToWorker, "abc"),
            ("direction", &bytes, Direction::FromWorker, "abc"),
            ("sweep", &bytes, Direction::ToWorker, "abd"),
            ("a sweep extending it", &bytes, Direction::ToWorker, "abc\0"),
        ] {
            let err = mac(1, sweep).open::<ToWorker>(dir, forged).unwrap_err();
            assert!(matches!(err, CodecError::BadMac), "{what}: {err}");
        }
    }

    /// Known answer: the tag is `blake3::keyed_hash` under the sweep's key
    /// over the byte layout the module doc gives, spelt out here by hand.
    #[test]
    fn the_tag_is_keyed_blake3_over_the_documented_layout() {
        let key = [7u8; KEY_BYTES];
        let m = SweepMac::new(SweepKey::from_bytes(key), "abc");
        let frame =
            m.seal(Direction::FromWorker, 0x0102_0304_0506_0708, &FromWorker::Goodbye).unwrap();
        let message = codec::encode(&FromWorker::Goodbye).unwrap();
        let mut layout = b"ceilfarm-mac/2".to_vec();
        layout.push(1);
        layout.extend_from_slice(&[3, 0, 0, 0, 0, 0, 0, 0]);
        layout.extend_from_slice(b"abc");
        layout.extend_from_slice(&message);
        layout.extend_from_slice(&[8, 7, 6, 5, 4, 3, 2, 1]);
        let tag = blake3::keyed_hash(&key, &layout);
        let mut expected = message;
        expected.extend_from_slice(&[8, 7, 6, 5, 4, 3, 2, 1]);
        expected.extend_from_slice(tag.as_bytes());
        assert_eq!(frame, expected);
        // And the direction's byte is 0 the other way.
        layout[LABEL.len()] = 0;
        let to_worker = m.seal(Direction::ToWorker, 0x0102_0304_0506_0708, &FromWorker::Goodbye);
        let to_worker = to_worker.unwrap();
        assert_eq!(
            &to_worker[to_worker.len() - TAG_BYTES..],
            blake3::keyed_hash(&key, &layout).as_bytes()
        );
    }

    /// Sealing into an uninitialised buffer of [`sealed_len`] bytes writes
    /// the very bytes [`SweepMac::seal`] returns, a megabyte history's too;
    /// a buffer a byte short or long is refused, named.
    #[test]
    fn sealing_into_a_buffer_writes_the_same_frame_and_refuses_another_length() {
        use crate::{History, Outcome, Outputs, TaskResult};
        let m = mac(3, "abc");
        let history = History {
            name: "h".into(),
            dt_s: 0.01,
            channels: vec!["x".into()],
            data: (0..131_072).map(|i| i as f64 * 0.5).collect(),
        };
        let outcome = Outcome::Ok(Outputs { scalars: vec![], histories: vec![history] });
        let result = TaskResult { id: TaskId(2), outcome, wall_s: 0.1, host: "w".into() };
        for msg in [FromWorker::Goodbye, FromWorker::Result(result)] {
            let frame = m.seal(Direction::FromWorker, 5, &msg).unwrap();
            let len = sealed_len(&msg).unwrap();
            assert_eq!(frame.len(), len);
            let mut buf = vec![MaybeUninit::<u8>::uninit(); len];
            m.seal_into(Direction::FromWorker, 5, &msg, &mut buf).unwrap();
            // SAFETY: `seal_into` returned `Ok`, so every byte of `buf` is written.
            let written: Vec<u8> = buf.iter().map(|b| unsafe { b.assume_init() }).collect();
            assert!(written == frame, "seal_into wrote another frame");
            let (seq, back): (u64, FromWorker) = m.open(Direction::FromWorker, &written).unwrap();
            assert_eq!((seq, back), (5, msg.clone()));
            for other in [len - 1, len + 1] {
                let mut buf = vec![MaybeUninit::<u8>::uninit(); other];
                let err = m.seal_into(Direction::FromWorker, 5, &msg, &mut buf).unwrap_err();
                assert!(
                    matches!(err, CodecError::SealedLength { expected, .. } if expected == other),
                    "{err}"
                );
            }
        }
    }

    #[test]
    fn another_version_is_named_before_the_mac() {
        let mut bytes = mac(1, "abc").seal(Direction::ToWorker, 1, &task()).unwrap();
        bytes[0] = 99;
        let err = mac(1, "abc").open::<ToWorker>(Direction::ToWorker, &bytes).unwrap_err();
        assert!(matches!(err, CodecError::Version { found: 99, .. }), "{err}");
    }

    /// A peer of protocol version 3 (HMAC-SHA256, `ceilfarm-mac/1`) is
    /// refused by its version, named, and its frame is never read further.
    #[test]
    fn a_version_3_peer_is_refused_by_its_version() {
        assert_eq!(crate::PROTOCOL_VERSION, 4);
        let mut bytes = mac(1, "abc").seal(Direction::FromWorker, 1, &FromWorker::Goodbye).unwrap();
        bytes[..2].copy_from_slice(&3u16.to_le_bytes());
        let err = mac(1, "abc").open::<FromWorker>(Direction::FromWorker, &bytes).unwrap_err();
        assert!(matches!(err, CodecError::Version { found: 3, expected: 4 }), "{err}");
        assert_eq!(err.to_string(), "protocol version 3 received, this build speaks 4");
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
