//! The numerical methods tests as one test binary: each file beside this one is a module here,
//! so they compile and link once and share the cores. `Cargo.toml` turns off the discovery of
//! each file as its own test.

#[path = "alpha_error.rs"]
mod alpha_error;
/// What the modules share (tests/common/mod.rs), compiled once.
mod common;
#[path = "differences.rs"]
mod differences;
#[path = "dopri5.rs"]
mod dopri5;
#[path = "eigen.rs"]
mod eigen;
#[path = "generalized_alpha.rs"]
mod generalized_alpha;
#[path = "newton.rs"]
mod newton;
#[path = "norms.rs"]
mod norms;
#[path = "riccati.rs"]
mod riccati;
#[path = "sparse.rs"]
mod sparse;
