//! The spatial lumped model's coordinates for the modal classification: the effector, each free
//! node with its cable's tangent there, each stored node's motion along its reel line.

use super::LumpedSpatial;
use cdpr_core::modal_layout::{Dof, ModalLayout};

impl LumpedSpatial {
    /// The effector and each free node with its cable's tangent; a stored node on a locked (or
    /// driven) reel held, all three coordinates frozen (the spatial modes study's case); on a
    /// reel pulled by tension it moves material along its reel line, listed as the coordinate on
    /// which r_i is largest with the other two frozen — exact for reel lines along an axis.
    pub(super) fn modal_layout_of(&self, y: &[f64]) -> ModalLayout {
        let n = self.elements;
        let mut layout = ModalLayout {
            dofs: vec![Dof::Effector {
                coordinates: (0..3).map(|axis| self.index(0, n, axis)).collect(),
                mass: self.robot.effector_mass,
            }],
            frozen: Vec::new(),
        };
        for cable in 0..self.robot.cables() {
            let r = self.stored[cable];
            let reel = self.reels[cable];
            let along = reel.iamax();
            let held = self.drive != super::reel::ReelDrive::Tension;
            for j in 0..n {
                if j < r && held {
                    // A locked (or driven) reel holds its stored line.
                    layout
                        .frozen
                        .extend((0..3).map(|axis| self.index(cable, j, axis)));
                } else if j < r {
                    for axis in (0..3).filter(|&a| a != along) {
                        layout.frozen.push(self.index(cable, j, axis));
                    }
                    layout.dofs.push(Dof::Axial {
                        cable,
                        index: self.index(cable, j, along),
                        mass: self.node_mass,
                    });
                } else {
                    let prev = if j == r {
                        self.pulley(cable)
                    } else {
                        self.node(y, cable, j - 1)
                    };
                    let tangent = (self.node(y, cable, j + 1) - prev).normalize();
                    layout.dofs.push(Dof::Node {
                        cable,
                        coordinates: (0..3).map(|axis| self.index(cable, j, axis)).collect(),
                        tangent: tangent.iter().copied().collect(),
                        mass: self.node_mass,
                    });
                }
            }
        }
        layout
    }
}
