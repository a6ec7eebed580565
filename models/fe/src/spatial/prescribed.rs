//! Reels driven by length on the FE cables in space: Du's form (MODELS.md FE.5.6, FE.11.10) —
//! the free lengths l_i prescribed by the reels' velocity loop, their columns moved to the
//! right-hand side of the star, the stored cable on the reel — and the forces that impose them
//! (FE.7's reel work). Locked reels are the same form with no command.

use super::FeSpatial;
use super::star::StarSystem;
use nalgebra::Vector3;

impl FeSpatial {
    /// Locks every reel (or hands it to the commanded tensions): the length reels holding still
    /// (MODELS.md §11, the firmware's printer between moves) — Du's form with no command, each
    /// l_i held by the reel loop, the stored cable on the reel.
    pub fn lock_reels(&mut self, locked: bool) {
        self.length_driven = locked;
        self.drive = None;
    }

    /// The commanded l_i'' [m/s²]: l̈0_i plus the velocity loop (l̇0_i − l_i')/τ
    /// ([`cdpr_core::robot::reels::REEL_TIME_CONSTANT`]), as the lumped lines' reels.
    pub(super) fn commanded_l_acceleration(&self, y: &[f64], cable: usize) -> f64 {
        let l_rate = y[self.positions_len() + self.l_index(cable)];
        let (rate, acceleration) = self.drive.map_or((0.0, 0.0), |(r, a)| (r[cable], a[cable]));
        acceleration + (rate - l_rate) / cdpr_core::robot::reels::REEL_TIME_CONSTANT
    }

    /// Du's form (MODELS.md FE.5.6): l_i'' is known, so its columns move to the right-hand side
    /// and its row becomes l_i'' = the command; ρ_i (the reel side, not modelled) stays still.
    pub(super) fn prescribe_lengths(&self, sys: &mut StarSystem, y: &[f64]) {
        let nn = self.elements - 1;
        sys.hold_l_rows();
        for cable in 0..self.robot.cables() {
            let a = self.commanded_l_acceleration(y, cable);
            for k in cable * nn..(cable + 1) * nn {
                sys.force[k] -= sys.l_column[k] * a;
                sys.l_column[k] = Vector3::zeros();
            }
            sys.effector_force -= sys.effector_l[cable] * a;
            sys.effector_l[cable] = Vector3::zeros();
            sys.border[cable] = [1.0, 0.0, 1.0, a, 0.0];
        }
    }

    /// The force each driven reel needs to impose l_i, Q_l,i = (M q'' − F)_l of the span alone
    /// (MODELS.md FE.7: d/dt(E_span + E_P) = Σ Q_l,i l_i'), at `y` [N], assembled and solved
    /// afresh (each right-hand side keeps its own in `prescribing`).
    pub(super) fn prescribing_forces(&self, y: &[f64]) -> Vec<f64> {
        let (m, nn) = (self.robot.cables(), self.elements - 1);
        let mut sys = StarSystem::new(m, nn);
        self.assemble_into(&mut sys, y, &vec![0.0; m], false);
        self.prescribe_lengths(&mut sys, y);
        let mut nodes = vec![Vector3::zeros(); m * nn];
        let (mut effector, mut border) = (Vector3::zeros(), vec![[0.0; 2]; m]);
        let mut q = vec![f64::NAN; m];
        if sys.solve(&mut nodes, &mut effector, &mut border) {
            sys.held_l_residuals(&nodes, &effector, &border, &mut q);
        }
        q
    }
}
