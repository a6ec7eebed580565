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
use std::sync::atomic::{AtomicUsize, Ordering};

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

/// The system allocator, counting every allocation.
pub struct CountingAllocator;

// SAFETY: every call is forwarded unchanged to the system allocator.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// Allocations made so far through [`CountingAllocator`] (0 if it is not the global allocator).
pub fn allocations() -> usize {
    ALLOCATIONS.load(Ordering::SeqCst)
}
