//! # cdpr-core
//!
//! Everything the cable models of cdpr-bench share, and nothing about any one cable: the scenario
//! (MODELS.md §9), the `step5` trajectory (paper eq. 13), the PID and tension distribution (§3.2),
//! the [`model::CableModel`] interface, the closed loop and its runner, the integrators, the static
//! Newton service, spectra, metrics and the closed-loop linearisation.
//!
//! Dependencies point one way: models depend on this crate; this crate knows no model.

pub mod closed_loop;
pub mod controller;
pub mod geometry;
pub mod integrate;
pub mod metrics;
pub mod modal;
pub mod model;
pub mod scenario;
pub mod second_order;
pub mod series;
pub mod spectrum;
pub mod statics;
pub mod trajectory;

pub use nalgebra::Vector2;
