//! A lumped cable hanging between two fixed points: the lumped model's springs and node masses
//! without pulleys or reels. It is the configuration of the analytic references (Irvine's elastic
//! catenary, the discrete taut string), so the lumped physics is checked against them directly.
//!
//! N springs of unstrained length l0 = L0/N and stiffness EA/l0 join the fixed end A, N − 1
//! interior nodes of mass μ l0 each, and the fixed end B.

use crate::spring_tension;
use cdpr_core::model::ModelError;
use cdpr_core::statics::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector2;

/// A lumped cable between fixed ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
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

impl Chain {
    /// Chain of unstrained length `unstrained_length` [m] in `elements` springs, axial stiffness
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

    fn node(&self, interior: &[f64], k: usize) -> Vector2<f64> {
        match k {
            0 => self.ends[0],
            k if k == self.elements => self.ends[1],
            k => Vector2::new(interior[2 * (k - 1)], interior[2 * (k - 1) + 1]),
        }
    }

    /// Net static force on each interior node, (x, z) interleaved [N], for interior positions
    /// (x, z) interleaved [m]: spring tensions and gravity.
    pub fn forces(&self, interior: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for j in 0..self.elements {
            let (a, b) = (self.node(interior, j), self.node(interior, j + 1));
            let d = b - a;
            let length = d.norm();
            let pull =
                d * (spring_tension(self.stiffness, self.segment, 0.0, length, 0.0) / length);
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

    /// Static shape by Newton from a parabola with the cable's length; all N + 1 nodes, A to B.
    pub fn equilibrium(&self) -> Result<Vec<Vector2<f64>>, ModelError> {
        let n = self.elements;
        let [a, b] = self.ends;
        let chord = (b - a).norm();
        let length = self.segment * n as f64;
        // Parabola sag for the excess length (√(3c(L − c)/8)); a taut cable starts straight.
        let sag = (3.0 * chord * (length - chord).max(0.0) / 8.0).sqrt();
        let mut u = Vec::with_capacity(2 * (n - 1));
        for k in 1..n {
            let s = k as f64 / n as f64;
            let p = a + (b - a) * s - Vector2::new(0.0, 4.0 * sag * s * (1.0 - s));
            u.extend_from_slice(&[p.x, p.y]);
        }
        let mut problem = Statics { chain: self };
        statics::solve(
            &mut problem,
            &mut u,
            NewtonOptions {
                residual_tol: 1e-9,
                max_iterations: 200,
                ..NewtonOptions::default()
            },
        )?;
        Ok((0..=n).map(|k| self.node(&u, k)).collect())
    }
}

struct Statics<'a> {
    chain: &'a Chain,
}

impl StaticProblem for Statics<'_> {
    fn dimension(&self) -> usize {
        2 * (self.chain.elements - 1)
    }
    fn length_unknowns(&self) -> usize {
        self.dimension()
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.chain.forces(u, r);
    }
    /// 1e-6 m: a 6e-12 m step stays inside the smallest stretch of the reference cases (8e-9 m,
    /// slack steel at N = 80) and moves forces 4e-5 relative above their round-off.
    fn scale(&self, _i: usize) -> f64 {
        1e-6
    }
}
