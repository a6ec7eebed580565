//! # cdpr-testing
//!
//! Support shared by the test suites of cdpr-bench, never by the library: the Python the
//! cross-code and Python-package tests need ([`python`]), and a global allocator that counts
//! allocations, for the tests that a right-hand side allocates nothing. A test binary installs
//! it with
//!
//! ```
//! #[global_allocator]
//! static GLOBAL: cdpr_testing::CountingAllocator = cdpr_testing::CountingAllocator;
//!
//! let before = cdpr_testing::allocations();
//! let v = vec![1.0f64; 8];
//! assert_eq!(cdpr_testing::allocations(), before + 1);
//! # drop(v);
//! ```

pub mod python;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    /// This thread's allocations: the test harness's own threads (its monitor of slow tests
    /// under a loaded machine) allocate too, and must not count against the code under test.
    /// Const-initialised without a destructor, so reading it never allocates.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, counting every allocation per thread.
pub struct CountingAllocator;

// SAFETY: every call is forwarded unchanged to the system allocator.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// Allocations made so far on this thread through [`CountingAllocator`] (0 if it is not the
/// global allocator).
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}
