//! The FE cable tests as one test binary: each file beside this one is a module here, so they
//! compile and link once and share the cores. `Cargo.toml` turns off the discovery of each file
//! as its own test; the allocation test stays a binary of its own, as it installs a counting
//! global allocator.

/// What the modules share (tests/common/mod.rs), compiled once.
mod common;
#[path = "damping.rs"]
mod damping;
#[path = "lagrangian.rs"]
mod lagrangian;
#[path = "prescribed_lengths.rs"]
mod prescribed_lengths;
#[path = "reweighted_matrix.rs"]
mod reweighted_matrix;
#[path = "statics_dynamics.rs"]
mod statics_dynamics;
