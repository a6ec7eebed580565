//! Statics of one cable hanging between two fixed ends in the vertical plane — the configuration
//! of Irvine's elastic catenary and of the discrete taut string, against which the lumped and FE
//! models are checked. A model says how its pieces pull on the interior nodes
//! ([`FixedEndCable::interior_forces`]); the start, the softening stages and the two Newton stages
//! are written here once.

use crate::geometry::sagging_polygon;
use crate::model::ModelError;
use cdpr_numerics::newton::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector2;

/// A cable of N pieces (springs or elements) of equal unstrained length between fixed ends A
/// (node 0) and B (node N). Interior nodes 1…N−1 are the unknowns, (x, z) interleaved [m].
pub trait FixedEndCable {
    /// Fixed ends A and B [m].
    fn ends(&self) -> [Vector2<f64>; 2];
    /// Pieces N ≥ 2.
    fn pieces(&self) -> usize;
    /// Unstrained length of one piece [m]: the start's chord and Newton's length scale.
    fn piece_length(&self) -> f64;
    /// Unstrained length of the whole cable [m]; the cable sags when |AB| is shorter.
    fn unstrained_length(&self) -> f64;
    /// Net static force on each interior node, (x, z) interleaved [N], at interior positions
    /// `interior` [m], with the axial stiffness scaled by `softening` (1: the cable's own);
    /// `bilateral` lets pieces push (the smooth law Newton steers with).
    fn interior_forces(&self, interior: &[f64], softening: f64, bilateral: bool, out: &mut [f64]);

    /// Node k (0…N) for interior positions `interior` [m].
    fn node(&self, interior: &[f64], k: usize) -> Vector2<f64> {
        let ends = self.ends();
        match k {
            0 => ends[0],
            k if k == self.pieces() => ends[1],
            k => Vector2::new(interior[2 * (k - 1)], interior[2 * (k - 1) + 1]),
        }
    }
}

/// The static shape of `cable`, all N + 1 nodes from A to B, by Newton from a start where every
/// piece is taut (the circular-arc polygon of chord l0 (1 + 1e-6)).
///
/// Stage 1, the bilateral law (pieces may push): smooth, so Newton is well-posed from the taut
/// start, where a tension-only piece slackened by an early iterate would have no stiffness and
/// make the Jacobian singular. A slack stiff cable (steel, L0 > |AB|) defeats Newton even so: a
/// linear step rotates pieces of stiffness ~1e6 N/m carrying ~0.1 N and fakes huge stretches; it
/// is solved first with EA softened 1e5-fold and stiffened tenfold per stage from the last shape.
/// Stage 2, the true tension-only law: at a hanging cable's equilibrium every piece pulls, the
/// laws agree, and this only confirms.
///
/// Residual tolerance 2e-8 N: above the round-off floor EA/l0·ulp(x) (≈ 3e-9 N for a taut steel
/// cable at N = 80); with the weakest stiffness of the reference cases (T/l0 ≈ 7 N/m) a position
/// error of 3e-9 m, far below the discretisation errors the cable is compared for.
pub fn hanging_shape(cable: &impl FixedEndCable) -> Result<Vec<Vector2<f64>>, ModelError> {
    let n = cable.pieces();
    let [a, b] = cable.ends();
    let mut interior = Vec::with_capacity(2 * (n - 1));
    for p in &sagging_polygon(a, b, n, cable.piece_length() * (1.0 + 1e-6))[1..n] {
        interior.extend_from_slice(&[p.x, p.y]);
    }
    let opts = NewtonOptions {
        residual_tol: 2e-8,
        max_iterations: 200,
        ..NewtonOptions::default()
    };
    let sags = (b - a).norm() < cable.unstrained_length();
    let softening: &[f64] = if sags {
        &[1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0]
    } else {
        &[1.0]
    };
    for &factor in softening {
        let mut stage = Stage {
            cable,
            softening: factor,
            bilateral: true,
        };
        newton::solve(&mut stage, &mut interior, opts)?;
    }
    let mut confirm = Stage {
        cable,
        softening: 1.0,
        bilateral: false,
    };
    newton::solve(&mut confirm, &mut interior, opts)?;
    Ok((0..=n).map(|k| cable.node(&interior, k)).collect())
}

/// One Newton stage: the cable's interior forces under one stiffness scale and law.
struct Stage<'a, C> {
    cable: &'a C,
    softening: f64,
    bilateral: bool,
}

impl<C: FixedEndCable> StaticProblem for Stage<'_, C> {
    fn dimension(&self) -> usize {
        2 * (self.cable.pieces() - 1)
    }
    fn length_unknowns(&self) -> usize {
        self.dimension()
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.cable
            .interior_forces(u, self.softening, self.bilateral, r);
    }
    /// l0: the steering law is smooth, so a step of 6e-6·l0 only needs to beat round-off.
    fn scale(&self, _i: usize) -> f64 {
        self.cable.piece_length()
    }
}
