//! A bounded fuzz of the decoder (proptest): random bytes, and valid
//! messages cut, flipped and extended, through `codec::decode` of both
//! message directions and through a sweep's `SweepMac::open`. None may
//! panic, and no single allocation while decoding may exceed the 1 MiB
//! that serde preallocates at most for a claimed sequence length (the
//! largest message here is a few kilobytes).
//!
//! Allocations are counted per thread by the binary's counting allocator
//! ([`crate::decode_limits`]), so tests running beside these are not
//! counted.

use crate::decode_limits::largest_allocation;
use proptest::prelude::*;
use protocol::codec::{decode, encode};
use protocol::seal::{Direction, SweepKey, SweepMac, KEY_BYTES};
use protocol::{FromWorker, History, Outcome, Outputs, Task, TaskId, TaskResult, ToWorker};

/// Most bytes one allocation may take while decoding a fuzzed message.
const LIMIT_BYTES: usize = 1 << 20;

/// Decodes `bytes` every way a peer could; returns the largest allocation.
fn decode_every_way(bytes: &[u8]) -> usize {
    let mac = SweepMac::new(SweepKey::from_bytes([3; KEY_BYTES]), "fuzz");
    largest_allocation(|| {
        let _ = decode::<FromWorker>(bytes);
        let _ = decode::<ToWorker>(bytes);
        let _ = mac.open::<FromWorker>(Direction::FromWorker, bytes);
        let _ = mac.open::<ToWorker>(Direction::ToWorker, bytes);
    })
}

fn samples() -> Vec<Vec<u8>> {
    let history = History {
        name: "sensors".into(),
        dt_s: 0.01,
        channels: vec!["a".into(), "b".into()],
        data: (0..64).map(f64::from).collect(),
    };
    let outputs = Outputs { scalars: vec![("y".into(), 1.5)], histories: vec![history] };
    let result = FromWorker::Result(TaskResult {
        id: TaskId(9),
        outcome: Outcome::Ok(outputs),
        wall_s: 0.5,
        host: "h".into(),
    });
    let hello = FromWorker::Hello { proto: 3, name: "w".into(), threads: 2, study: None };
    let task = ToWorker::Task(Task { id: TaskId(2), params: vec![0.1, 0.2] });
    let mac = SweepMac::new(SweepKey::from_bytes([3; KEY_BYTES]), "fuzz");
    vec![
        encode(&result).unwrap(),
        encode(&hello).unwrap(),
        encode(&task).unwrap(),
        mac.seal(Direction::FromWorker, 5, &result).unwrap(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_after_a_valid_header_never_panic_or_allocate_much(
        body in proptest::collection::vec(any::<u8>(), 0..512)
    ) {
        let mut bytes = protocol::PROTOCOL_VERSION.to_le_bytes().to_vec();
        bytes.extend_from_slice(&body);
        let largest = decode_every_way(&bytes);
        prop_assert!(largest <= LIMIT_BYTES, "{} bytes allocated {largest} at once", bytes.len());
    }

    #[test]
    fn mutated_messages_never_panic_or_allocate_much(
        which in 0usize..4,
        cut in any::<prop::sample::Index>(),
        flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..8),
        tail in proptest::collection::vec(any::<u8>(), 0..16),
    ) {
        let mut bytes = samples().swap_remove(which);
        let keep = 2 + cut.index(bytes.len() - 1);
        bytes.truncate(keep);
        for (at, value) in flips {
            let i = 2 + at.index(bytes.len().saturating_sub(2).max(1));
            if i < bytes.len() {
                bytes[i] = value;
            }
        }
        bytes.extend_from_slice(&tail);
        let largest = decode_every_way(&bytes);
        prop_assert!(largest <= LIMIT_BYTES, "{} bytes allocated {largest} at once", bytes.len());
    }
}
