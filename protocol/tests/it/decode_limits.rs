//! Decoding a forged message allocates no more than the message could
//! justify: the largest single allocation made while decoding is measured
//! by a counting global allocator. It counts only the allocations of the
//! thread that is measuring, so the other tests of this binary, running on
//! their own threads (zenoh's included), are not counted.

use protocol::codec::{decode, CodecError};
use protocol::{FromWorker, PROTOCOL_VERSION};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, remembering the largest request made by a thread
/// while that thread measures.
struct Largest;

thread_local! {
    /// The largest request since this thread started measuring, or `None`
    /// when it is not measuring. Const-initialised without a destructor,
    /// so reading it never allocates.
    static LARGEST: Cell<Option<usize>> = const { Cell::new(None) };
}

/// Notes a request of `size` bytes if this thread is measuring.
fn note(size: usize) {
    // try_with: a thread being torn down has no slot left, and counts nothing.
    let _ = LARGEST.try_with(|l| {
        if let Some(m) = l.get() {
            l.set(Some(m.max(size)));
        }
    });
}

unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Largest = Largest;

/// Largest single allocation (bytes) made by `f` on this thread (the
/// binary's one counting allocator, shared with the decoder fuzz).
pub(crate) fn largest_allocation(f: impl FnOnce()) -> usize {
    LARGEST.with(|l| l.set(Some(0)));
    f();
    LARGEST.with(|l| l.take()).expect("measuring")
}

/// Regression (issue 56): version, Hello, proto 2, a name claiming 1 GiB
/// (varint 0xFC + u32) and 4 bytes of it made the coordinator allocate 1.3 GB.
#[test]
fn a_forged_hello_is_refused_without_a_large_allocation() {
    let mut bytes = PROTOCOL_VERSION.to_le_bytes().to_vec();
    bytes.extend_from_slice(&[0, 2, 0xFC]);
    bytes.extend_from_slice(&(1u32 << 30).to_le_bytes());
    bytes.extend_from_slice(b"evil");
    let mut result = None;
    let largest = largest_allocation(|| result = Some(decode::<FromWorker>(&bytes)));
    let err = result.unwrap().unwrap_err();
    assert!(matches!(err, CodecError::Overlong { .. }), "{err}");
    assert!(err.to_string().contains("claims more than the 11 bytes"), "{err}");
    assert!(largest < 4096, "decoding 13 bytes allocated {largest} bytes at once");
}

/// A result claiming 2^60 scalars preallocates at most serde's cautious
/// 1 MiB before running out of bytes.
#[test]
fn a_forged_sequence_length_preallocates_at_most_one_mebibyte() {
    let mut bytes = PROTOCOL_VERSION.to_le_bytes().to_vec();
    // Result, task id 3, Outcome::Ok, scalars: varint 0xFD + u64 length.
    bytes.extend_from_slice(&[1, 3, 0, 0xFD]);
    bytes.extend_from_slice(&(1u64 << 60).to_le_bytes());
    let mut result = None;
    let largest = largest_allocation(|| result = Some(decode::<FromWorker>(&bytes)));
    assert!(result.unwrap().is_err());
    assert!(largest <= 1 << 20, "decoding {} bytes allocated {largest} bytes at once", bytes.len());
}
