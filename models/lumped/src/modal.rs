//! The lumped model's coordinates for the modal classification: the effector, each free node
//! with its cable's tangent there, each stored node's x (which moves material along the reel
//! line) and its z, held at 0 by MODELS.md §4 eq. 6.

use crate::Lumped;
use cdpr_core::modal_layout::{Dof, ModalLayout};

impl Lumped {
    /// The coordinates of `y` as the modal analysis classifies them.
    pub(crate) fn modal_layout_of(&self, y: &[f64]) -> ModalLayout {
        let n = self.elements;
        let mut layout = ModalLayout {
            dofs: vec![Dof::Effector {
                coordinates: vec![self.x_index(0, n), self.z_index(0, n)],
                mass: self.effector_mass,
            }],
            frozen: Vec::new(),
        };
        for cable in 0..2 {
            let r = self.stored()[cable];
            for j in 0..n {
                let (x, z) = (self.x_index(cable, j), self.z_index(cable, j));
                if j < r {
                    layout.frozen.push(z);
                    layout.dofs.push(Dof::Axial {
                        cable,
                        index: x,
                        mass: self.node_mass,
                    });
                } else {
                    let prev = if j == r {
                        self.pulley(cable)
                    } else {
                        self.node(y, cable, j - 1)
                    };
                    let next = self.node(y, cable, j + 1);
                    let tangent = (next - prev).normalize();
                    layout.dofs.push(Dof::Node {
                        cable,
                        coordinates: vec![x, z],
                        tangent: vec![tangent.x, tangent.y],
                        mass: self.node_mass,
                    });
                }
            }
        }
        layout
    }
}
