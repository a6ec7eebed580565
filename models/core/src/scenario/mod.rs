//! The scenario of one run (MODELS.md §1, §9): TOML in, the paper's values as defaults.
//!
//! Every key is optional, so an empty file is the paper's scenario. Unknown keys, malformed TOML and
//! values outside their physical range are typed errors that name the key, the value and the allowed
//! range; nothing here panics on bad input.

use serde::Deserialize;

mod controller;
mod error;
mod printer;
mod spatial;
mod validate;
pub use controller::{Controller, ControllerKind, FlexCompensation};
pub use error::{
    MAX_ELEMENTS, ScenarioError, count_in_range, finite, non_negative, out_of_range, positive,
};
pub use printer::{FirmwareShaper, Printer};

use crate::shaper::{Impulses, ShaperKind};
use std::path::Path;

/// Robot geometry and effector (MODELS.md §1).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct Robot {
    /// Distance d between the pulleys A1 = (0, 0) and A2 = (d, 0) [m] (paper: 1 m).
    pub anchor_distance: f64,
    /// Effector point mass M [kg] (derived from eq. 15: 1 kg).
    pub effector_mass: f64,
    /// Gravitational acceleration g [m/s²], acting along −z.
    pub gravity: f64,
    /// A spatial robot's anchors [[x, y, z], …] [m] (MODELS.md §11: each cable's exit point from
    /// its pulley, z up; 2 ≤ m ≤ 8). Absent: the planar robot of `anchor_distance`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub anchors: Option<Vec<Vec<f64>>>,
    /// A spatial robot's reel directions r_i [[x, y, z], …], one per anchor: the line behind each
    /// pulley along which a massive cable's stored part lies (MODELS.md §11). Absent: horizontal,
    /// away from the anchors' centroid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reel_directions: Option<Vec<Vec<f64>>>,
}

impl Robot {
    /// Two anchors given as 2-vectors are the planar robot, spelled as MODELS.md §1 draws it:
    /// A1 = (0, 0), A2 = (d, 0) become `anchor_distance = d` (the same run, bit for bit). Other
    /// 2-vector anchors are refused by name: the planar model's pulleys sit at those points.
    fn read_planar_anchors(&mut self) -> Result<(), ScenarioError> {
        let Some(anchors) = &self.anchors else {
            return Ok(());
        };
        if !anchors.iter().any(|a| a.len() == 2) {
            return Ok(());
        }
        let given = format!("{anchors:?}");
        let d = match anchors.as_slice() {
            [a, b] if a.as_slice() == [0.0, 0.0] && b.len() == 2 && b[1] == 0.0 => b[0],
            _ => {
                return Err(out_of_range(
                    "robot.anchors",
                    given,
                    "two 2-vectors [[0, 0], [d, 0]] (the planar robot, MODELS.md §1), or 3-vectors \
                     [[x, y, z], …] for a spatial robot",
                ));
            }
        };
        let default = Self::default().anchor_distance;
        if self.anchor_distance != default && self.anchor_distance != d {
            return Err(out_of_range(
                "robot.anchors",
                given,
                format!(
                    "A2 = (anchor_distance, 0) = ({}, 0), or anchor_distance left out",
                    self.anchor_distance
                ),
            ));
        }
        positive("robot.anchors", d)?;
        self.anchor_distance = d;
        self.anchors = None;
        Ok(())
    }
}

impl Default for Robot {
    fn default() -> Self {
        Self {
            anchor_distance: 1.0,
            effector_mass: 1.0,
            gravity: 9.81,
            anchors: None,
            reel_directions: None,
        }
    }
}

/// Cable material (MODELS.md §1).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct Cable {
    /// Young's modulus E [Pa] (paper: 102 GPa).
    pub youngs_modulus: f64,
    /// Cross-section A [m²] (paper: 1.76e-6 m²).
    pub area: f64,
    /// Density ρ [kg/m³] (chosen: steel, 7850).
    pub density: f64,
    /// Unstrained length L0 of each modelled cable, free span plus stored part [m] (lumped and FE).
    pub modelled_length: f64,
    /// Kelvin–Voigt axial damping coefficient C [N s] (massive-cable models; 0 in the paper's run).
    pub axial_damping: f64,
}

impl Default for Cable {
    fn default() -> Self {
        Self {
            youngs_modulus: 102e9,
            area: 1.76e-6,
            density: 7850.0,
            modelled_length: 1.0,
            axial_damping: 0.0,
        }
    }
}

impl Cable {
    /// Axial stiffness EA [N].
    pub fn axial_stiffness(&self) -> f64 {
        self.youngs_modulus * self.area
    }
    /// Mass per unstrained length μ = ρA [kg/m].
    pub fn mass_per_length(&self) -> f64 {
        self.density * self.area
    }
}

/// The `[model]` section as written: the cable model's `kind` and its own keys. The core knows no
/// cable model: each model crate owns its keys' defaults and validation, and the registry crate
/// (`cdpr-bench`) reads this section into its typed model choice.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, serde::Serialize)]
#[serde(transparent)]
pub struct ModelSection(pub toml::Table);

/// Trajectory family; the paper uses only `step5` (eq. 13).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TrajectoryKind {
    #[default]
    Step5,
}

/// Reference trajectory of the effector's x (paper §3.1).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct Trajectory {
    pub kind: TrajectoryKind,
    /// Start position x1 [m].
    pub x1: f64,
    /// End position x2 [m].
    pub x2: f64,
    /// Start time t1 [s].
    pub t1: f64,
    /// End time t2 [s].
    pub t2: f64,
    /// The vertical reference (absent: [`ZRef::Hold`] for controllers that act on z, else
    /// [`ZRef::Free`]; see [`Scenario::z_ref`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z_ref: Option<ZRef>,
    /// The input shaper the move is convolved with ([`crate::shaper`]).
    #[serde(skip_serializing_if = "is_default")]
    pub shaper: ShaperKind,
    /// The shaped mode's natural frequency [rad/s], or "auto": the least-damped vertical mode
    /// of the model's closed loop at x2.
    #[serde(skip_serializing_if = "is_default")]
    pub shaper_frequency: Designed,
    /// The shaped mode's damping ratio, or "auto" (that mode's).
    #[serde(skip_serializing_if = "is_default")]
    pub shaper_damping: Designed,
    /// The EI family's tolerated residual vibration V_tol (0, 1).
    #[serde(skip_serializing_if = "is_default_vtol")]
    pub shaper_vtol: f64,
    /// A spatial robot's move: the start pose [x, y, z] [m] (eq. 13 along the straight segment
    /// to `end`; x1, x2 are the plane's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start: Option<Vec<f64>>,
    /// A spatial robot's move: the end pose [x, y, z] [m].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end: Option<Vec<f64>>,
}

fn is_default<T: Default + PartialEq>(v: &T) -> bool {
    *v == T::default()
}

fn is_default_vtol(v: &f64) -> bool {
    *v == DEFAULT_VTOL
}

/// Tolerated residual vibration of the EI shapers unless given (firmware's 5 %).
pub const DEFAULT_VTOL: f64 = 0.05;

/// A shaper design value: a number, or "auto" (from the modal analysis).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, serde::Serialize)]
#[serde(untagged)]
pub enum Designed {
    Value(f64),
    Auto(AutoWord),
}

/// The word `"auto"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum AutoWord {
    #[default]
    Auto,
}

impl Default for Designed {
    fn default() -> Self {
        Designed::Auto(AutoWord::Auto)
    }
}

impl Designed {
    /// The value, or None for "auto".
    pub fn value(self) -> Option<f64> {
        match self {
            Designed::Value(v) => Some(v),
            Designed::Auto(_) => None,
        }
    }
}

impl Trajectory {
    /// The shaper's impulses: the unshaped move for `shaper = "none"`; `Ok(None)` while a design
    /// value is still "auto" (the registry resolves it from the modal analysis).
    pub fn impulses(&self) -> Result<Option<Impulses>, ScenarioError> {
        if self.shaper == ShaperKind::None {
            return Ok(Some(Impulses::none()));
        }
        match (self.shaper_frequency.value(), self.shaper_damping.value()) {
            (Some(omega), Some(zeta)) => {
                Impulses::design(self.shaper, omega, zeta, self.shaper_vtol).map(Some)
            }
            _ => Ok(None),
        }
    }
}

/// The reference of the effector's height.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ZRef {
    /// Not controlled: z is left to the statics (the paper). Errors in z are measured against
    /// the start height z0.
    Free,
    /// The start height z0 held: a straight horizontal print line.
    Hold,
}

impl Default for Trajectory {
    fn default() -> Self {
        Self {
            kind: TrajectoryKind::Step5,
            x1: 0.5,
            x2: 0.6,
            t1: 0.0,
            t2: 0.2,
            z_ref: None,
            shaper: ShaperKind::None,
            shaper_frequency: Designed::default(),
            shaper_damping: Designed::default(),
            shaper_vtol: DEFAULT_VTOL,
            start: None,
            end: None,
        }
    }
}

/// Time integrator family.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum IntegratorKind {
    /// Dormand–Prince 5(4) with dense output (the paper's ode45).
    #[default]
    Dopri5,
    /// Implicit path for the stiff cable models (MODELS.md §6).
    Implicit,
}

impl IntegratorKind {
    /// The scenario file's spelling.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Dopri5 => "dopri5",
            IntegratorKind::Implicit => "implicit",
        }
    }
}

/// Implicit method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default, serde::Serialize)]
pub enum ImplicitMethod {
    #[default]
    #[serde(rename = "generalized-alpha")]
    GeneralizedAlpha,
}

/// Integration settings (MODELS.md §1, §6).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct Simulation {
    /// Final time [s].
    pub t_final: f64,
    /// Relative tolerance of the error norm.
    pub rtol: f64,
    /// Absolute tolerance of the error norm (every state component).
    pub atol: f64,
    /// Output sample period [s], from the dense output.
    pub sample_period: f64,
    /// Step-size controller β (Hairer's PI stabilisation; 0 = scipy RK45).
    pub dopri_beta: f64,
    pub integrator: IntegratorKind,
    pub implicit_method: ImplicitMethod,
    /// Fixed step of the implicit method [s], or its first step when `adaptive`.
    pub step: f64,
    /// Spectral radius at infinity of generalized-α.
    pub rho_inf: f64,
    /// Error control of the implicit method: each step's local error estimate, held within
    /// √rtol × (atol + rtol |q|), chooses the next step (numerics `alpha_error`), up to
    /// [`Scenario::largest_adaptive_step`]. Off by default: the fixed `step` (written into a
    /// run's provenance only when on, so that today's results stay byte for byte).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub adaptive: bool,
    /// What the error control of an `adaptive` implicit run measures (written into a run's
    /// provenance only when not the default).
    #[serde(skip_serializing_if = "ErrorNorm::is_all")]
    pub error_norm: ErrorNorm,
}

/// The coordinates whose local error an `adaptive` implicit run holds within its tolerances.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ErrorNorm {
    /// Every position of the model and the controller's states, as DOPRI5 measures them.
    #[default]
    All,
    /// The effector's position and the controller's states: the cables' own vibrations (a
    /// lumped line's nodes ringing at µm long after the effector has settled) are integrated at
    /// the effector's steps and, where those do not resolve them, damped by ρ∞ as on the fixed
    /// step (docs/numerics.md).
    Effector,
}

impl ErrorNorm {
    /// The scenario file's spelling.
    pub fn name(self) -> &'static str {
        match self {
            ErrorNorm::All => "all",
            ErrorNorm::Effector => "effector",
        }
    }

    fn is_all(&self) -> bool {
        *self == ErrorNorm::All
    }
}

impl Default for Simulation {
    fn default() -> Self {
        Self {
            t_final: 5.0,
            rtol: 1e-5,
            atol: 1e-9,
            sample_period: 1e-5,
            dopri_beta: 0.04,
            integrator: IntegratorKind::Dopri5,
            implicit_method: ImplicitMethod::GeneralizedAlpha,
            step: 1e-4,
            rho_inf: 0.9,
            adaptive: false,
            error_norm: ErrorNorm::All,
        }
    }
}

/// Whether a run computes the closed-loop modes at the end of the move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ModesChoice {
    /// When the linearised loop is small enough for the dense eigen-analysis (up to
    /// `cdpr_analysis::linearise::DENSE_MAX_STATES` states); skipped with a note above it.
    #[default]
    Auto,
    /// Never.
    Off,
}

/// The analyses a run makes besides integrating (MODELS.md §7's metrics are always computed).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Analysis {
    /// The closed-loop modes at the end of the move (the vertical mode of MODELS.md §8).
    pub modes: ModesChoice,
}

/// One run, validated. Construct with [`Scenario::from_toml_str`], [`Scenario::from_file`] or
/// [`Scenario::paper`]; after changing fields by hand call [`Scenario::validate`].
#[derive(Debug, Clone, PartialEq, Deserialize, Default, serde::Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scenario {
    pub robot: Robot,
    pub cable: Cable,
    pub model: ModelSection,
    pub controller: Controller,
    pub trajectory: Trajectory,
    pub simulation: Simulation,
    pub analysis: Analysis,
    /// The printing firmware's limits and frame (`cargo xtask plan`, `print`); absent for a
    /// robot that only makes moves.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub printer: Option<Printer>,
}

/// Fewest implicit steps over the move [t1, t2] ([`Scenario::largest_implicit_step`]).
pub const STEPS_PER_MOVE: f64 = 20.0;

/// Largest number of output samples accepted (memory guard: ~50 channels × 8 B each).
pub const MAX_SAMPLES: f64 = 2.0e7;

impl Scenario {
    /// The paper's scenario (MODELS.md §1), with the elastic model.
    pub fn paper() -> Self {
        Self::default()
    }

    /// The planar robot of the `[robot]` section: pulleys A1 = (0, 0) and A2 = (d, 0), z up
    /// (validated with the scenario).
    pub fn robot(&self) -> crate::robot::Robot<2> {
        let r = &self.robot;
        let anchors = [
            crate::robot::Vector::<2>::new(0.0, 0.0),
            crate::robot::Vector::<2>::new(r.anchor_distance, 0.0),
        ];
        crate::robot::Robot::new(&anchors, r.effector_mass, r.gravity)
            .expect("a validated scenario's robot")
    }

    /// The spatial robot of `[robot] anchors` (validated with the scenario); None for the planar
    /// robot.
    pub fn spatial_robot(&self) -> Option<crate::robot::Robot<3>> {
        let anchors: Vec<crate::robot::Vector<3>> = self
            .robot
            .anchors
            .as_ref()?
            .iter()
            .map(|a| crate::robot::Vector::<3>::from_iterator(a.iter().copied()))
            .collect();
        crate::robot::Robot::new(&anchors, self.robot.effector_mass, self.robot.gravity).ok()
    }

    /// Parses and validates a scenario from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Self, ScenarioError> {
        let mut scenario: Scenario = toml::from_str(text)
            .map_err(|e| ScenarioError::Syntax(e.to_string().trim_end().to_owned()))?;
        scenario.robot.read_planar_anchors()?;
        scenario.validate()?;
        Ok(scenario)
    }

    /// Reads, parses and validates a scenario file.
    pub fn from_file(path: &Path) -> Result<Self, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|error| ScenarioError::Io {
            path: path.display().to_string(),
            error,
        })?;
        Self::from_toml_str(&text)
    }

    /// The largest fixed step [s] the implicit path accepts: generalised-α is unconditionally
    /// stable, so nothing stops a step that skips over the physics but this rule. The step must
    /// resolve the move ([`STEPS_PER_MOVE`] steps over [t1, t2]) and the controller's fastest
    /// dynamics, the derivative filter's time constant 1/N_f (paper: 1.85 ms; the paper runs use
    /// 1e-4 s). A step of 1 s was accepted before and returned T1 min 76.1 N instead of 91.8 N.
    pub fn largest_implicit_step(&self) -> f64 {
        self.largest_adaptive_step()
            .min(1.0 / self.controller.filter)
    }

    /// The largest step of an `adaptive` implicit run [s]: the move resolved as on the fixed
    /// path ([`STEPS_PER_MOVE`] steps over [t1, t2]). The controller's dynamics, which bound
    /// the fixed step, are the error norm's to resolve: it measures the controller's states
    /// (`Controller::state_weights`).
    pub fn largest_adaptive_step(&self) -> f64 {
        let t = &self.trajectory;
        (t.t2 - t.t1) / STEPS_PER_MOVE
    }

    /// The vertical reference in force: the trajectory's `z_ref`, or the controller's default.
    pub fn z_ref(&self) -> ZRef {
        self.trajectory
            .z_ref
            .unwrap_or(if self.controller.kind.acts_on_z() {
                ZRef::Hold
            } else {
                ZRef::Free
            })
    }

    /// The free cable length the trajectory needs, for the massive-cable models' rule on
    /// `cable.modelled_length` (MODELS.md §9): 1.05 × (1 + ΣT/EA) × the longest chord from a
    /// pulley to the trajectory, the chord's depth bounded by the elastic model's mid-span sag.
    /// Returns (free length [m], longest chord [m]).
    pub fn free_length_needed(&self) -> (f64, f64) {
        let r = &self.robot;
        let t = &self.trajectory;
        let sag = 0.5
            * r.anchor_distance
            * (r.effector_mass * r.gravity / self.controller.tension_sum)
                .asin()
                .tan();
        let reach = t.x1.max(t.x2).max(r.anchor_distance - t.x1.min(t.x2));
        let chord = reach.hypot(sag);
        let stretch = 1.0 + self.controller.tension_sum / self.cable.axial_stiffness();
        (1.05 * stretch * chord, chord)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_file_is_the_paper() {
        let s = Scenario::from_toml_str("").unwrap();
        assert_eq!(s, Scenario::paper());
        assert_eq!(s.cable.axial_stiffness(), 102e9 * 1.76e-6);
        assert!(s.model.0.is_empty());
    }
}
