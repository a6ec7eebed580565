//! # cdpr-core
//!
//! The robot of cdpr-bench, and nothing about any one cable model: the scenario (MODELS.md §9),
//! the `step5` trajectory (paper eq. 13), the PID and tension distribution (§3.2), the
//! [`model::CableModel`] interface (with its second-order form and what the modal analysis needs
//! from a model), the closed loop and the runner that integrates and samples it.
//!
//! Dependencies point one way: the numerical methods come from `cdpr-numerics`; the models
//! depend on this crate; this crate knows no model.

pub mod channel;
pub mod closed_loop;
pub mod controller;
pub mod fixed_end;
pub mod geometry;
pub mod modal_layout;
pub mod model;
pub mod print_path;
pub mod robot;
pub mod runner;
pub mod scenario;
pub mod second_order;
pub mod series;
pub mod shaper;
pub mod statics;
pub mod trajectory;

pub use nalgebra::Vector2;
