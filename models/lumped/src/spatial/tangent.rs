//! The analytic iteration matrix of the spatial lumped lines, S = diag(m) − c_v ∂F/∂q' −
//! c_q ∂F/∂q (MODELS.md §6), spring by spring: each spring's end forces F_a, F_b (a = P_j,
//! b = P_{j+1}) differentiated by its end positions and velocities, each block's rows projected
//! as the node's forces are.
//!
//! With the tension T = k0 (λ − l0) + c λ̇ of eq. 5 (c = C/l0; 0 while slack or clipped):
//! - a chord spring, u = (b − a)/λ, P = I − u uᵀ, w = P (v_b − v_a)/λ = ∂λ̇/∂b:
//!   ∂F_a/∂b = u (k0 u + c w)ᵀ + (T/λ) P = −∂F_a/∂a = ∂F_b/∂a = −∂F_b/∂b, and
//!   ∂F_a/∂v_b = c u uᵀ with the same signs;
//! - the straddling spring pulls each end toward the pulley A, u_a = (A − a)/|A − a|,
//!   λ = |A − a| + |A − b|, λ̇ = −u_a·v_a − u_b·v_b, g_a = ∂T/∂a = −k0 u_a + c P_a v_a/|A − a|:
//!   ∂F_a/∂a = u_a g_aᵀ − (T/|A − a|) P_a, ∂F_a/∂b = u_a g_bᵀ, and ∂F_a/∂v_b = −c u_a u_bᵀ.
//!
//! The damping terms make the blocks unsymmetric; without damping they are the planar model's
//! blocks in 3-D, computed as before to the bit.

use super::LumpedSpatial;
use crate::spring_tension;
use nalgebra::{Matrix3, Vector3};

/// A spring's end-force derivatives in the order (a, a), (a, b), (b, a), (b, b): by position,
/// and by velocity for a damped spring.
struct SpringBlocks {
    position: [Matrix3<f64>; 4],
    rate: Option<[Matrix3<f64>; 4]>,
}

/// A straddling spring's end sits exactly at its pulley, where its direction is undefined.
struct AtPulley;

impl LumpedSpatial {
    /// S into `values` (the iteration pattern's order). False where a straddling end sits
    /// exactly at its pulley (the caller then differences the residual).
    pub(super) fn tangent_matrix(
        &self,
        state: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> bool {
        let n = self.elements;
        self.mass_matrix_into(values);
        for cable in 0..self.robot.cables() {
            for j in 0..n {
                let blocks = match self.spring_blocks(state, cable, j) {
                    Ok(Some(blocks)) => blocks,
                    Ok(None) => continue,
                    Err(AtPulley) => return false,
                };
                let pairs = [(j, j), (j, j + 1), (j + 1, j), (j + 1, j + 1)];
                let project = |row: usize, block: &Matrix3<f64>| {
                    if row < n {
                        self.row_projection(cable, row) * block
                    } else {
                        *block
                    }
                };
                for (k, (row, col)) in pairs.into_iter().enumerate() {
                    let projected = project(row, &blocks.position[k]);
                    let damped = blocks.rate.map(|rate| project(row, &rate[k]));
                    for r in 0..3 {
                        for c in 0..3 {
                            let entry = &mut values[self.pattern_index(cable, row, col, r, c)];
                            *entry -= c_q * projected[(r, c)];
                            if let Some(damped) = &damped {
                                *entry -= c_v * damped[(r, c)];
                            }
                        }
                    }
                }
            }
        }
        true
    }

    /// The derivatives of spring j of `cable` (None while it pulls nothing).
    fn spring_blocks(
        &self,
        state: &[f64],
        cable: usize,
        j: usize,
    ) -> Result<Option<SpringBlocks>, AtPulley> {
        let (a, b) = (self.node(state, cable, j), self.node(state, cable, j + 1));
        if j + 1 == self.stored[cable] {
            self.straddling_blocks(state, cable, j, (a, b))
        } else {
            Ok(self.chord_blocks(state, cable, j, b - a))
        }
    }

    /// A chord spring's blocks, d = b − a.
    fn chord_blocks(
        &self,
        state: &[f64],
        cable: usize,
        j: usize,
        d: Vector3<f64>,
    ) -> Option<SpringBlocks> {
        let (k, l0, c) = (self.stiffness, self.segment, self.damping);
        let identity = Matrix3::identity();
        let length = d.norm();
        let stretch = length - l0;
        if stretch <= 0.0 {
            return None;
        }
        let u = d / length;
        let along = u * u.transpose();
        if c == 0.0 {
            let tangent = along * k + (identity - along) * (k * stretch / length);
            return Some(SpringBlocks {
                position: [-tangent, tangent, tangent, -tangent],
                rate: None,
            });
        }
        let dv = self.node_velocity(state, cable, j + 1) - self.node_velocity(state, cable, j);
        let t = spring_tension(k, l0, c, length, u.dot(&dv));
        if t <= 0.0 {
            return None;
        }
        let across = identity - along;
        let w = across * dv / length;
        let tangent = u * (u * k + w * c).transpose() + across * (t / length);
        let damping = along * c;
        Some(SpringBlocks {
            position: [-tangent, tangent, tangent, -tangent],
            rate: Some([-damping, damping, damping, -damping]),
        })
    }

    /// The straddling spring's blocks, its ends (a, b) on either side of the pulley.
    fn straddling_blocks(
        &self,
        state: &[f64],
        cable: usize,
        j: usize,
        (a, b): (Vector3<f64>, Vector3<f64>),
    ) -> Result<Option<SpringBlocks>, AtPulley> {
        let (k, l0, c) = (self.stiffness, self.segment, self.damping);
        let identity = Matrix3::identity();
        let pulley = self.pulley(cable);
        let (da, db) = (pulley - a, pulley - b);
        let (la, lb) = (da.norm(), db.norm());
        if la == 0.0 || lb == 0.0 {
            return Err(AtPulley);
        }
        let stretch = la + lb - l0;
        if stretch <= 0.0 {
            return Ok(None);
        }
        let (ua, ub): (Vector3<f64>, Vector3<f64>) = (da / la, db / lb);
        if c == 0.0 {
            let t = k * stretch;
            return Ok(Some(SpringBlocks {
                position: [
                    -ua * ua.transpose() * k - (identity - ua * ua.transpose()) * (t / la),
                    -ua * ub.transpose() * k,
                    -ub * ua.transpose() * k,
                    -ub * ub.transpose() * k - (identity - ub * ub.transpose()) * (t / lb),
                ],
                rate: None,
            }));
        }
        let (va, vb) = (
            self.node_velocity(state, cable, j),
            self.node_velocity(state, cable, j + 1),
        );
        let t = spring_tension(k, l0, c, la + lb, -ua.dot(&va) - ub.dot(&vb));
        if t <= 0.0 {
            return Ok(None);
        }
        let (across_a, across_b) = (
            identity - ua * ua.transpose(),
            identity - ub * ub.transpose(),
        );
        let ga = -ua * k + across_a * va * (c / la);
        let gb = -ub * k + across_b * vb * (c / lb);
        Ok(Some(SpringBlocks {
            position: [
                ua * ga.transpose() - across_a * (t / la),
                ua * gb.transpose(),
                ub * ga.transpose(),
                ub * gb.transpose() - across_b * (t / lb),
            ],
            rate: Some([
                -ua * ua.transpose() * c,
                -ua * ub.transpose() * c,
                -ub * ua.transpose() * c,
                -ub * ub.transpose() * c,
            ]),
        }))
    }
}
