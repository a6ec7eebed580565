//! The implicit residual of the spatial FE robot element by element (MODELS.md FE.9.3), its span
//! elements as one loop the compiler runs several elements at a time, as the plane's chain
//! ([`crate::lanes`]).
//!
//! Every arm's nodes are laid out arm after arm in columns — its pulley at rest, its free nodes
//! 1 … N − 1, the effector — so an arm's element e is the consecutive pair (e − 1, e) and one
//! loop over all consecutive pairs runs [`element::residual_at_chord`] on every lane; each
//! cable's stored element follows as the pair (R_i, A_i) (the 2m − 1 pairs between are computed
//! and never read).
//! Each lane does the scalar kernel's operations in its order, so the rows are the scalar
//! kernel's bit for bit (a test below checks it). The rows are then summed into R per node, per
//! l_i and at the effector, with each stored element's rows (one per cable, scalar) and the
//! effector's own mass and weight.
//!
//! Why: the star's assembly forms M and F (FE.5.3's terms, then M q'' − F), one element at a
//! time, each waiting on its chord's square root and division; the collected rows need fewer
//! operations and the lanes use the vector width the scalar code leaves idle.

use super::FeSpatial;
use crate::element::{self, Chord, ElementState, MassCoefficients, Material};
use nalgebra::Vector3;

/// How an element's unstrained length h follows its cable's free length l.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Length {
    /// One of the span's N elements: h = l/N, h' = 1/N.
    Free(usize),
    /// A cable's stored element: h = L0 − l, h' = −1, L0 its total unstrained length, set
    /// where it is read ([`StarRows::set_total_length`]; NaN until then).
    Stored,
}

/// The elements' fixed mass coefficients and how each one's h follows l, element by element:
/// h = (offset + slope l)/divisor, which is l/N or L0 − l to the bit.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct Coefficients {
    c1: Vec<f64>,
    c2: Vec<f64>,
    alpha: Vec<f64>,
    beta: Vec<f64>,
    gamma: Vec<f64>,
    offset: Vec<f64>,
    slope: Vec<f64>,
    divisor: Vec<f64>,
    h_prime: Vec<f64>,
}

impl Coefficients {
    /// Element i's mass coefficients and length, the i-th of `per_element`.
    pub fn new<'a>(per_element: impl Iterator<Item = (&'a MassCoefficients, Length)>) -> Self {
        let mut k = Self::default();
        for (c, length) in per_element {
            k.c1.push(c.c1);
            k.c2.push(c.c2);
            k.alpha.push(c.alpha);
            k.beta.push(c.beta);
            k.gamma.push(c.gamma);
            let (offset, slope, divisor, h_prime) = match length {
                Length::Free(n) => (0.0, 1.0, n as f64, 1.0 / n as f64),
                Length::Stored => (f64::NAN, -1.0, 1.0, -1.0),
            };
            k.offset.push(offset);
            k.slope.push(slope);
            k.divisor.push(divisor);
            k.h_prime.push(h_prime);
        }
        k
    }
}

/// One evaluation's inputs, element by element: node a's and node b's position, velocity and
/// acceleration (x, y, z each), and the span's l [m], l' [m/s] and l'' [m/s²].
#[derive(Debug, Clone, Copy)]
pub(super) struct Inputs<'a> {
    pub a: [&'a [f64]; 9],
    pub b: [&'a [f64]; 9],
    pub l: &'a [f64],
    pub l_rate: &'a [f64],
    pub l_acceleration: &'a [f64],
}

/// Each element's rows of R: node a's and node b's (x, y, z) and l's [N].
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct Rows {
    pub a: [Vec<f64>; 3],
    pub b: [Vec<f64>; 3],
    pub l: Vec<f64>,
}

impl Rows {
    pub fn new(len: usize) -> Self {
        Self {
            a: std::array::from_fn(|_| vec![0.0; len]),
            b: std::array::from_fn(|_| vec![0.0; len]),
            l: vec![0.0; len],
        }
    }

    /// Element i's rows in the block's local order (r_a, r_b, l).
    #[inline]
    pub fn local(&self, i: usize) -> [f64; 7] {
        let (a, b) = (&self.a, &self.b);
        [
            a[0][i], a[1][i], a[2][i], b[0][i], b[1][i], b[2][i], self.l[i],
        ]
    }

    /// The rows of every element of `input` ([`element::residual_at_chord`] in lanes).
    pub fn evaluate(&mut self, k: &Coefficients, mat: &Material, damping: f64, input: &Inputs) {
        let [ra_x, ra_y, ra_z] = &mut self.a;
        let [rb_x, rb_y, rb_z] = &mut self.b;
        let out = (ra_x, ra_y, ra_z, rb_x, rb_y, rb_z, &mut self.l);
        // Undamped, the damping branch is compiled out: in lanes a branch becomes a select,
        // which would evaluate the damping terms' square root and divisions on every element.
        if damping == 0.0 {
            rows::<false>(
                k, mat, 0.0, input, out.0, out.1, out.2, out.3, out.4, out.5, out.6,
            );
        } else {
            rows::<true>(
                k, mat, damping, input, out.0, out.1, out.2, out.3, out.4, out.5, out.6,
            );
        }
    }
}

/// The rows into the seven output columns, one element per lane. Kept out of line with each
/// column its own argument: the compiler then knows the outputs alias neither the inputs nor
/// each other, and vectorises the loop without runtime overlap checks (which it gives up on for
/// this many columns).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn rows<const DAMPED: bool>(
    k: &Coefficients,
    mat: &Material,
    damping: f64,
    input: &Inputs,
    ra_x: &mut [f64],
    ra_y: &mut [f64],
    ra_z: &mut [f64],
    rb_x: &mut [f64],
    rb_y: &mut [f64],
    rb_z: &mut [f64],
    rl: &mut [f64],
) {
    let damping = if DAMPED { damping } else { 0.0 };
    let m = rl.len();
    // Every slice cut to its length here, so the loop carries no bounds checks.
    let a = input.a.map(|c| &c[..m]);
    let b = input.b.map(|c| &c[..m]);
    let (c1, c2, alpha, beta, gamma) = (
        &k.c1[..m],
        &k.c2[..m],
        &k.alpha[..m],
        &k.beta[..m],
        &k.gamma[..m],
    );
    let (offset, slope, divisor, h_prime) = (
        &k.offset[..m],
        &k.slope[..m],
        &k.divisor[..m],
        &k.h_prime[..m],
    );
    let (l, l_rate, l_acceleration) = (
        &input.l[..m],
        &input.l_rate[..m],
        &input.l_acceleration[..m],
    );
    let (ra_x, ra_y, ra_z) = (&mut ra_x[..m], &mut ra_y[..m], &mut ra_z[..m]);
    let (rb_x, rb_y, rb_z) = (&mut rb_x[..m], &mut rb_y[..m], &mut rb_z[..m]);
    for i in 0..m {
        let at =
            |c: &[&[f64]; 9], q: usize| Vector3::new(c[3 * q][i], c[3 * q + 1][i], c[3 * q + 2][i]);
        // h and 1/h as `ElementState::new` forms them.
        let h = (offset[i] + slope[i] * l[i]) / divisor[i];
        let s = ElementState {
            ra: at(&a, 0),
            rb: at(&b, 0),
            va: at(&a, 1),
            vb: at(&b, 1),
            l_rate: l_rate[i],
            h,
            inv_h: 1.0 / h,
            h_prime: h_prime[i],
        };
        let coefficients = MassCoefficients {
            c1: c1[i],
            c2: c2[i],
            alpha: alpha[i],
            beta: beta[i],
            gamma: gamma[i],
        };
        let (row_a, row_b, row_l) = element::residual_at_chord(
            mat,
            &coefficients,
            &s,
            damping,
            Chord::of(&s),
            at(&a, 2),
            at(&b, 2),
            l_acceleration[i],
        );
        ra_x[i] = row_a.x;
        ra_y[i] = row_a.y;
        ra_z[i] = row_a.z;
        rb_x[i] = row_b.x;
        rb_y[i] = row_b.y;
        rb_z[i] = row_b.z;
        rl[i] = row_l;
    }
}

/// The residual's elements: each arm's span elements, arm after arm, then each cable's stored
/// element. Nodes in columns: per arm its pulley, free nodes and the effector (N + 1), so arm
/// a's element e is the pair at index a (N + 1) + e − 1; then per cable its reel end R_i and
/// pulley A_i, the stored element the pair at m (N + 1) + 2i. The pairs between (an arm's
/// effector and the next pulley, a pulley and the next reel end) are computed and never read.
/// Allocated once.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct StarRows {
    coefficients: Coefficients,
    /// Cables m and elements per span N.
    arms: usize,
    elements: usize,
    /// The nodes' positions, velocities and accelerations (x, y, z each).
    nodes: [Vec<f64>; 9],
    /// Per element, its cable's l [m], l' [m/s] and l'' [m/s²].
    l: Vec<f64>,
    l_rate: Vec<f64>,
    l_acceleration: Vec<f64>,
    rows: Rows,
}

impl StarRows {
    /// For `arms` ≥ 1 cables of N elements with the coefficients of elements e = 1 … N (index
    /// e − 1), and their stored elements' coefficients.
    pub fn new(arms: usize, coefficients: &[MassCoefficients], stored: &MassCoefficients) -> Self {
        let n = coefficients.len();
        let spans = arms * (n + 1);
        let len = spans + 2 * arms - 1;
        // The joining pairs take a neighbour's coefficients: any finite numbers do.
        let per_element = (0..len).map(|i| {
            if i < spans {
                (&coefficients[(i % (n + 1)).min(n - 1)], Length::Free(n))
            } else {
                (stored, Length::Stored)
            }
        });
        Self {
            coefficients: Coefficients::new(per_element),
            arms,
            elements: n,
            nodes: std::array::from_fn(|_| vec![0.0; len + 1]),
            l: vec![1.0; len],
            l_rate: vec![0.0; len],
            l_acceleration: vec![0.0; len],
            rows: Rows::new(len),
        }
    }

    /// Index of cable `cable`'s stored element (its reel end's node).
    fn stored(&self, cable: usize) -> usize {
        self.arms * (self.elements + 1) + 2 * cable
    }

    /// Cable `cable`'s total unstrained length L0 [m], read by its stored element's h (and
    /// by the joining pair after it, never read).
    fn set_total_length(&mut self, cable: usize, total: f64) {
        let s = self.stored(cable);
        let joint = (s + 2).min(self.l.len());
        self.coefficients.offset[s..joint].fill(total);
    }

    /// The rows of every element from the nodes and spans set.
    pub fn evaluate(&mut self, mat: &Material, damping: f64) {
        let m = self.l.len();
        let input = Inputs {
            a: std::array::from_fn(|k| &self.nodes[k][..m]),
            b: std::array::from_fn(|k| &self.nodes[k][1..]),
            l: &self.l,
            l_rate: &self.l_rate,
            l_acceleration: &self.l_acceleration,
        };
        self.rows.evaluate(&self.coefficients, mat, damping, &input);
    }
}

impl FeSpatial {
    /// R = M(q) q'' − F(q, q', T) at (`state`, `qdd`) into `r` (FE.9.3) from the element rows:
    /// each free node's from its two elements; the effector's from its own mass and weight and
    /// each arm's last element; each l_i's from its span's elements and its stored element; each
    /// ρ_i's from the stored element along r_i and the commanded tension T_i (FE.5.3). Driven
    /// by length (Du's form, FE.5.6) the spans see l_i'' = the command, the l_i rows read
    /// l_i'' − the command and the ρ_i rows ρ_i'' (the stored cable is on the reel).
    pub(super) fn element_residual(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: &[f64],
        r: &mut [f64],
    ) {
        let mut rows = std::mem::take(&mut self.rows);
        self.gather_rows(&mut rows, state, qdd);
        rows.evaluate(&self.material, self.axial_damping);
        self.sum_rows(&rows, qdd, tensions, r);
        self.rows = rows;
    }

    /// Each arm's nodes (its pulley at rest, its free nodes, the effector) and span, and each
    /// stored element's nodes (R_i = A_i + ρ_i r_i moving along r_i, A_i at rest) into `rows`.
    fn gather_rows(&self, rows: &mut StarRows, state: &[f64], qdd: &[f64]) {
        let (n, np) = (self.elements, self.positions_len());
        let (positions, velocities) = state.split_at(np);
        let sources = [positions, velocities, qdd];
        let p = self.effector_index(0);
        for cable in 0..self.robot.cables() {
            let (o, li) = (cable * (n + 1), self.l_index(cable));
            let l_acceleration = if self.length_driven {
                self.commanded_l_acceleration(state, cable)
            } else {
                qdd[li]
            };
            rows.l[o..o + n + 1].fill(positions[li]);
            rows.l_rate[o..o + n + 1].fill(velocities[li]);
            rows.l_acceleration[o..o + n + 1].fill(l_acceleration);
            // The arm's columns cut once (a store through a column then cannot move another).
            let columns = rows.nodes.each_mut().map(|c| &mut c[o..o + n + 1]);
            let pulley = self.pulley(cable);
            for axis in 0..3 {
                columns[axis][0] = pulley[axis];
                columns[3 + axis][0] = 0.0;
                columns[6 + axis][0] = 0.0;
            }
            // The arm's free nodes lie together in q, (x, y, z) per node.
            let free = 3 * cable * (n - 1);
            for (q, source) in sources.iter().enumerate() {
                let nodes = source[free..free + 3 * (n - 1)].chunks_exact(3);
                for (k, node) in nodes.enumerate() {
                    for axis in 0..3 {
                        columns[3 * q + axis][k + 1] = node[axis];
                    }
                }
            }
            for (q, source) in sources.iter().enumerate() {
                for axis in 0..3 {
                    columns[3 * q + axis][n] = source[p + axis];
                }
            }
            self.gather_stored(rows, cable, state, qdd);
        }
    }

    /// Cable `cable`'s stored element into `rows`, as [`FeSpatial::stored_element`] has it.
    fn gather_stored(&self, rows: &mut StarRows, cable: usize, state: &[f64], qdd: &[f64]) {
        let (np, li) = (self.positions_len(), self.l_index(cable));
        let s = rows.stored(cable);
        let joint = (s + 2).min(rows.l.len());
        rows.l[s..joint].fill(state[li]);
        rows.l_rate[s..joint].fill(state[np + li]);
        rows.l_acceleration[s..joint].fill(qdd[li]);
        // The model's L0 as it is now (a public field), as `stored_element` reads it.
        rows.set_total_length(cable, self.modelled_length);
        let (pulley, reel) = (self.pulley(cable), self.reels[cable]);
        let reel_end = [
            pulley + reel * state[li + 1],
            reel * state[np + li + 1],
            reel * qdd[li + 1],
        ];
        for (q, at) in reel_end.iter().enumerate() {
            for axis in 0..3 {
                rows.nodes[3 * q + axis][s] = at[axis];
                rows.nodes[3 * q + axis][s + 1] = if q == 0 { pulley[axis] } else { 0.0 };
            }
        }
    }

    /// R from the evaluated element rows (see [`Self::element_residual`]).
    fn sum_rows(&self, rows: &StarRows, qdd: &[f64], tensions: &[f64], r: &mut [f64]) {
        let n = self.elements;
        let p = self.effector_index(0);
        let row = |columns: &[Vec<f64>; 3], i: usize| {
            Vector3::new(columns[0][i], columns[1][i], columns[2][i])
        };
        let weight = Vector3::new(0.0, 0.0, self.material.gravity);
        let mut r_p =
            (Vector3::new(qdd[p], qdd[p + 1], qdd[p + 2]) + weight) * self.robot.effector_mass;
        for (cable, tension) in tensions.iter().enumerate().take(self.robot.cables()) {
            // Free node k's rows: element k's node b and element k + 1's node a.
            let (o, free) = (cable * (n + 1), 3 * cable * (n - 1));
            let nodes = &mut r[free..free + 3 * (n - 1)];
            for axis in 0..3 {
                let (b, a) = (
                    &rows.rows.b[axis][o..o + n - 1],
                    &rows.rows.a[axis][o + 1..o + n],
                );
                for ((node, b), a) in nodes.chunks_exact_mut(3).zip(b).zip(a) {
                    node[axis] = b + a;
                }
            }
            r_p += row(&rows.rows.b, o + n - 1);
            let (li, rho) = (self.l_index(cable), self.l_index(cable) + 1);
            if self.length_driven {
                r[li] = qdd[li] - rows.l_acceleration[o];
                r[rho] = qdd[rho];
            } else {
                // The stored element: its l row, and its reel end's rows along r_i.
                let s = rows.stored(cable);
                let span: f64 = rows.rows.l[o..o + n].iter().sum();
                r[li] = span + rows.rows.l[s];
                r[rho] = row(&rows.rows.a, s).dot(&self.reels[cable]) - tension;
            }
        }
        r[p..p + 3].copy_from_slice(r_p.as_slice());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::FeMass;
    use proptest::prelude::*;

    proptest! {
        /// Every lane's rows are the scalar element kernel's bit for bit, for each span element
        /// of 1 … 8 arms of N = 1 … 12 elements (lengths that leave a partial vector) and each
        /// stored element (h = L0 − l, h' = −1), nodes, lengths, rates and accelerations
        /// random, with and without damping, lumped and consistent mass.
        #[test]
        fn lanes_are_the_scalar_kernel_bit_for_bit(
            arms in 1usize..9,
            n in 1usize..13,
            lumped in any::<bool>(),
            damping in prop_oneof![Just(0.0), 0.5f64..5.0],
            seed in prop::collection::vec(-1.0f64..1.0, 31),
        ) {
            let mass = if lumped { FeMass::Lumped } else { FeMass::Consistent };
            let w = |k: usize| 1.0 - k as f64 / n as f64;
            let coefficients: Vec<_> =
                (1..=n).map(|e| MassCoefficients::new(mass, w(e - 1), w(e))).collect();
            let stored = MassCoefficients::new(mass, 0.0, 1.0);
            let total = 3.0;
            let mat = Material { ea: 1.0e4, mu: 0.05, gravity: 9.81 };
            let mut rows = StarRows::new(arms, &coefficients, &stored);
            for a in 0..arms {
                rows.set_total_length(a, total);
            }
            // Values spread from the seed: consecutive nodes 0.17 ± 0.1 m apart and every
            // element's h 0.17 ± 0.05 m, so each one is taut or slack by the draw.
            let value = |j: usize, k: usize| seed[(7 * j + 3 * k) % seed.len()] * (1.0 + 0.01 * k as f64);
            let len = rows.l.len();
            for j in 0..=len {
                for k in 0..9 {
                    rows.nodes[k][j] = if k < 3 { 0.1 * j as f64 + 0.05 * value(j, k) } else { value(j, k) };
                }
            }
            for i in 0..len {
                rows.l[i] = n as f64 * (0.17 + 0.05 * value(i, 1));
                rows.l_rate[i] = value(i, 5);
                rows.l_acceleration[i] = value(i, 11);
            }
            for a in 0..arms {
                let s = rows.stored(a);
                rows.l[s] = total - (0.17 + 0.05 * value(s, 1));
            }
            rows.evaluate(&mat, damping);
            let el = &rows;
            let node = |q: usize, j: usize| Vector3::new(el.nodes[3 * q][j], el.nodes[3 * q + 1][j], el.nodes[3 * q + 2][j]);
            let same = |u: Vector3<f64>, v: [f64; 3]| (0..3).all(|k| u[k].to_bits() == v[k].to_bits());
            let elements = (0..arms).flat_map(|a| (1..=n).map(move |e| (a * (n + 1) + e - 1, Some(e))));
            let stored_elements = (0..arms).map(|a| (el.stored(a), None));
            for (i, e) in elements.chain(stored_elements) {
                let (h, h_prime, k) = match e {
                    Some(e) => (el.l[i] / n as f64, 1.0 / n as f64, &coefficients[e - 1]),
                    None => (total - el.l[i], -1.0, &stored),
                };
                let s = ElementState::new(
                    (node(0, i), node(1, i)),
                    (node(0, i + 1), node(1, i + 1)),
                    el.l_rate[i],
                    h,
                    h_prime,
                );
                let (ra, rb, rl) = element::residual_at_chord(
                    &mat, k, &s, damping, Chord::of(&s),
                    node(2, i), node(2, i + 1), el.l_acceleration[i],
                );
                let at = |r: &[Vec<f64>; 3]| [r[0][i], r[1][i], r[2][i]];
                prop_assert!(same(ra, at(&el.rows.a)) && same(rb, at(&el.rows.b)), "element {i} ({e:?})");
                prop_assert_eq!(rl.to_bits(), el.rows.l[i].to_bits(), "element {} ({:?})", i, e);
            }
        }
    }
}
