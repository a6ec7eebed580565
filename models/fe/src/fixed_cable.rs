//! One FE cable hanging between two fixed points with a fixed unstrained length l (l' = 0): the
//! configuration of Irvine's elastic catenary (MODELS.md FE.8.2, FE.11 test 8). Its forces are the
//! model's own element kernel ([`crate::element::terms`]) at rest: the truss force N t and the
//! lumped gravity μ g h/2 on each end node. The static shape is the core's [`hanging_shape`],
//! shared with the lumped cable.

use crate::element::{self, ElementState, MassCoefficients, Material};
use crate::params::FeMass;
use cdpr_core::fixed_end::{FixedEndCable, hanging_shape};
use cdpr_core::model::ModelError;
use nalgebra::Vector2;

/// An FE cable of N elements between fixed ends A and B.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedCable {
    /// Fixed ends A (node 0) and B (node N) [m].
    pub ends: [Vector2<f64>; 2],
    /// Elements N.
    pub elements: usize,
    /// Unstrained length l [m].
    pub length: f64,
    pub material: Material,
}

impl FixedCable {
    /// Net static force on each interior node, (x, z) interleaved [N], from the element kernel.
    pub fn forces(&self, interior: &[f64], out: &mut [f64]) {
        self.interior_forces(interior, 1.0, false, out);
    }

    /// Static shape, all N + 1 nodes from A to B ([`hanging_shape`]).
    pub fn equilibrium(&self) -> Result<Vec<Vector2<f64>>, ModelError> {
        hanging_shape(self)
    }
}

impl FixedEndCable for FixedCable {
    fn ends(&self) -> [Vector2<f64>; 2] {
        self.ends
    }
    fn pieces(&self) -> usize {
        self.elements
    }
    fn piece_length(&self) -> f64 {
        self.length / self.elements as f64
    }
    fn unstrained_length(&self) -> f64 {
        self.length
    }
    fn interior_forces(&self, interior: &[f64], softening: f64, bilateral: bool, out: &mut [f64]) {
        let mat = Material {
            ea: self.material.ea * softening,
            ..self.material
        };
        out.fill(0.0);
        let n = self.elements;
        let h = self.length / n as f64;
        // Weights and mass variant are irrelevant at rest (every velocity term vanishes).
        let k = MassCoefficients::new(FeMass::Consistent, 1.0, 1.0);
        for e in 1..=n {
            let (ra, rb) = (self.node(interior, e - 1), self.node(interior, e));
            let s = ElementState::new(
                (ra, Vector2::zeros()),
                (rb, Vector2::zeros()),
                0.0,
                h,
                1.0 / n as f64,
            );
            let mut t = element::terms(&mat, &k, &s);
            if bilateral {
                let d = rb - ra;
                let len = d.norm();
                let (strain, tension) = s.tension(mat.ea, len);
                let push = d * ((mat.ea * strain - tension) / len);
                t.fa += push;
                t.fb -= push;
            }
            if e > 1 {
                out[2 * (e - 2)] += t.fa.x;
                out[2 * (e - 2) + 1] += t.fa.y;
            }
            if e < n {
                out[2 * (e - 1)] += t.fb.x;
                out[2 * (e - 1) + 1] += t.fb.y;
            }
        }
    }
}
