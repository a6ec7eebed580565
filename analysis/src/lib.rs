//! # cdpr-analysis
//!
//! What cdpr-bench measures in a run and around an equilibrium, knowing no cable model: amplitude
//! spectra ([`spectrum`]), the metrics of MODELS.md §7 ([`metrics`]), the closed loop's
//! linearisation and its modes ([`linearise`]), their classification ([`modes`]) and the
//! stability margins built on them ([`damping`]).
//!
//! Why a crate of its own: these read a run or a linearised loop and never take part in one, so
//! the core (the robot and its runner) stays free of FFTs and eigen-solvers, and an analysis can
//! be added without touching what is simulated.

pub mod contour;
pub mod control_metrics;
pub mod damping;
pub mod linearise;
pub mod metrics;
pub mod modes;
pub mod rest_modes;
pub mod spatial;
pub mod spectrum;

use cdpr_core::model::ModelError;
use cdpr_numerics::eigen::{EvdError, ModalError};

/// Why an analysis could not be made.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// The model refused the state or found no equilibrium.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The closed loop could not be built or brought to rest.
    #[error(transparent)]
    Loop(#[from] cdpr_core::closed_loop::LoopError),
    #[error("eigenvalue computation failed: {0:?}")]
    Eigen(EvdError),
    #[error(transparent)]
    Modal(#[from] ModalError),
    #[error("no oscillatory closed-loop mode found")]
    NoMode,
    /// The sparse shift-invert eigen-solve failed (a singular K − ω²M at the shift, or the
    /// Lanczos iteration).
    #[error("sparse eigen-solve near the shift: {0}")]
    Sparse(String),
    /// The mass matrix over the free coordinates has no Cholesky factor: a free coordinate
    /// carries no kinetic energy (it should be frozen in the model's layout).
    #[error("the mass matrix over the free coordinates is not positive definite")]
    MassNotPositive,
    /// The model offers no second-order form to read its mass and stiffness from.
    #[error("the model offers no second-order form (mass and stiffness matrices)")]
    NoSecondOrder,
    /// The dense eigen-analysis would cost more than it is allowed (time O(n³), memory O(n²)).
    #[error(
        "the linearised loop has {states} states, more than the dense eigen-analysis's limit of {limit} (lumped N ≤ 249, FE N ≤ 499)"
    )]
    TooLarge { states: usize, limit: usize },
}
