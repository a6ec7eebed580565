//! The `[controller]` section: which controller closes the loop, its gains, the paper's
//! pretension ΣT (it sets the start equilibrium for every controller) and the tension limits
//! every controller obeys. Each kind's gains are keys of the same section; a kind ignores the
//! others' keys (see [`crate::controller`] for the equations).

use super::{Robot, ScenarioError, finite, non_negative, out_of_range, positive};
use crate::robot::distribution::DistributionMethod;
use serde::Deserialize;

/// The controller that computes the commanded tensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, serde::Serialize, Default)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum ControllerKind {
    /// The paper's PID on x, ΣT fixed (§3.2); z is left to the statics.
    #[default]
    Pid,
    /// The paper's PID on x plus a PID on z, decoupled through the structure matrix W.
    PidXz,
    /// Feedback linearisation of the effector on rigid massless cables.
    ComputedTorque,
    /// Linear-quadratic state feedback with integral action, designed on the elastic loop.
    Lqr,
    /// The reels follow unstrained lengths with a flex compensation, as printer firmware does
    /// (spatial robots).
    Length,
}

/// How the `length` controller stretches the reference's cable lengths (MODELS.md §11).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, serde::Serialize, Default)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum FlexCompensation {
    /// By the distribution of the static load M g at p_ref(t) (the firmware's).
    #[default]
    Static,
    /// By the distribution of M (a_ref − g⃗).
    Dynamic,
    /// Not at all: the start pose's lengths shifted by the geometric length change.
    None,
}

impl ControllerKind {
    /// Every tension controller, in the leaderboard's order (the planar robot's controllers).
    pub const ALL: [ControllerKind; 4] = [
        ControllerKind::Pid,
        ControllerKind::PidXz,
        ControllerKind::ComputedTorque,
        ControllerKind::Lqr,
    ];

    /// The scenario file's spelling.
    pub fn name(self) -> &'static str {
        match self {
            ControllerKind::Pid => "pid",
            ControllerKind::PidXz => "pid-xz",
            ControllerKind::ComputedTorque => "computed-torque",
            ControllerKind::Lqr => "lqr",
            ControllerKind::Length => "length",
        }
    }

    /// Whether the controller acts on z (its default reference then holds the start height).
    pub fn acts_on_z(self) -> bool {
        self != ControllerKind::Pid
    }
}

/// Controller choice, gains and tension distribution (MODELS.md §2 for the paper's PID).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct Controller {
    pub kind: ControllerKind,
    /// Proportional gain P [N/m] (x loop of `pid` and `pid-xz`).
    pub p: f64,
    /// Integral gain I [N/(m s)].
    pub i: f64,
    /// Derivative gain D [N s/m].
    pub d: f64,
    /// Derivative filter coefficient N_f [1/s] (both loops of `pid-xz`).
    pub filter: f64,
    /// Pretension sum ΣT = T1 + T2 [N]: the paper's PID holds it; every controller starts from
    /// the equilibrium it sets (MODELS.md §2).
    pub tension_sum: f64,
    /// Optional lower saturation of the commanded tensions [N] (absent = off).
    pub t_min: Option<f64>,
    /// Optional upper saturation of the commanded tensions [N] (absent = off).
    pub t_max: Option<f64>,
    /// `pid-xz`: z-loop proportional gain [N/m].
    pub p_z: f64,
    /// `pid-xz`: z-loop integral gain [N/(m s)].
    pub i_z: f64,
    /// `pid-xz`: z-loop derivative gain [N s/m].
    pub d_z: f64,
    /// `computed-torque`: proportional gain K_p [1/s²] of the error dynamics.
    pub kp: f64,
    /// `computed-torque`: derivative gain K_d [1/s].
    pub kd: f64,
    /// `computed-torque`: integral gain K_i [1/s³] (0 = PD).
    pub ki: f64,
    /// `computed-torque`, `lqr`: corner ω_f of the second-order low-pass on the velocity error
    /// [rad/s] (`inf`: unfiltered).
    pub velocity_filter: f64,
    /// `lqr`: weight of the position error [1/m²].
    pub q_position: f64,
    /// `lqr`: weight of the velocity error [s²/m²].
    pub q_velocity: f64,
    /// `lqr`: weight of the integrated position error [1/(m² s²)].
    pub q_integral: f64,
    /// `lqr`: weight of the tension deviation [1/N²].
    pub r: f64,
    /// How a redundantly actuated robot (more cables than axes) turns the controller's wrench
    /// into tensions in the box [t_min, t_max] (MODELS.md §11). Robots with as many cables as
    /// axes solve W T = w directly and ignore it.
    #[serde(skip_serializing_if = "is_qp")]
    pub distribution: DistributionMethod,
    /// `length`: how the reels' lengths allow for the cables' stretch.
    #[serde(skip_serializing_if = "is_static")]
    pub flex_compensation: FlexCompensation,
}

fn is_static(flex: &FlexCompensation) -> bool {
    *flex == FlexCompensation::Static
}

fn is_qp(method: &DistributionMethod) -> bool {
    *method == DistributionMethod::Qp
}

impl Default for Controller {
    fn default() -> Self {
        Self {
            kind: ControllerKind::Pid,
            p: 1860.0,
            i: 8700.0,
            d: 100.0,
            filter: 540.0,
            tension_sum: 200.0,
            t_min: None,
            t_max: None,
            // A z loop of the x loop's bandwidth on a stiffer plant (see docs/control.md).
            p_z: 1860.0,
            i_z: 8700.0,
            d_z: 100.0,
            // Error poles (s + 100)³: 3ω, 3ω², ω³ at ω = 100 rad/s, the fastest that keeps the
            // massive-cable loops' axial modes within 0.04 1/s of neutral (docs/control.md).
            kp: 30_000.0,
            kd: 300.0,
            ki: 1_000_000.0,
            // Well below the cables' first axial mode (≈ 5 800 rad/s), 4× above ω.
            velocity_filter: 400.0,
            // Bryson's rule: 32 µm, 10 mm/s, 10 µm·s of error against 1 N of tension; closed-loop
            // poles near the computed-torque's.
            q_position: 1e9,
            q_velocity: 1e4,
            q_integral: 1e10,
            r: 1.0,
            distribution: DistributionMethod::Qp,
            flex_compensation: FlexCompensation::Static,
        }
    }
}

impl Controller {
    /// Checks the gains of the chosen kind and the limits against the pretension and the
    /// effector's weight.
    pub(super) fn validate(&self, robot: &Robot) -> Result<(), ScenarioError> {
        self.validate_gains()?;
        self.validate_limits(robot)
    }

    /// The chosen kind's gains (and the paper's pretension, which every start uses).
    pub(super) fn validate_gains(&self) -> Result<(), ScenarioError> {
        non_negative("controller.p", self.p)?;
        non_negative("controller.i", self.i)?;
        non_negative("controller.d", self.d)?;
        positive("controller.filter", self.filter)?;
        positive("controller.tension_sum", self.tension_sum)?;
        match self.kind {
            ControllerKind::Pid => {}
            ControllerKind::PidXz => {
                non_negative("controller.p_z", self.p_z)?;
                non_negative("controller.i_z", self.i_z)?;
                non_negative("controller.d_z", self.d_z)?;
            }
            ControllerKind::ComputedTorque => {
                corner(self.velocity_filter)?;
                positive("controller.kp", self.kp)?;
                positive("controller.kd", self.kd)?;
                non_negative("controller.ki", self.ki)?;
                // Routh–Hurwitz for s³ + K_d s² + K_p s + K_i: stable iff K_d K_p > K_i.
                if self.ki >= self.kd * self.kp {
                    return Err(out_of_range(
                        "controller.ki",
                        self.ki,
                        format!(
                            "< kd·kp = {} 1/s³ (Routh–Hurwitz: the error dynamics are unstable otherwise)",
                            self.kd * self.kp
                        ),
                    ));
                }
            }
            ControllerKind::Lqr => {
                corner(self.velocity_filter)?;
                positive("controller.q_position", self.q_position)?;
                non_negative("controller.q_velocity", self.q_velocity)?;
                // Without a weight the integral states are not detectable: the CARE has no
                // stabilising solution and the design fails.
                positive("controller.q_integral", self.q_integral)?;
                positive("controller.r", self.r)?;
            }
            ControllerKind::Length => {}
        }
        Ok(())
    }

    pub(super) fn validate_limits(&self, robot: &Robot) -> Result<(), ScenarioError> {
        let weight = robot.effector_mass * robot.gravity;
        if let Some(t_min) = self.t_min {
            finite("controller.t_min", t_min)?;
            if t_min < 0.0 || t_min >= 0.5 * self.tension_sum {
                return Err(out_of_range(
                    "controller.t_min",
                    t_min,
                    format!(
                        "[0, tension_sum/2 = {}) N: the start equilibrium's tensions share ΣT",
                        0.5 * self.tension_sum
                    ),
                ));
            }
        }
        if let Some(t_max) = self.t_max {
            finite("controller.t_max", t_max)?;
            let lower = self.t_min.unwrap_or(0.0).max(0.0);
            if t_max <= lower {
                return Err(out_of_range(
                    "controller.t_max",
                    t_max,
                    format!("> t_min = {lower} N (finite)"),
                ));
            }
            // Two cables at t_max hold at most 2 t_max vertically, and the start equilibrium
            // needs T1 + T2 = ΣT with each ≤ t_max.
            let needed = (0.5 * self.tension_sum).max(0.5 * weight);
            if t_max < needed {
                return Err(out_of_range(
                    "controller.t_max",
                    t_max,
                    format!(
                        "≥ max(tension_sum/2, M g/2) = {needed} N: two cables at t_max cannot \
                         hold the effector's weight or its start pretension otherwise"
                    ),
                ));
            }
        }
        if weight > 0.0 && weight >= self.tension_sum {
            return Err(out_of_range(
                "controller.tension_sum",
                self.tension_sum,
                format!(
                    "> effector weight M g = {weight} N (the cables cannot hold the effector otherwise)"
                ),
            ));
        }
        Ok(())
    }
}

/// The velocity filter's corner: > 0, `inf` for none.
fn corner(omega: f64) -> Result<(), ScenarioError> {
    if omega > 0.0 {
        Ok(())
    } else {
        Err(out_of_range(
            "controller.velocity_filter",
            omega,
            "> 0 rad/s (inf: unfiltered)",
        ))
    }
}
