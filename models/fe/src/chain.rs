//! One FE cable hanging between two fixed points with a fixed unstrained length l (l' = 0): the
//! configuration of Irvine's elastic catenary (MODELS.md FE.8.2, FE.11 test 8). Its forces are the
//! model's own element kernel ([`crate::element::terms`]) at rest: the truss force N t and the
//! lumped gravity μ g h/2 on each end node.

use crate::element::{self, ElementState, MassCoefficients, Material};
use crate::params::FeMass;
use cdpr_core::model::ModelError;
use cdpr_numerics::newton::{self, NewtonOptions, StaticProblem};
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
    fn node(&self, interior: &[f64], k: usize) -> Vector2<f64> {
        match k {
            0 => self.ends[0],
            k if k == self.elements => self.ends[1],
            k => Vector2::new(interior[2 * (k - 1)], interior[2 * (k - 1) + 1]),
        }
    }

    /// Net static force on each interior node, (x, z) interleaved [N], from the element kernel.
    pub fn forces(&self, interior: &[f64], out: &mut [f64]) {
        self.forces_with(interior, out, &self.material, false);
    }

    /// As [`FixedCable::forces`]; `bilateral` lets elements push (the smooth law Newton steers
    /// with from a start where tension-only elements might go slack).
    fn forces_with(&self, interior: &[f64], out: &mut [f64], mat: &Material, bilateral: bool) {
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
            let mut t = element::terms(mat, &k, &s);
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

    /// Static shape, all N + 1 nodes from A to B, by Newton: first the bilateral law (smooth) with
    /// EA softened and stiffened tenfold per stage for a slack stiff cable, then the true
    /// tension-only law (at a hanging cable's equilibrium every element pulls: it only confirms).
    pub fn equilibrium(&self) -> Result<Vec<Vector2<f64>>, ModelError> {
        let n = self.elements;
        let span = (self.ends[1] - self.ends[0]).norm();
        let mut u = Vec::with_capacity(2 * (n - 1));
        for p in &cdpr_core::geometry::sagging_polygon(
            self.ends[0],
            self.ends[1],
            n,
            self.length / n as f64 * (1.0 + 1e-6),
        )[1..n]
        {
            u.extend_from_slice(&[p.x, p.y]);
        }
        let sag = span < self.length;
        // 2e-8 N: above the round-off floor EA/h·ulp(x) (≈ 3e-9 N for steel at N = 80); for the
        // softest reference case (EA = 1 N) a position error of ~1e-9 m, far below the
        // discretisation errors compared.
        let opts = NewtonOptions {
            residual_tol: 2e-8,
            max_iterations: 200,
            ..NewtonOptions::default()
        };
        let softening: &[f64] = if !sag {
            &[1.0]
        } else {
            &[1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0]
        };
        for &factor in softening {
            let material = Material {
                ea: self.material.ea * factor,
                ..self.material
            };
            newton::solve(
                &mut Statics {
                    cable: self,
                    material,
                    bilateral: true,
                },
                &mut u,
                opts,
            )?;
        }
        newton::solve(
            &mut Statics {
                cable: self,
                material: self.material,
                bilateral: false,
            },
            &mut u,
            opts,
        )?;
        Ok((0..=n).map(|k| self.node(&u, k)).collect())
    }
}

struct Statics<'a> {
    cable: &'a FixedCable,
    material: Material,
    bilateral: bool,
}

impl StaticProblem for Statics<'_> {
    fn dimension(&self) -> usize {
        2 * (self.cable.elements - 1)
    }
    fn length_unknowns(&self) -> usize {
        self.dimension()
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.cable.forces_with(u, r, &self.material, self.bilateral);
    }
    /// h: the steering law is smooth, so a step of 6e-6·h only needs to beat round-off.
    fn scale(&self, _i: usize) -> f64 {
        self.cable.length / self.cable.elements as f64
    }
}
