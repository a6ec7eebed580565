//! # cdpr-lumped: lumped mass-spring cables over point pulleys (paper §2.2, MODELS.md §4)
//!
//! Each cable is N point masses P_0 … P_{N−1} (each m = μ l0, l0 = L0/N) joined by N tension-only
//! springs of stiffness k0 = EA/l0; spring j joins P_j and P_{j+1}, and P_N is the effector, shared
//! by both cables. P_0 is the reel end, pulled by the commanded tension along e_out. Nodes beyond
//! the pulley are *stored* (rolled on the reel): they slide on z = 0 (paper eq. 6). The spring
//! that straddles the pulley measures its length along the cable path over the pulley (eq. 4);
//! each spring's tension follows eq. 5 and each free node moves by eq. 7. Nodes pass the pulley
//! as located events ([`pulley`]); no node ever changes mass, so the cable mass is conserved exactly.
//!
//! State: positions then velocities, each laid out as structure-of-arrays so that the spring loop
//! vectorises: `[x of cable 1 nodes 0…N−1 | z of cable 1 | x of cable 2 | z of cable 2 | x_P, z_P]`,
//! 4N + 2 components, then the velocities in the same order; the state has 2(4N + 2) components
//! (stored nodes keep z = ż = 0). The number of stored nodes r_i per cable is the model's discrete
//! mode.

mod damped;
pub mod fixed_cable;
mod implicit;
mod modal;
pub mod params;
mod path;
mod pulley;
pub mod spatial;
mod statics;

use cdpr_core::model::{CableModel, Energy, Equilibrium, ModelError, ModelEvent, RestRule};
use cdpr_core::robot::{Effector, PerCable, Robot};
use cdpr_core::scenario::Scenario;
use nalgebra::Vector2;

pub use params::Params;
pub use pulley::PULLEY_OFFSET;

/// The two-cable robot with lumped mass-spring cables.
#[derive(Debug, Clone, PartialEq)]
pub struct Lumped {
    /// The planar robot: pulleys A1 = (0, 0), A2 = (d, 0).
    pub robot: Robot<2>,
    /// Pulley distance d [m].
    pub anchor_distance: f64,
    /// Effector mass M [kg].
    pub effector_mass: f64,
    /// Gravity g [m/s²] along −z.
    pub gravity: f64,
    /// Elements (springs, and masses) per cable N.
    pub elements: usize,
    /// Unstrained spring length l0 = L0/N [m].
    pub segment: f64,
    /// Node mass m = μ l0 [kg].
    pub node_mass: f64,
    /// Spring stiffness k0 = EA/l0 [N/m].
    pub stiffness: f64,
    /// Kelvin–Voigt coefficient per unit length rate, C/l0 [N s/m] (0: undamped, the paper's run).
    pub damping: f64,
    /// Number of stored nodes r_i of each cable (nodes 0 … r_i − 1 lie beyond the pulley).
    stored: [usize; 2],
    /// Per cable, the forces each spring puts on its two end nodes (allocated once).
    scratch: [SpringForces; 2],
    /// Buffers of the second-order form ([`implicit`]).
    implicit: implicit::ImplicitScratch,
}

/// Forces of the springs j = 0 … N−1 of one cable on their end nodes a = P_j and b = P_{j+1} [N].
#[derive(Debug, Clone, PartialEq, Default)]
struct SpringForces {
    ax: Vec<f64>,
    az: Vec<f64>,
    bx: Vec<f64>,
    bz: Vec<f64>,
}

impl SpringForces {
    fn new(n: usize) -> Self {
        Self {
            ax: vec![0.0; n],
            az: vec![0.0; n],
            bx: vec![0.0; n],
            bz: vec![0.0; n],
        }
    }
}

/// The lumped spring law (paper eq. 5, MODELS.md §4): T = k0 (λ − l0) + (C/l0) λ̇ while taut
/// (λ > l0), else 0;
/// a damping part that would make the spring push is clipped, so T ≥ 0 always.
/// `stiffness` k0 [N/m], `segment` l0 [m], `damping` C/l0 [N s/m], `length` λ [m], `rate` λ̇ [m/s].
#[inline]
pub fn spring_tension(stiffness: f64, segment: f64, damping: f64, length: f64, rate: f64) -> f64 {
    let stretch = length - segment;
    if stretch <= 0.0 {
        return 0.0;
    }
    (stiffness * stretch + damping * rate).max(0.0)
}

/// Direction from each pulley towards its reel along x, e_out,i of MODELS.md §4.
pub const TOWARD_REEL: [f64; 2] = [-1.0, 1.0];

impl Lumped {
    /// The model with the scenario's robot, cable and element count; r_i are set by
    /// [`CableModel::equilibrium`].
    pub fn new(scenario: &Scenario, params: Params) -> Result<Self, ModelError> {
        let n = params.elements;
        if n < params::MIN_ELEMENTS {
            return Err(ModelError::Parameter {
                name: "model.elements",
                value: n as f64,
                allowed: "≥ 3 for the lumped model (a reel end, a straddling spring, a free node)"
                    .into(),
            });
        }
        let cable = &scenario.cable;
        let segment = cable.modelled_length / n as f64;
        Ok(Self {
            robot: scenario.robot(),
            anchor_distance: scenario.robot.anchor_distance,
            effector_mass: scenario.robot.effector_mass,
            gravity: scenario.robot.gravity,
            elements: n,
            segment,
            node_mass: cable.mass_per_length() * segment,
            stiffness: cable.axial_stiffness() / segment,
            damping: cable.axial_damping / segment,
            stored: [n / 2, n / 2],
            scratch: [SpringForces::new(n), SpringForces::new(n)],
            implicit: Default::default(),
        })
    }

    /// Stored nodes per cable, r_i.
    pub fn stored(&self) -> [usize; 2] {
        self.stored
    }

    /// Sets the stored-node counts (the discrete mode), e.g. for a hand-made state.
    pub fn set_stored(&mut self, stored: [usize; 2]) {
        self.stored = stored;
    }

    /// Pulley point A_i [m].
    pub fn pulley(&self, cable: usize) -> Vector2<f64> {
        Vector2::new(
            if cable == 0 {
                0.0
            } else {
                self.anchor_distance
            },
            0.0,
        )
    }

    /// Number of position coordinates, 4N + 2.
    pub fn positions_len(&self) -> usize {
        4 * self.elements + 2
    }

    /// Index of the x coordinate of node `j` of `cable` (j = N is the effector).
    pub fn x_index(&self, cable: usize, j: usize) -> usize {
        if j == self.elements {
            4 * self.elements
        } else {
            2 * cable * self.elements + j
        }
    }

    /// Index of the z coordinate of node `j` of `cable` (j = N is the effector).
    pub fn z_index(&self, cable: usize, j: usize) -> usize {
        if j == self.elements {
            4 * self.elements + 1
        } else {
            (2 * cable + 1) * self.elements + j
        }
    }

    /// Position of node `j` of `cable` (the effector at j = N) [m].
    pub fn node(&self, y: &[f64], cable: usize, j: usize) -> Vector2<f64> {
        Vector2::new(y[self.x_index(cable, j)], y[self.z_index(cable, j)])
    }

    /// Velocity of node `j` of `cable` [m/s].
    pub fn node_velocity(&self, y: &[f64], cable: usize, j: usize) -> Vector2<f64> {
        let np = self.positions_len();
        Vector2::new(
            y[np + self.x_index(cable, j)],
            y[np + self.z_index(cable, j)],
        )
    }

    #[inline]
    fn spring_tension(&self, length: f64, rate: f64) -> f64 {
        spring_tension(self.stiffness, self.segment, self.damping, length, rate)
    }

    /// Length λ_j of spring j of `cable` along the cable path (eq. 4 for the straddling spring):
    /// [`Self::spring`] without the rate and directions, for the energy and the output channels
    /// (per sample, where the full version was a third of the lumped implicit run).
    #[inline]
    pub fn spring_length(&self, y: &[f64], cable: usize, j: usize) -> f64 {
        crate::path::path_length(
            (self.node(y, cable, j), self.node(y, cable, j + 1)),
            (j + 1 == self.stored[cable]).then(|| self.pulley(cable)),
        )
    }

    /// Length λ_j of spring j of `cable` along the cable path, its rate λ̇_j, and the unit vectors
    /// along which it pulls its two end nodes. The straddling spring j = r − 1 runs over the pulley
    /// (eq. 4): λ = |P_{r−1} A| + |A P_r|, pulling both ends towards A.
    #[inline]
    fn spring(&self, y: &[f64], cable: usize, j: usize) -> (f64, f64, Vector2<f64>, Vector2<f64>) {
        path::spring_path(
            (self.node(y, cable, j), self.node(y, cable, j + 1)),
            (
                self.node_velocity(y, cable, j),
                self.node_velocity(y, cable, j + 1),
            ),
            (j + 1 == self.stored[cable]).then(|| self.pulley(cable)),
        )
    }

    /// Net forces on every position coordinate [N] (gravity included; stored nodes' vertical
    /// forces are constraint-reacted and zeroed: paper eq. 6; free nodes and the node past the
    /// pulley: eq. 7), for the commanded tensions. The springs between
    /// two cable nodes are computed in one vectorisable sweep; the straddling spring and the spring
    /// to the effector are then recomputed along the cable path.
    fn forces(&mut self, y: &[f64], tensions: &[f64], out: &mut [f64]) {
        let n = self.elements;
        let np = self.positions_len();
        let (k, l0, c) = (self.stiffness, self.segment, self.damping);
        let mut effector = Vector2::new(0.0, -self.effector_mass * self.gravity);
        for cable in 0..2 {
            let mut s = std::mem::take(&mut self.scratch[cable]);
            let (bx, bz) = (self.x_index(cable, 0), self.z_index(cable, 0));
            let (x, z) = (&y[bx..bx + n], &y[bz..bz + n]);
            let (vx, vz) = (&y[np + bx..np + bx + n], &y[np + bz..np + bz + n]);
            let m = n - 1;
            let (ax, az, sbx, sbz) = (
                &mut s.ax[..m],
                &mut s.az[..m],
                &mut s.bx[..m],
                &mut s.bz[..m],
            );
            if c == 0.0 {
                // Undamped: max(k (λ − l0), 0) is the whole tension-only law, branch-free.
                for j in 0..m {
                    let (dx, dz) = (x[j + 1] - x[j], z[j + 1] - z[j]);
                    let length = (dx * dx + dz * dz).sqrt();
                    let per_length = (k * (length - l0)).max(0.0) / length;
                    ax[j] = per_length * dx;
                    az[j] = per_length * dz;
                    sbx[j] = -per_length * dx;
                    sbz[j] = -per_length * dz;
                }
            } else {
                for j in 0..m {
                    let (dx, dz) = (x[j + 1] - x[j], z[j + 1] - z[j]);
                    let length = (dx * dx + dz * dz).sqrt();
                    let inv = 1.0 / length;
                    let rate = (dx * (vx[j + 1] - vx[j]) + dz * (vz[j + 1] - vz[j])) * inv;
                    let stretch = length - l0;
                    let taut = (k * stretch + c * rate).max(0.0);
                    let per_length = if stretch > 0.0 { taut * inv } else { 0.0 };
                    ax[j] = per_length * dx;
                    az[j] = per_length * dz;
                    sbx[j] = -per_length * dx;
                    sbz[j] = -per_length * dz;
                }
            }
            let r = self.stored[cable];
            for j in [Some(n - 1), r.checked_sub(1)].into_iter().flatten() {
                let (length, rate, ua, ub) = self.spring(y, cable, j);
                let t = self.spring_tension(length, rate);
                (s.ax[j], s.az[j], s.bx[j], s.bz[j]) = (t * ua.x, t * ua.y, t * ub.x, t * ub.y);
            }
            let (fx, rest) = out[bx..].split_at_mut(n);
            let fz = &mut rest[..n];
            fx[0] = s.ax[0] + tensions[cable] * TOWARD_REEL[cable];
            fz[0] = s.az[0];
            for j in 1..n {
                fx[j] = s.ax[j] + s.bx[j - 1];
                fz[j] = s.az[j] + s.bz[j - 1];
            }
            let weight = self.node_mass * self.gravity;
            fz[..r].fill(0.0);
            fz[r..].iter_mut().for_each(|f| *f -= weight);
            effector += Vector2::new(s.bx[n - 1], s.bz[n - 1]);
            self.scratch[cable] = s;
        }
        out[4 * n] = effector.x;
        out[4 * n + 1] = effector.y;
    }

    /// Tension of spring j of `cable` [N].
    pub fn spring_force(&self, y: &[f64], cable: usize, j: usize) -> f64 {
        let (length, rate, _, _) = self.spring(y, cable, j);
        self.spring_tension(length, rate)
    }

    /// Unstrained length of cable between the pulley and the effector [m]: the free springs plus
    /// the free-side share of the straddling spring (uniform strain along it).
    pub fn free_length(&self, y: &[f64], cable: usize) -> f64 {
        let r = self.stored[cable];
        crate::path::free_length(
            (self.elements, r, self.segment),
            self.pulley(cable),
            (r > 0).then(|| (self.node(y, cable, r - 1), self.node(y, cable, r))),
        )
    }

    /// Total mass of the cables [kg] (constant: every node keeps its mass).
    pub fn cable_mass(&self) -> f64 {
        2.0 * self.elements as f64 * self.node_mass
    }
}

impl CableModel<2> for Lumped {
    fn name(&self) -> &'static str {
        "lumped"
    }

    fn robot(&self) -> &Robot<2> {
        &self.robot
    }

    fn state_len(&self) -> usize {
        2 * self.positions_len()
    }

    fn equilibrium(&mut self, rule: &dyn RestRule<2>) -> Result<Equilibrium, ModelError> {
        statics::equilibrium(self, rule)
    }

    fn rhs(&mut self, _t: f64, y: &[f64], tensions: &[f64], rate: &mut [f64]) {
        let n = self.elements;
        let np = self.positions_len();
        let (dq, dv) = rate.split_at_mut(np);
        dq.copy_from_slice(&y[np..]);
        self.forces(y, tensions, dv);
        let inv_m = 1.0 / self.node_mass;
        dv[..4 * n].iter_mut().for_each(|a| *a *= inv_m);
        dv[4 * n] /= self.effector_mass;
        dv[4 * n + 1] /= self.effector_mass;
        for cable in 0..2 {
            let bz = self.z_index(cable, 0);
            dq[bz..bz + self.stored[cable]].fill(0.0);
        }
    }

    fn effector(&self, y: &[f64]) -> Effector<2> {
        Effector {
            position: self.node(y, 0, self.elements),
            velocity: self.node_velocity(y, 0, self.elements),
        }
    }

    /// The reel end P_0 moving along e_out takes cable in.
    fn reel_speeds(&self, y: &[f64]) -> PerCable {
        PerCable::from_fn(2, |c| self.node_velocity(y, c, 0).x * TOWARD_REEL[c])
    }

    fn energy(&self, y: &[f64]) -> Energy {
        // One sweep over each cable's contiguous coordinate slices (this runs per output sample),
        // then the springs whose path is not the straight chord: the straddling one (eq. 4) and
        // the one to the effector.
        let n = self.elements;
        let np = self.positions_len();
        let (m, g, l0, k) = (self.node_mass, self.gravity, self.segment, self.stiffness);
        let elastic = |length: f64| {
            let stretch = (length - l0).max(0.0);
            0.5 * k * stretch * stretch
        };
        let mut e = Energy::default();
        for cable in 0..2 {
            let (bx, bz) = (self.x_index(cable, 0), self.z_index(cable, 0));
            let (x, z) = (&y[bx..bx + n], &y[bz..bz + n]);
            let (vx, vz) = (&y[np + bx..np + bx + n], &y[np + bz..np + bz + n]);
            e.kinetic += 0.5 * m * (sum_of_squares(vx) + sum_of_squares(vz));
            // Stored nodes sit at z = 0 exactly, so they add nothing here.
            e.gravity += m * g * sum(z);
            // The chords of springs 0 … N − 2 but the straddling one's.
            e.elastic += match self.stored[cable].checked_sub(1) {
                Some(j) if j < n - 1 => {
                    chord_elastic(&x[..=j], &z[..=j], k, l0)
                        + chord_elastic(&x[j + 1..], &z[j + 1..], k, l0)
                        + elastic(self.spring_length(y, cable, j))
                }
                _ => chord_elastic(x, z, k, l0),
            };
            e.elastic += elastic(self.spring_length(y, cable, n - 1));
        }
        let (p, v) = (self.node(y, 0, n), self.node_velocity(y, 0, n));
        e.kinetic += 0.5 * self.effector_mass * v.norm_squared();
        e.gravity += self.effector_mass * g * p.y;
        e
    }

    /// Power of the damping forces: Σ (T − k0 (λ − l0)⁺) λ̇ ≥ 0 (clipping included).
    fn dissipation(&self, y: &[f64]) -> f64 {
        if self.damping == 0.0 {
            return 0.0;
        }
        let mut d = 0.0;
        for cable in 0..2 {
            for j in 0..self.elements {
                let (length, rate, _, _) = self.spring(y, cable, j);
                let elastic = self.stiffness * (length - self.segment).max(0.0);
                d += (self.spring_tension(length, rate) - elastic) * rate;
            }
        }
        d
    }

    fn event_count(&self) -> usize {
        pulley::EVENT_COUNT
    }

    fn event_functions(&self, y: &[f64], out: &mut [f64]) {
        pulley::event_functions(self, y, out);
    }

    fn apply_event(
        &mut self,
        index: usize,
        t: f64,
        y: &mut [f64],
    ) -> Result<ModelEvent, ModelError> {
        pulley::apply_event(self, index, t, y)
    }

    fn channel_names(&self) -> Vec<String> {
        cdpr_core::channel::Channel::cable_channel_names(2)
    }

    fn channel_units(&self) -> Vec<&'static str> {
        cdpr_core::channel::Channel::cable_channel_units(2, "nodes")
    }

    fn second_order(&self) -> Option<&dyn cdpr_core::second_order::SecondOrderForm> {
        Some(self)
    }

    fn second_order_mut(&mut self) -> Option<&mut dyn cdpr_core::second_order::SecondOrderForm> {
        Some(self)
    }

    fn modal_layout(&self, state: &[f64]) -> cdpr_core::modal_layout::ModalLayout {
        self.modal_layout_of(state)
    }

    /// Spring tensions at the effector and over the pulley [N], free unstrained lengths [m] and
    /// stored-node counts.
    fn channels(&self, y: &[f64], _tensions: &[f64], out: &mut [f64]) {
        let n = self.elements;
        let straddle = |c: usize| {
            let r = self.stored[c];
            if r == 0 {
                f64::NAN
            } else {
                self.spring_force(y, c, r - 1)
            }
        };
        out.copy_from_slice(&[
            self.spring_force(y, 0, n - 1),
            self.spring_force(y, 1, n - 1),
            straddle(0),
            straddle(1),
            self.free_length(y, 0),
            self.free_length(y, 1),
            self.stored[0] as f64,
            self.stored[1] as f64,
        ]);
    }
}

/// Σ ½ k max(|P_{j+1} − P_j| − l0, 0)² [J] over consecutive points (x_j, z_j): the chord
/// springs' strain energy. Two independent lanes, so that the square roots pair up and the sum's
/// add chain halves (this runs per output sample).
fn chord_elastic(x: &[f64], z: &[f64], k: f64, l0: f64) -> f64 {
    if x.len() < 2 {
        return 0.0;
    }
    let springs = x.len() - 1;
    let (xa, xb, za, zb) = (&x[..springs], &x[1..], &z[..springs], &z[1..]);
    let squared_stretch = |xa: f64, xb: f64, za: f64, zb: f64| {
        let (dx, dz) = (xb - xa, zb - za);
        let stretch = ((dx * dx + dz * dz).sqrt() - l0).max(0.0);
        stretch * stretch
    };
    let mut lanes = [0.0; 2];
    let pairs = xa
        .chunks_exact(2)
        .zip(xb.chunks_exact(2))
        .zip(za.chunks_exact(2).zip(zb.chunks_exact(2)));
    for ((xa, xb), (za, zb)) in pairs {
        lanes[0] += squared_stretch(xa[0], xb[0], za[0], zb[0]);
        lanes[1] += squared_stretch(xa[1], xb[1], za[1], zb[1]);
    }
    if springs % 2 == 1 {
        let j = springs - 1;
        lanes[0] += squared_stretch(xa[j], xb[j], za[j], zb[j]);
    }
    0.5 * k * (lanes[0] + lanes[1])
}

/// Σ v² in four independent lanes (the add chain of a sequential sum is its cost).
fn sum_of_squares(v: &[f64]) -> f64 {
    let mut lanes = [0.0; 4];
    let chunks = v.chunks_exact(4);
    let tail: f64 = chunks.remainder().iter().map(|a| a * a).sum();
    for chunk in chunks {
        for (total, a) in lanes.iter_mut().zip(chunk) {
            *total += a * a;
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// Σ v in four independent lanes.
fn sum(v: &[f64]) -> f64 {
    let mut lanes = [0.0; 4];
    let chunks = v.chunks_exact(4);
    let tail: f64 = chunks.remainder().iter().sum();
    for chunk in chunks {
        for (total, a) in lanes.iter_mut().zip(chunk) {
            *total += a;
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The two-lane chord sum is the plain Σ ½ k max(λ − l0, 0)² over every length (odd and
        /// even spring counts, slack springs included), to the round-off of reordering a sum of
        /// positive terms: 1e-14 relative (≈ 50 ulps; the sums here have at most 60 terms).
        #[test]
        fn chord_elastic_is_the_plain_sum(
            points in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 0..60),
            l0 in 0.0f64..0.5,
        ) {
            let k = 7.2e6;
            let (x, z): (Vec<f64>, Vec<f64>) = points.into_iter().unzip();
            let plain: f64 = (1..x.len())
                .map(|j| {
                    let length = (x[j] - x[j - 1]).hypot(z[j] - z[j - 1]);
                    let stretch = (length - l0).max(0.0);
                    0.5 * k * stretch * stretch
                })
                .sum();
            let lanes = chord_elastic(&x, &z, k, l0);
            prop_assert!((lanes - plain).abs() <= 1e-14 * plain, "{lanes} vs {plain}");
        }

        /// The four-lane sums are the plain sums to reordering round-off (terms of both signs:
        /// 1e-14 of Σ|v|).
        #[test]
        fn lane_sums_are_the_plain_sums(v in prop::collection::vec(-1.0f64..1.0, 0..90)) {
            let plain: f64 = v.iter().sum();
            let scale: f64 = v.iter().map(|a| a.abs()).sum();
            prop_assert!((sum(&v) - plain).abs() <= 1e-14 * scale);
            let squares: f64 = v.iter().map(|a| a * a).sum();
            prop_assert!((sum_of_squares(&v) - squares).abs() <= 1e-14 * squares);
        }
    }
}
