//! # cdpr-verify
//!
//! The verification of cdpr-bench against what it did not compute: the acceptance table of
//! MODELS.md §8 (the paper's numbers, ours, the tolerance, pass/fail), which both the tests and
//! the report use, and Irvine's elastic catenary as an independent reference. Its `tests/` hold
//! the reference cases and the cross-model comparisons.

pub mod acceptance;
pub mod irvine;
pub mod spatial;
