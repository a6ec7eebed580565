//! Why a run stopped ([`RunError`]) and what it kept ([`RunFailure`]).

use super::Run;
use crate::closed_loop::LoopError;
use crate::controller::ControlError;
use crate::model::ModelError;
use crate::robot::CableId;
use cdpr_numerics::IntegratorError;

/// Why a run stopped early.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The controller could not be designed at the run's start.
    #[error(transparent)]
    Control(#[from] ControlError),
    /// The loop could not be assembled (e.g. a controller with more states than it holds).
    #[error("{0}")]
    Loop(String),
    /// The integrator's error is part of the message (not a `source`, which a chain would print
    /// twice).
    #[error("integrator failed at t = {t} s: {error}")]
    Integrator { t: f64, error: IntegratorError },
    /// The effector left the workspace (below the highest anchor and, seen from above, inside
    /// the anchors' hull; the plane: 0 < x < d, z < 0): a run gone unstable, its numbers past
    /// here describe no robot.
    #[error(
        "the effector left the workspace at t = {t} s: {}, allowed below the highest anchor and between the anchors",
        coordinates(position)
    )]
    Workspace {
        t: f64,
        /// The effector's coordinates [m], per axis, the vertical last.
        position: Vec<f64>,
    },
    /// The shaper's design is still "auto": the modal analysis must resolve it first.
    #[error(
        "trajectory.shaper_frequency / shaper_damping = \"auto\" are not resolved: the registry's \
         simulate designs the shaper from the modal analysis before a run"
    )]
    UnresolvedShaper,
    /// A commanded tension ≤ 0 (MODELS.md §2): a cable cannot push.
    #[error("cable {cable} went slack at t = {t} s: commanded tension {tension} N ≤ 0")]
    SlackCable {
        t: f64,
        cable: CableId,
        tension: f64,
    },
    /// Stopped from outside (an interrupt) after the step that reached `t`.
    #[error("interrupted at t = {t} s")]
    Interrupted { t: f64 },
    /// The scenario asks for an integrator the model does not support.
    #[error(
        "simulation.integrator = \"{integrator}\" is not available for the {model} model: {why}"
    )]
    Unsupported {
        integrator: &'static str,
        model: &'static str,
        why: &'static str,
    },
}

/// "x = …, z = … m" (or x, y, z in space) for a message.
fn coordinates(position: &[f64]) -> String {
    let names: &[&str] = if position.len() == 3 {
        &["x", "y", "z"]
    } else {
        &["x", "z"]
    };
    let parts: Vec<String> = position
        .iter()
        .zip(names)
        .map(|(value, name)| format!("{name} = {value}"))
        .collect();
    format!("{} m", parts.join(", "))
}

impl From<LoopError> for RunError {
    fn from(e: LoopError) -> Self {
        match e {
            LoopError::Model(e) => RunError::Model(e),
            LoopError::Control(e) => RunError::Control(e),
            e @ LoopError::ControllerStates { .. } => RunError::Loop(e.to_string()),
        }
    }
}

/// A failed run: the reason and everything sampled before it.
#[derive(Debug, Clone)]
pub struct RunFailure {
    pub error: RunError,
    pub partial: Option<Run>,
}

impl std::fmt::Display for RunFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.error)?;
        if let Some(run) = &self.partial {
            write!(
                f,
                " (output kept up to t = {} s, {} samples)",
                run.t_reached,
                run.series.len()
            )?;
        }
        Ok(())
    }
}

impl std::error::Error for RunFailure {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.error)
    }
}
