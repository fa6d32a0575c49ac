//! A counting global allocator for the fuzz tests: it records the largest
//! single allocation request, so that a test can assert that no input made a
//! parser grow without bound. Shared by `#[path]` between this crate's
//! `fuzz_parsers.rs` and the renderer's `tests/fuzz_inputs.rs` (each test
//! binary has its own global allocator and its own record).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, recording the largest request in [`LARGEST`].
pub struct Largest;

/// The largest single allocation (or reallocation) requested so far, in bytes.
pub static LARGEST: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        LARGEST.fetch_max(l.size(), Ordering::Relaxed);
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        LARGEST.fetch_max(n, Ordering::Relaxed);
        System.realloc(p, l, n)
    }
}

#[global_allocator]
static A: Largest = Largest;

/// Panics if any allocation so far requested `limit` bytes or more.
pub fn assert_bounded(limit: usize) {
    let m = LARGEST.load(Ordering::Relaxed);
    assert!(m < limit, "an allocation of {m} bytes (the limit is {limit})");
}

/// The allocator is the test binary's: a request of 1 MiB is recorded (else
/// every `assert_bounded` would pass on a record that stays 0).
#[test]
fn records_the_largest_request() {
    let v: Vec<u8> = Vec::with_capacity(1 << 20);
    std::hint::black_box(&v);
    assert!(LARGEST.load(Ordering::Relaxed) >= 1 << 20);
}
