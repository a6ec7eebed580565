//! The reels of the spatial lumped model: pulled by the commanded tensions, held still, or
//! driven by length (MODELS.md §11, the `length` controller on massive cables).
//!
//! A reel driven by length pays out the commanded free unstrained length l0_i(t). The stored
//! nodes are the line on the reel: they move with it as one, along r_i, their springs keeping
//! their lengths (wound line does not stretch), so that the free span is the only compliance, as
//! in the elastic model's reel that fixes the unstrained length at the pulley. Line of stretch
//! λ/l0 (the straddling spring's, at the pulley) crosses the pulley as unstrained length at the
//! reel's speed divided by that stretch, so the stored line is given
//!
//! ```text
//! v_i = −l̇0_i λ_{r−1} / l0            (speed along r_i; positive: reeling in)
//! v̇_i = −(l̈0_i λ_{r−1} + l̇0_i λ̇_{r−1}) / l0
//! a_j = v̇_i + (v_i − v_j) / τ          (each stored node j)
//! ```
//!
//! a_j is the command's own derivative plus a velocity loop of time constant τ
//! ([`REEL_TIME_CONSTANT`], far faster than the effector's modes, far slower than the line's
//! axial ones) that keeps each node's integrated speed on the command. A node reeled in takes
//! the reel's speed at once (the event records the kinetic energy it loses). The reel supplies
//! whatever force along r_i gives each stored node its acceleration against its springs and
//! gravity, F_j = m a_j − f_j·r_i, and does the work Σ_j F_j v_j: the energy balance's reel
//! power. A locked reel holds its stored line still (a_j = 0): the length controller holding
//! still.

use super::LumpedSpatial;
use cdpr_core::robot::PerCable;
pub use cdpr_core::robot::reels::REEL_TIME_CONSTANT;
use nalgebra::Vector3;

/// What moves each cable's stored line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum ReelDrive {
    /// The commanded tensions pull the reel end P_0 along r_i; the stored line slides freely.
    Tension,
    /// Every stored line held where it is.
    Locked,
    /// The stored lines moved so that the free unstrained lengths change at l̇0_i [m/s] by
    /// l̈0_i [m/s²].
    Length {
        rates: PerCable,
        accelerations: PerCable,
    },
}

impl LumpedSpatial {
    /// The speed v_i [m/s] and its rate v̇_i [m/s²] the reel gives the stored line of `cable`
    /// along r_i (the module's law): zero when locked, None when the reel is pulled by tension.
    #[inline]
    pub(super) fn reel_command(&self, y: &[f64], cable: usize) -> Option<(f64, f64)> {
        let (rate, acceleration) = match &self.drive {
            ReelDrive::Tension => return None,
            ReelDrive::Locked => return Some((0.0, 0.0)),
            ReelDrive::Length {
                rates,
                accelerations,
            } => (rates[cable], accelerations[cable]),
        };
        let Some(straddling) = self.stored[cable].checked_sub(1) else {
            return Some((0.0, 0.0));
        };
        let (length, stretch_rate, _, _) = self.spring(y, cable, straddling);
        let l0 = self.segment;
        Some((
            -rate * length / l0,
            -(acceleration * length + rate * stretch_rate) / l0,
        ))
    }

    /// The acceleration a_j [m/s²] along r_i the reel gives stored node `j` of `cable` under
    /// `command` = (v_i, v̇_i): 0 when locked.
    #[inline]
    pub(super) fn stored_acceleration(
        &self,
        y: &[f64],
        cable: usize,
        j: usize,
        (speed, speed_rate): (f64, f64),
    ) -> f64 {
        if self.drive == ReelDrive::Locked {
            return 0.0;
        }
        let own = self.node_velocity(y, cable, j).dot(&self.reels[cable]);
        speed_rate + (speed - own) / REEL_TIME_CONSTANT
    }

    /// The locked or driven reels' power into the cables [W]: Σ_j F_j v_j over the stored
    /// nodes, F_j = m a_j − f_j·r_i with f_j the force of node j's springs and of gravity.
    pub(super) fn driven_reel_power(&self, y: &[f64]) -> f64 {
        let weight = Vector3::new(0.0, 0.0, -self.node_mass * self.gravity());
        let mut power = 0.0;
        for cable in 0..self.robot.cables() {
            let Some(command) = self.reel_command(y, cable) else {
                continue;
            };
            let reel = self.reels[cable];
            let mut from_behind = Vector3::zeros();
            for j in 0..self.stored[cable] {
                let (length, rate, toward_next, toward_previous) = self.spring(y, cable, j);
                let t =
                    crate::spring_tension(self.stiffness, self.segment, self.damping, length, rate);
                let pull = (from_behind + t * toward_next + weight).dot(&reel);
                from_behind = t * toward_previous;
                let accel = self.stored_acceleration(y, cable, j, command);
                let speed = self.node_velocity(y, cable, j).dot(&reel);
                power += (self.node_mass * accel - pull) * speed;
            }
        }
        power
    }
}
