//! The springs of the spatial lumped model: each spring's length along the cable's path (eq. 4
//! over the pulley), its tension (eq. 5) and the net forces on every coordinate.

use super::LumpedSpatial;
use crate::spring_tension;
use nalgebra::Vector3;

/// Forces of springs j = 0 … N−1 on their end nodes a = P_j and b = P_{j+1} [N], per axis.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct SpringForces {
    pub(super) a: [Vec<f64>; 3],
    pub(super) b: [Vec<f64>; 3],
}

impl LumpedSpatial {
    /// Length λ_j of spring j of `cable` along the cable path (eq. 4 over the pulley).
    pub fn spring_length(&self, y: &[f64], cable: usize, j: usize) -> f64 {
        crate::path::path_length(
            (self.node(y, cable, j), self.node(y, cable, j + 1)),
            (j + 1 == self.stored[cable]).then(|| self.pulley(cable)),
        )
    }

    /// Length λ_j, rate λ̇_j and the unit vectors along which spring j pulls its end nodes (both
    /// toward the pulley for the straddling spring, eq. 4).
    #[inline]
    pub(super) fn spring(
        &self,
        y: &[f64],
        cable: usize,
        j: usize,
    ) -> (f64, f64, Vector3<f64>, Vector3<f64>) {
        crate::path::spring_path(
            (self.node(y, cable, j), self.node(y, cable, j + 1)),
            (
                self.node_velocity(y, cable, j),
                self.node_velocity(y, cable, j + 1),
            ),
            (j + 1 == self.stored[cable]).then(|| self.pulley(cable)),
        )
    }

    /// Tension of spring j of `cable` [N].
    pub fn spring_force(&self, y: &[f64], cable: usize, j: usize) -> f64 {
        let (length, rate, _, _) = self.spring(y, cable, j);
        spring_tension(self.stiffness, self.segment, self.damping, length, rate)
    }

    /// Unstrained length between the pulley and the effector [m]: the free springs and the
    /// free-side share of the straddling spring.
    pub fn free_length(&self, y: &[f64], cable: usize) -> f64 {
        let r = self.stored[cable];
        crate::path::free_length(
            (self.elements, r, self.segment),
            self.pulley(cable),
            (r > 0).then(|| (self.node(y, cable, r - 1), self.node(y, cable, r))),
        )
    }

    /// Net force on every position coordinate [N]: springs, gravity, the reel tensions on P_0;
    /// a stored node keeps the component along its reel line (the guide reacts the rest), or on
    /// a locked or driven reel m times the acceleration the reel gives it ([`super::reel`]).
    pub(super) fn forces(&mut self, y: &[f64], tensions: &[f64], out: &mut [f64]) {
        let n = self.elements;
        let weight = self.node_mass * self.gravity();
        let mut effector = Vector3::new(0.0, 0.0, -self.robot.effector_mass * self.gravity());
        for cable in 0..self.robot.cables() {
            let mut s = std::mem::take(&mut self.scratch[cable]);
            self.chord_springs(y, cable, &mut s);
            let r = self.stored[cable];
            for j in [Some(n - 1), r.checked_sub(1)].into_iter().flatten() {
                let (length, rate, ua, ub) = self.spring(y, cable, j);
                let t = spring_tension(self.stiffness, self.segment, self.damping, length, rate);
                for axis in 0..3 {
                    s.a[axis][j] = t * ua[axis];
                    s.b[axis][j] = t * ub[axis];
                }
            }
            let reel = self.reels[cable];
            let pull = match self.drive {
                super::reel::ReelDrive::Tension => tensions[cable],
                _ => 0.0,
            };
            for axis in 0..3 {
                let f = &mut out[self.index(cable, 0, axis)..][..n];
                let (a, b) = (&s.a[axis], &s.b[axis]);
                f[0] = a[0] + pull * reel[axis];
                for ((f, a), b) in f[1..].iter_mut().zip(&a[1..]).zip(&b[..n - 1]) {
                    *f = a + b;
                }
                effector[axis] += s.b[axis][n - 1];
            }
            let z = self.index(cable, 0, 2);
            out[z..z + n].iter_mut().for_each(|f| *f -= weight);
            for j in 0..r {
                let f = self.node(out, cable, j);
                let along = reel * f.dot(&reel);
                for axis in 0..3 {
                    out[self.index(cable, j, axis)] = along[axis];
                }
            }
            if let Some(command) = self.reel_command(y, cable) {
                for j in 0..r {
                    let a = self.stored_acceleration(y, cable, j, command);
                    for axis in 0..3 {
                        out[self.index(cable, j, axis)] = self.node_mass * a * reel[axis];
                    }
                }
            }
            self.scratch[cable] = s;
        }
        for axis in 0..3 {
            out[self.index(0, n, axis)] = effector[axis];
        }
    }

    /// The springs between two cable nodes (j = 0 … N − 2) as straight chords, one sweep per
    /// cable over its contiguous coordinates.
    fn chord_springs(&self, y: &[f64], cable: usize, s: &mut SpringForces) {
        let n = self.elements;
        let np = self.positions_len();
        let (k, l0, c) = (self.stiffness, self.segment, self.damping);
        let at = |axis: usize| &y[self.index(cable, 0, axis)..][..n];
        let rate_of = |axis: usize| &y[np + self.index(cable, 0, axis)..][..n];
        let (x, yy, z) = (at(0), at(1), at(2));
        let (vx, vy, vz) = (rate_of(0), rate_of(1), rate_of(2));
        let [ax, ay, az] = &mut s.a;
        let [bx, by, bz] = &mut s.b;
        for j in 0..n - 1 {
            let (dx, dy, dz) = (x[j + 1] - x[j], yy[j + 1] - yy[j], z[j + 1] - z[j]);
            let length = (dx * dx + dy * dy + dz * dz).sqrt();
            let per_length = if c == 0.0 {
                (k * (length - l0)).max(0.0) / length
            } else {
                let rate = (dx * (vx[j + 1] - vx[j])
                    + dy * (vy[j + 1] - vy[j])
                    + dz * (vz[j + 1] - vz[j]))
                    / length;
                spring_tension(k, l0, c, length, rate) / length
            };
            (ax[j], ay[j], az[j]) = (per_length * dx, per_length * dy, per_length * dz);
            (bx[j], by[j], bz[j]) = (-ax[j], -ay[j], -az[j]);
        }
    }
}
