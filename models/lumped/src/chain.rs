//! A lumped cable hanging between two fixed points: the lumped model's springs and node masses
//! without pulleys or reels. It is the configuration of the analytic references (Irvine's elastic
//! catenary, the discrete taut string), so the lumped physics is checked against them directly.
//!
//! N springs of unstrained length l0 = L0/N and stiffness EA/l0 join the fixed end A, N − 1
//! interior nodes of mass μ l0 each, and the fixed end B.

use crate::spring_tension;
use cdpr_core::model::ModelError;
use cdpr_numerics::newton::{self, NewtonOptions, StaticProblem};
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
        self.forces_with(interior, out, false);
    }

    /// As [`Chain::forces`]; `bilateral` lets springs push (the smooth law Newton steers with).
    fn forces_with(&self, interior: &[f64], out: &mut [f64], bilateral: bool) {
        out.fill(0.0);
        for j in 0..self.elements {
            let (a, b) = (self.node(interior, j), self.node(interior, j + 1));
            let d = b - a;
            let length = d.norm();
            let tension = if bilateral {
                self.stiffness * (length - self.segment)
            } else {
                spring_tension(self.stiffness, self.segment, 0.0, length, 0.0)
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

    /// Static shape by Newton from a start where every spring is taut; all N + 1 nodes, A to B.
    pub fn equilibrium(&self) -> Result<Vec<Vector2<f64>>, ModelError> {
        let n = self.elements;
        let mut u = Vec::with_capacity(2 * (n - 1));
        for p in &cdpr_core::geometry::sagging_polygon(
            self.ends[0],
            self.ends[1],
            n,
            self.segment * (1.0 + 1e-6),
        )[1..n]
        {
            u.extend_from_slice(&[p.x, p.y]);
        }
        // Stage 1, the bilateral chain (springs may push): smooth, so Newton is well-posed from
        // the taut start, where a tension-only spring slackened by an early iterate would have no
        // stiffness and make the Jacobian singular. Stage 2, the true tension-only law: at a
        // hanging chain's equilibrium every spring pulls, the laws agree, and this only confirms.
        // 2e-8 N: above the round-off floor k0·ulp(x) (3e-9 N for a taut steel chain at N = 80);
        // with the weakest stiffness of the reference cases (T/l0 ≈ 7 N/m) a position error of
        // 3e-9 m, far below the discretisation errors the chain is compared for.
        let opts = NewtonOptions {
            residual_tol: 2e-8,
            max_iterations: 200,
            ..NewtonOptions::default()
        };
        // A slack stiff chain (steel, L0 > |AB|) defeats Newton from the arc: a linear step
        // rotates springs of stiffness ~1e6 N/m carrying ~0.1 N and fakes huge stretches. Solve
        // it first with EA softened 1e5-fold and stiffen tenfold per stage from the last shape.
        let straight = (self.ends[1] - self.ends[0]).norm() >= self.segment * n as f64;
        let softening: &[f64] = if straight {
            &[1.0]
        } else {
            &[1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0]
        };
        for &factor in softening {
            let soft = Chain {
                stiffness: self.stiffness * factor,
                ..self.clone()
            };
            newton::solve(
                &mut Statics {
                    chain: &soft,
                    bilateral: true,
                },
                &mut u,
                opts,
            )?;
        }
        newton::solve(
            &mut Statics {
                chain: self,
                bilateral: false,
            },
            &mut u,
            opts,
        )?;
        Ok((0..=n).map(|k| self.node(&u, k)).collect())
    }
}

struct Statics<'a> {
    chain: &'a Chain,
    bilateral: bool,
}

impl StaticProblem for Statics<'_> {
    fn dimension(&self) -> usize {
        2 * (self.chain.elements - 1)
    }
    fn length_unknowns(&self) -> usize {
        self.dimension()
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.chain.forces_with(u, r, self.bilateral);
    }
    /// l0: the steering law is smooth, so a step of 6e-6·l0 only needs to beat round-off.
    fn scale(&self, _i: usize) -> f64 {
        self.chain.segment
    }
}
