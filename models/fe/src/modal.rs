//! The FE model's coordinates for the modal classification: the effector, each interior node of
//! a span with its cable's tangent there, and the lengths l_i and ρ_i, which move material along
//! the cable.

use crate::Fe;
use cdpr_core::modal_layout::{Dof, ModalLayout};

impl Fe {
    /// The coordinates of `y` as the modal analysis classifies them.
    pub(crate) fn modal_layout_of(&self, y: &[f64]) -> ModalLayout {
        let n = self.elements;
        let nn = self.chain_nodes();
        let p = self.effector_index();
        let mut layout = ModalLayout {
            dofs: vec![Dof::Effector {
                coordinates: vec![self.node_coordinate(p, 0), self.node_coordinate(p, 1)],
                mass: self.effector_mass,
            }],
            frozen: Vec::new(),
        };
        let mu = self.material.mu;
        for cable in 0..2 {
            let l = self.free_length(y, cable);
            for k in 1..n {
                let j = self.chain_index(cable, k).expect("k ≥ 1 is a chain node");
                let (prev, _) = self.node(y, cable, k - 1);
                let (next, _) = self.node(y, cable, k + 1);
                let tangent = (next - prev).normalize();
                layout.dofs.push(Dof::Node {
                    cable,
                    coordinates: vec![j, nn + j],
                    tangent: vec![tangent.x, tangent.y],
                    mass: mu * l / n as f64,
                });
            }
            // l_i moves material through every node of the span (weight ≈ the kinetic-energy
            // coefficient γ ≈ 1/3 of the span's mass); ρ_i moves the stored cable (c1 = 1/3).
            layout.dofs.push(Dof::Axial {
                cable,
                index: self.l_index(cable),
                mass: mu * l / 3.0,
            });
            if let Some(r) = self.rho_index(cable) {
                layout.dofs.push(Dof::Axial {
                    cable,
                    index: r,
                    mass: mu * (self.modelled_length - l) / 3.0,
                });
            }
        }
        layout
    }
}
