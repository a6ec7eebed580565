//! A lumped cable hanging between two fixed points: the lumped model's springs and node masses
//! without pulleys or reels. It is the configuration of the analytic references (Irvine's elastic
//! catenary, the discrete taut string), so the lumped physics is checked against them directly.
//!
//! N springs of unstrained length l0 = L0/N and stiffness EA/l0 join the fixed end A, N − 1
//! interior nodes of mass μ l0 each, and the fixed end B. The static shape is the core's
//! [`hanging_shape`], shared with the FE cable.

use crate::spring_tension;
use cdpr_core::fixed_end::{FixedEndCable, hanging_shape};
use cdpr_core::model::ModelError;
use nalgebra::Vector2;

/// A lumped cable between fixed ends.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedCable {
    /// Fixed ends A and B [m].
    pub ends: [Vector2<f64>; 2],
    /// Springs N.
    pub elements: usize,
    /// Unstrained spring length l0 [m].
    pub segment: f64,
    /// Interior node mass μ l0 [kg].
    pub node_mass: f64,
    /// Spring stiffness EA/l0 [N/m].
    pub stiffness: f64,
    /// Gravity g [m/s²] along −z.
    pub gravity: f64,
}

impl FixedCable {
    /// Cable of unstrained length `unstrained_length` [m] in `elements` springs, axial stiffness
    /// `ea` [N], mass per unstrained length `mu` [kg/m].
    pub fn new(
        ends: [Vector2<f64>; 2],
        unstrained_length: f64,
        elements: usize,
        ea: f64,
        mu: f64,
        gravity: f64,
    ) -> Self {
        let segment = unstrained_length / elements as f64;
        Self {
            ends,
            elements,
            segment,
            node_mass: mu * segment,
            stiffness: ea / segment,
            gravity,
        }
    }

    /// Net static force on each interior node, (x, z) interleaved [N], for interior positions
    /// (x, z) interleaved [m]: spring tensions and gravity.
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
        self.segment
    }
    fn unstrained_length(&self) -> f64 {
        self.segment * self.elements as f64
    }
    fn interior_forces(&self, interior: &[f64], softening: f64, bilateral: bool, out: &mut [f64]) {
        let stiffness = self.stiffness * softening;
        out.fill(0.0);
        for j in 0..self.elements {
            let (a, b) = (self.node(interior, j), self.node(interior, j + 1));
            let d = b - a;
            let length = d.norm();
            let tension = if bilateral {
                stiffness * (length - self.segment)
            } else {
                spring_tension(stiffness, self.segment, 0.0, length, 0.0)
            };
            let pull = d * (tension / length);
            if j > 0 {
                out[2 * (j - 1)] += pull.x;
                out[2 * (j - 1) + 1] += pull.y;
            }
            if j + 1 < self.elements {
                out[2 * j] -= pull.x;
                out[2 * j + 1] -= pull.y;
            }
        }
        for k in 0..self.elements - 1 {
            out[2 * k + 1] -= self.node_mass * self.gravity;
        }
    }
}
