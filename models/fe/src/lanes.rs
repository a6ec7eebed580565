//! The implicit residual's span elements in chain order, as one loop the compiler runs several
//! elements at a time (AVX2: four).
//!
//! The chain (FE.5.5) numbers cable 1's nodes 1 … N−1, the effector, then cable 2's nodes N−1 … 1,
//! and the state holds each coordinate of the chain contiguously. With the pulleys A_1, A_2 put at
//! its ends (node 0 and node 2N of a padded copy), the 2N span elements of both cables are the
//! padded chain's consecutive node pairs (i, i + 1), i = 0 … 2N−1: cable 1's element i + 1 with
//! a = i (its pulley on the left), cable 2's element 2N − i mirrored, a = i + 1. One loop over i
//! picks a and b (and the cable's span quantities) by a select rather than a branch and runs the
//! same element kernel ([`element::residual_at_chord`]) on every lane; each lane does the scalar
//! kernel's operations in its order, so the rows are the scalar kernel's bit for bit (a test
//! below checks it). The summation into R stays with the caller, in span order e = 1 … N.
//!
//! Why: a span element's ~100 operations spill registers one element at a time, and one element
//! after another waits on its chord's square root and division; four elements in lanes use the
//! vector width the scalar code leaves idle (FE implicit paper run: docs/performance.md).

use crate::Span;
use crate::element::{self, Chord, ElementState, MassCoefficients, Material};
use nalgebra::Vector2;

/// The span elements' fixed mass coefficients, the nodes they read and their rows of R, in chain
/// order with the pulley nodes at its ends (allocated once).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ChainRows {
    /// Elements i < `split` belong to cable 1 (a = i), the rest to cable 2 (a = i + 1).
    split: usize,
    c1: Vec<f64>,
    c2: Vec<f64>,
    alpha: Vec<f64>,
    beta: Vec<f64>,
    gamma: Vec<f64>,
    /// Node positions, velocities and accelerations (x, z each): pulley 1, the chain, pulley 2.
    nodes: [Vec<f64>; 6],
    /// Rows (x, z) of element i's node a and node b, and its row l [N].
    pub a_x: Vec<f64>,
    pub a_z: Vec<f64>,
    pub b_x: Vec<f64>,
    pub b_z: Vec<f64>,
    pub l: Vec<f64>,
}

impl ChainRows {
    /// For N elements per span with the coefficients of elements e = 1 … N (index e − 1).
    pub fn new(elements: usize, coefficients: &[MassCoefficients]) -> Self {
        let n = elements;
        let m = 2 * n;
        // Element i is element i + 1 of cable 1, or element 2N − i of cable 2.
        let k: Vec<MassCoefficients> = (0..m)
            .map(|i| coefficients[if i < n { i } else { 2 * n - 1 - i }])
            .collect();
        let column = |f: fn(&MassCoefficients) -> f64| k.iter().map(f).collect::<Vec<f64>>();
        Self {
            split: n,
            c1: column(|k| k.c1),
            c2: column(|k| k.c2),
            alpha: column(|k| k.alpha),
            beta: column(|k| k.beta),
            gamma: column(|k| k.gamma),
            nodes: std::array::from_fn(|_| vec![0.0; m + 1]),
            a_x: vec![0.0; m],
            a_z: vec![0.0; m],
            b_x: vec![0.0; m],
            b_z: vec![0.0; m],
            l: vec![0.0; m],
        }
    }

    /// Index in the padded chain of element e (1 … N) of `cable`.
    #[inline]
    pub fn element(&self, cable: usize, e: usize) -> usize {
        match cable {
            0 => e - 1,
            _ => 2 * self.split - e,
        }
    }

    /// The rows of every span element for chain-node positions (x, z), velocities (v_x, v_z)
    /// and accelerations (a_x, a_z) (in q's layout, FE.5.1), the pulleys A_1, A_2, and each
    /// cable's span and l''.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &mut self,
        mat: &Material,
        damping: f64,
        spans: [&Span; 2],
        l_accelerations: [f64; 2],
        pulleys: [Vector2<f64>; 2],
        positions: [&[f64]; 2],
        velocities: [&[f64]; 2],
        accelerations: [&[f64]; 2],
    ) {
        // The pulley nodes at rest at the ends, the chain between them.
        let sources = [positions, velocities, accelerations];
        for (axis, node) in self.nodes.iter_mut().enumerate() {
            let (quantity, coordinate) = (axis / 2, axis % 2);
            let chain = sources[quantity][coordinate];
            let last = node.len() - 1;
            let fixed = |cable: usize| match quantity {
                0 => pulleys[cable][coordinate],
                _ => 0.0,
            };
            node[0] = fixed(0);
            node[1..last].copy_from_slice(chain);
            node[last] = fixed(1);
        }
        // Undamped (the paper's cable), the damping branch is compiled out: in lanes a branch
        // becomes a select, which would evaluate the damping terms' square root and divisions
        // on every element.
        if damping == 0.0 {
            self.evaluate_with(mat, 0.0, spans, l_accelerations);
        } else {
            self.evaluate_with(mat, damping, spans, l_accelerations);
        }
    }

    #[inline(always)]
    fn evaluate_with(
        &mut self,
        mat: &Material,
        damping: f64,
        [s1, s2]: [&Span; 2],
        [l1, l2]: [f64; 2],
    ) {
        let m = self.l.len();
        // Every slice cut to its length here, so the loop carries no bounds checks.
        let [x, z, vx, vz, ax, az] = &self.nodes;
        let (x, z, vx, vz, ax, az) = (
            &x[..m + 1],
            &z[..m + 1],
            &vx[..m + 1],
            &vz[..m + 1],
            &ax[..m + 1],
            &az[..m + 1],
        );
        let (c1, c2, alpha, beta, gamma) = (
            &self.c1[..m],
            &self.c2[..m],
            &self.alpha[..m],
            &self.beta[..m],
            &self.gamma[..m],
        );
        let (a_x, a_z, b_x, b_z, l_rows) = (
            &mut self.a_x[..m],
            &mut self.a_z[..m],
            &mut self.b_x[..m],
            &mut self.b_z[..m],
            &mut self.l[..m],
        );
        for i in 0..m {
            let first = i < self.split;
            let pick = |p: f64, q: f64| if first { p } else { q };
            let left = (
                Vector2::new(x[i], z[i]),
                Vector2::new(vx[i], vz[i]),
                Vector2::new(ax[i], az[i]),
            );
            let right = (
                Vector2::new(x[i + 1], z[i + 1]),
                Vector2::new(vx[i + 1], vz[i + 1]),
                Vector2::new(ax[i + 1], az[i + 1]),
            );
            // |Δ| is the same for either orientation (squares of opposite differences).
            let length = (right.0 - left.0).norm();
            let chord = Chord {
                length,
                inv_length: 1.0 / length,
            };
            let (a, b) = if first { (left, right) } else { (right, left) };
            let s = ElementState {
                ra: a.0,
                rb: b.0,
                va: a.1,
                vb: b.1,
                l_rate: pick(s1.l_rate, s2.l_rate),
                h: pick(s1.h, s2.h),
                inv_h: pick(s1.inv_h, s2.inv_h),
                h_prime: pick(s1.h_prime, s2.h_prime),
            };
            let k = MassCoefficients {
                c1: c1[i],
                c2: c2[i],
                alpha: alpha[i],
                beta: beta[i],
                gamma: gamma[i],
            };
            let l_acceleration = pick(l1, l2);
            let (ra, rb, rl) =
                element::residual_at_chord(mat, &k, &s, damping, chord, a.2, b.2, l_acceleration);
            a_x[i] = ra.x;
            a_z[i] = ra.y;
            b_x[i] = rb.x;
            b_z[i] = rb.y;
            l_rows[i] = rl;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::FeMass;
    use proptest::prelude::*;

    proptest! {
        /// Every lane's rows are the scalar element kernel's bit for bit, for each element of
        /// both cables (orientation, coefficients and span picked by cable), N from 1 (no chain
        /// element between two free nodes) up to lengths that leave a partial vector, with and
        /// without damping.
        #[test]
        fn lanes_are_the_scalar_kernel_bit_for_bit(
            n in 1usize..13,
            lumped in any::<bool>(),
            damping in prop_oneof![Just(0.0), 0.5f64..5.0],
            values in prop::collection::vec(-1.0f64..1.0, 6 * 25 + 10),
        ) {
            let mass = if lumped { FeMass::Lumped } else { FeMass::Consistent };
            let w = |k: usize| 1.0 - k as f64 / n as f64;
            let coefficients: Vec<_> =
                (1..=n).map(|e| MassCoefficients::new(mass, w(e - 1), w(e))).collect();
            let mat = Material { ea: 1.0e4, mu: 0.05, gravity: 9.81 };
            let nn = 2 * n - 1;
            // A taut-ish chain: x spread over [0, 1], z sagging, perturbed by the random values.
            let mut q = vec![0.0; 6 * nn];
            for j in 0..nn {
                let s = (j + 1) as f64 / (nn + 1) as f64;
                q[j] = s + 0.01 * values[j];
                q[nn + j] = -0.3 + 0.01 * values[25 + j];
            }
            for (k, v) in q[2 * nn..].iter_mut().enumerate() {
                *v = values[50 + k % 100];
            }
            let span = |c: usize| {
                let l = 0.5 + 0.1 * values[150 + c];
                Span {
                    l_rate: values[152 + c],
                    h: l / n as f64,
                    inv_h: 1.0 / (l / n as f64),
                    h_prime: 1.0 / n as f64,
                }
            };
            let spans = [span(0), span(1)];
            let l_accelerations = [values[154], values[155]];
            let pulleys = [Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0)];
            let mut rows = ChainRows::new(n, &coefficients);
            let part = |k: usize| -> [&[f64]; 2] { [&q[2 * k * nn..(2 * k + 1) * nn], &q[(2 * k + 1) * nn..(2 * k + 2) * nn]] };
            rows.evaluate(&mat, damping, [&spans[0], &spans[1]], l_accelerations, pulleys, part(0), part(1), part(2));
            // Node k of cable c (0: the pulley) as (r, v, a), read from q directly.
            let node = |c: usize, k: usize| {
                if k == 0 {
                    return (pulleys[c], Vector2::zeros(), Vector2::zeros());
                }
                let j = if c == 0 { k - 1 } else { 2 * n - 1 - k };
                let at = |p: usize| Vector2::new(q[2 * p * nn + j], q[(2 * p + 1) * nn + j]);
                (at(0), at(1), at(2))
            };
            for (c, sp) in spans.into_iter().enumerate() {
                for e in 1..=n {
                    let (a, b) = (node(c, e - 1), node(c, e));
                    let s = ElementState {
                        ra: a.0, rb: b.0, va: a.1, vb: b.1,
                        l_rate: sp.l_rate, h: sp.h, inv_h: sp.inv_h, h_prime: sp.h_prime,
                    };
                    let (ra, rb, rl) = element::residual_at_chord(
                        &mat, &coefficients[e - 1], &s, damping, Chord::of(&s), a.2, b.2, l_accelerations[c],
                    );
                    let i = rows.element(c, e);
                    let la = Vector2::new(rows.a_x[i], rows.a_z[i]);
                    let lb = Vector2::new(rows.b_x[i], rows.b_z[i]);
                    let same = |u: Vector2<f64>, v: Vector2<f64>| u.x.to_bits() == v.x.to_bits() && u.y.to_bits() == v.y.to_bits();
                    prop_assert!(same(la, ra) && same(lb, rb), "cable {c} element {e}: {la:?} {lb:?} vs {ra:?} {rb:?}");
                    prop_assert_eq!(rows.l[i].to_bits(), rl.to_bits(), "cable {} element {}", c, e);
                }
            }
        }
    }
}
