//! # cdpr-bench
//!
//! The library a user of cdpr-bench depends on: every cable model behind one registry
//! ([`ModelKind`]), the scenario read and checked as a whole ([`scenario_from_toml_str`],
//! [`scenario_from_file`]), the scenario's model built ([`build`], [`with_model`]) and a study run
//! on it ([`simulate`], [`assess`], [`analyse`]).
//!
//! The crates below it each hold one part: `cdpr-numerics` (integrators, sparse LU, Newton),
//! `cdpr-core` (the robot: scenario, trajectory, controller, model interface, closed loop and
//! runner), `cdpr-elastic`, `cdpr-lumped` and `cdpr-fe` (the cable models) and `cdpr-analysis`
//! (spectra, metrics, modes). This crate is the only one that knows them all.
//!
//! # Examples
//!
//! Load a scenario, pick a model, run it and read its metrics and time series:
//!
//! ```
//! use cdpr_bench::{ModelKind, assess, scenario_from_toml_str, with_model_kind};
//! use cdpr_bench::core::channel::Channel;
//!
//! // The paper's scenario (every key defaults to it), shortened to 1.5 s.
//! let scenario = scenario_from_toml_str(
//!     "[simulation]\nt_final = 1.5\nsample_period = 1e-3",
//! )?;
//! let scenario = with_model_kind(&scenario, ModelKind::Elastic)?;
//!
//! let outcome = assess(&scenario, &mut |_fraction_done| {})?;
//! // The paper's T1 minimum during the move: 92 N (MODELS.md §8).
//! assert!((outcome.metrics.t1_min - 92.0).abs() < 1.0);
//! // The closed-loop vertical mode at x2, next to eq. 15's 20.41 rad/s.
//! let end = outcome.end.state().expect("the elastic loop is small");
//! assert!((end.mode.omega - 20.37).abs() < 0.01);
//!
//! let series = &outcome.run.series;
//! let x = series.column(Channel::X).expect("every run has x");
//! assert_eq!(x.len(), 1501);
//! assert!((x[1500] - 0.6).abs() < 1e-4);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod build;
mod config;
mod kind;
pub mod memory;
mod print;
mod provenance;
mod spatial;
mod study;

pub use build::{BuildError, DynModel, ModelVisitor, build, with_model};
pub use config::{
    ModelConfig, scenario_from_file, scenario_from_toml_str, validate, with_model_kind,
};
pub use kind::ModelKind;
pub use print::{
    FEASIBILITY_RATE, PreparedPrint, PrintRun, SETTLE, contour_of, gcode_home, plan_layers,
    positions, prepare_print, print_options, simulate_print,
};
pub use provenance::{Provenance, project_revision, revision};
pub use spatial::{
    FEASIBILITY_SAMPLES, InfeasibleReference, SpatialRun, check_feasible, check_reference,
    prepare_spatial, prepare_spatial_start, simulate_spatial, simulate_spatial_into,
    spatial_channel_headings, spatial_channels, spatial_metrics, spatial_metrics_of, spatial_robot,
};
pub use study::{
    Assessed, EndAnalysis, Error, analyse, assess, assess_observed, assess_observed_into,
    damping_sweep, end_analysis, end_state, eq15_at_end, growth_resolution,
    least_damped_vertical_mode, linearise, metrics, mode_as_integrated, prepare, resolve_shaper,
    simulate, simulate_observed, simulate_observed_into,
};

/// The crates this one composes, for their types.
pub use cdpr_analysis as analysis;
pub use cdpr_core as core;
pub use cdpr_elastic as elastic;
pub use cdpr_fe as fe;
pub use cdpr_lumped as lumped;
pub use cdpr_numerics as numerics;
pub use cdpr_printing as printing;
