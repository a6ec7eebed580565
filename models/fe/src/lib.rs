//! # cdpr-fe: variable-length finite-element cables (paper §2.3, MODELS.md §5)
//!
//! Each cable is one closed material system (FE.1): the stored part on the line z = 0 from the reel
//! end R_i to the pulley A_i, and the free span from A_i to the effector P. The span is N two-node
//! elements of equal unstrained length h = l_i/N whose nodes sit at fixed fractions ξ_k = k/N of
//! the span; the span's unstrained length l_i is itself a generalised coordinate, so material flows
//! through the nodes at the convective speed l_i'(1 − ξ_k) (FE.3). The stored cable is one more
//! element of the same kind ([`element`]), of unstrained length L0 − l_i, whose reel end R_i sits at
//! distance ρ_i from the pulley; the commanded tension T_i pulls R_i away from the pulley (Q_ρ = T_i).
//! Nothing is prescribed kinematically: Lagrange's equations (paper eq. 11) of the kinetic and
//! potential energies (eq. 8, 9) contain every mass-flux term of eq. 10, so dE/dt = T_1 ρ_1' +
//! T_2 ρ_2' exactly (FE.7) and the runner's `e_residual` audits it; each element contributes its
//! rows of eq. 12 ([`element`]).
//!
//! Generalised coordinates (FE.5.1) in the chain order of FE.5.5, as structure-of-arrays:
//! `q = [x of the 2N − 1 chain nodes | z of the chain nodes | l1, ρ1, l2, ρ2]` with the chain
//! cable 1 nodes 1…N−1, P, cable 2 nodes N−1…1; n = 4(N − 1) + 6. The state is (q, q'), 2n long.
//! The rigid-stored variant (FE.1.3) drops ρ_i: the border is (l1, l2), n = 4(N − 1) + 4.
//!
//! Per right-hand side: assemble M(q) and F(q, q', T) element by element ([`element::terms`]), then
//! the O(N) block solve of FE.5.5 ([`solve::ChainSystem`]); nothing is allocated. The implicit
//! path's residual M q'' − F sums each element's rows without assembling
//! ([`element::residual_at_chord`], the span elements in lanes).

mod assembly;
pub mod element;
pub mod fixed_cable;
mod implicit;
mod lanes;
mod modal;
pub mod params;
pub mod solve;
pub mod spatial;
mod statics;

use cdpr_core::model::{CableModel, Energy, Equilibrium, ModelError, RestRule};
use cdpr_core::robot::{Effector, PerCable, Robot};
use cdpr_core::scenario::Scenario;
use element::{Chord, ElementState, MassCoefficients, Material};
use nalgebra::Vector2;
pub use params::{FeMass, FeStored, Params};
use solve::ChainSystem;

/// Direction from each pulley towards its reel along x, e_out,i of MODELS.md FE.2.
pub const TOWARD_REEL: [f64; 2] = [-1.0, 1.0];

/// What the N free elements of a span share: l' [m/s], h = l_i/N [m], 1/h [1/m] and h' = 1/N.
#[derive(Debug, Clone, Copy)]
struct Span {
    l_rate: f64,
    h: f64,
    inv_h: f64,
    h_prime: f64,
}

impl Span {
    /// The element between nodes (r_a, v_a) and (r_b, v_b) of this span.
    #[inline]
    fn element(
        &self,
        (ra, va): (Vector2<f64>, Vector2<f64>),
        (rb, vb): (Vector2<f64>, Vector2<f64>),
    ) -> ElementState {
        ElementState {
            ra,
            rb,
            va,
            vb,
            l_rate: self.l_rate,
            h: self.h,
            inv_h: self.inv_h,
            h_prime: self.h_prime,
        }
    }
}

/// The two-cable robot with variable-length FE cables.
#[derive(Debug, Clone, PartialEq)]
pub struct Fe {
    /// Pulley distance d [m]: A1 = (0, 0), A2 = (d, 0).
    pub anchor_distance: f64,
    /// The planar robot: pulleys A1 = (0, 0), A2 = (d, 0).
    pub robot: Robot<2>,
    /// Effector mass M [kg].
    pub effector_mass: f64,
    /// Free-span elements per cable N.
    pub elements: usize,
    /// Total unstrained length per cable L0 (stored + free) [m].
    pub modelled_length: f64,
    /// EA [N], μ [kg/m], g [m/s²].
    pub material: Material,
    /// Consistent (reference) or lumped mass (FE.1.5).
    pub mass: FeMass,
    /// Elastic stored element (reference) or rigid stored cable (FE.1.3).
    pub stored: FeStored,
    /// Kelvin–Voigt axial damping C [N s] of MODELS.md FE.5.7 (0: undamped, the paper's run). The
    /// rigid stored cable (FE.1.3) has no strain and so no damping.
    pub axial_damping: f64,
    /// Mass coefficients of the free elements e = 1…N (index e − 1).
    coefficients: Vec<MassCoefficients>,
    /// Mass coefficients of the stored element (w_R = 0, w_A = 1).
    stored_coefficients: MassCoefficients,
    /// Border position of l_1, l_2 (0, 2 with ρ_i after each; 0, 1 for the rigid stored cable).
    border_l: [usize; 2],
    /// Border size: 4 or 2.
    border: usize,
    /// Assembled M, F and the solve's scratch (allocated once; taken out while assembling).
    system: ChainSystem,
    /// The chain's chords (between consecutive chain nodes) and their inverses, per assembly.
    chord_length: Vec<f64>,
    chord_inv_length: Vec<f64>,
    /// The implicit residual's chain elements (fixed coefficients, rows per evaluation).
    chain_rows: lanes::ChainRows,
    /// The last iteration matrix's difference quotients, for a new step size
    /// (`SecondOrderForm::reweighted_matrix`).
    matrix_parts: cdpr_numerics::MatrixParts,
}

impl Fe {
    /// The model with the scenario's robot, cable, element count and variants.
    pub fn new(scenario: &Scenario, params: Params) -> Result<Self, ModelError> {
        let n = params.elements;
        if n < 1 {
            return Err(ModelError::Parameter {
                name: "model.elements",
                value: n as f64,
                allowed: "≥ 1 for the FE model".into(),
            });
        }
        let cable = &scenario.cable;
        if !(cable.axial_damping >= 0.0 && cable.axial_damping.is_finite()) {
            return Err(ModelError::Parameter {
                name: "cable.axial_damping",
                value: cable.axial_damping,
                allowed: "finite and ≥ 0 N s (Kelvin–Voigt, MODELS.md FE.5.7)".into(),
            });
        }
        let Params { mass, stored, .. } = params;
        let coefficients = (1..=n)
            .map(|e| {
                let w = |k: usize| 1.0 - k as f64 / n as f64;
                MassCoefficients::new(mass, w(e - 1), w(e))
            })
            .collect::<Vec<_>>();
        let chain_rows = lanes::ChainRows::new(n, &coefficients);
        let nodes = 2 * n - 1;
        let (border, l_index) = match stored {
            FeStored::Elastic => (4, [0, 2]),
            FeStored::Rigid => (2, [0, 1]),
        };
        Ok(Self {
            anchor_distance: scenario.robot.anchor_distance,
            robot: scenario.robot(),
            effector_mass: scenario.robot.effector_mass,
            elements: n,
            modelled_length: cable.modelled_length,
            material: Material {
                ea: cable.axial_stiffness(),
                mu: cable.mass_per_length(),
                gravity: scenario.robot.gravity,
            },
            mass,
            stored,
            axial_damping: cable.axial_damping,
            coefficients,
            stored_coefficients: MassCoefficients::new(mass, 0.0, 1.0),
            border_l: l_index,
            border,
            system: ChainSystem::new(nodes, border, l_index),
            chord_length: vec![0.0; nodes - 1],
            chord_inv_length: vec![0.0; nodes - 1],
            chain_rows,
            matrix_parts: cdpr_numerics::MatrixParts::default(),
        })
    }

    /// Chain nodes 2N − 1 (cable 1 nodes 1…N−1, P, cable 2 nodes N−1…1).
    pub fn chain_nodes(&self) -> usize {
        2 * self.elements - 1
    }

    /// Border unknowns: 4 (l1, ρ1, l2, ρ2) or 2 (l1, l2, rigid stored cable).
    pub fn border_len(&self) -> usize {
        self.border
    }

    /// Number of generalised coordinates n (FE.5.1).
    pub fn positions_len(&self) -> usize {
        2 * self.chain_nodes() + self.border_len()
    }

    /// Chain index of node k (1…N) of `cable` (0 or 1); None for the pulley node k = 0.
    #[inline]
    pub fn chain_index(&self, cable: usize, k: usize) -> Option<usize> {
        let n = self.elements;
        match (cable, k) {
            (_, 0) => None,
            (0, k) => Some(k - 1),
            (_, k) => Some(2 * n - 1 - k),
        }
    }

    /// Index in q of the x (`axis` 0) or z (`axis` 1) coordinate of chain node `j`.
    #[inline]
    pub fn node_coordinate(&self, j: usize, axis: usize) -> usize {
        axis * self.chain_nodes() + j
    }

    /// Index in q of the effector's x (its z is at `+ chain_nodes()`).
    pub fn effector_index(&self) -> usize {
        self.elements - 1
    }

    /// Index in q of l_i (cable 0 or 1).
    #[inline]
    pub fn l_index(&self, cable: usize) -> usize {
        2 * self.chain_nodes() + self.border_l[cable]
    }

    /// Index in q of ρ_i; None for the rigid stored cable.
    #[inline]
    pub fn rho_index(&self, cable: usize) -> Option<usize> {
        match self.stored {
            FeStored::Elastic => Some(2 * self.chain_nodes() + 2 * cable + 1),
            FeStored::Rigid => None,
        }
    }

    /// Pulley point A_i [m].
    pub fn pulley(&self, cable: usize) -> Vector2<f64> {
        Vector2::new(cable as f64 * self.anchor_distance, 0.0)
    }

    /// Position and velocity of node k (0…N) of `cable` in state `y` = (q, q') [m, m/s]; node 0 is
    /// the fixed pulley point.
    #[inline]
    pub fn node(&self, y: &[f64], cable: usize, k: usize) -> (Vector2<f64>, Vector2<f64>) {
        match self.chain_index(cable, k) {
            None => (self.pulley(cable), Vector2::zeros()),
            Some(j) => {
                let (np, nn) = (self.positions_len(), self.chain_nodes());
                (
                    Vector2::new(y[j], y[nn + j]),
                    Vector2::new(y[np + j], y[np + nn + j]),
                )
            }
        }
    }

    /// What the free elements of `cable`'s span share, computed once per span.
    #[inline]
    fn span_of(&self, y: &[f64], cable: usize) -> Span {
        let n = self.elements as f64;
        let li = self.l_index(cable);
        let h = y[li] / n;
        Span {
            l_rate: y[self.positions_len() + li],
            h,
            inv_h: 1.0 / h,
            h_prime: 1.0 / n,
        }
    }

    /// State of element e (1…N) of `cable`.
    #[inline]
    fn free_element(&self, y: &[f64], cable: usize, e: usize) -> ElementState {
        self.element_of(&self.span_of(y, cable), y, cable, e)
    }

    /// State of element e (1…N) of `cable`, whose span is `span` (from [`Self::span_of`]).
    #[inline]
    fn element_of(&self, span: &Span, y: &[f64], cable: usize, e: usize) -> ElementState {
        span.element(self.node(y, cable, e - 1), self.node(y, cable, e))
    }

    /// The N elements of `cable`'s span in order e = 1 (at the pulley) … N (at the effector),
    /// walking the nodes once: the same states as [`Self::free_element`], bit for bit, without
    /// re-deriving each node's index and the span's h per element.
    #[inline]
    fn span<'a>(&'a self, y: &'a [f64], cable: usize) -> impl Iterator<Item = ElementState> + 'a {
        let span = self.span_of(y, cable);
        let mut a = self.node(y, cable, 0);
        (1..=self.elements).map(move |e| {
            let b = self.node(y, cable, e);
            let s = span.element(a, b);
            a = b;
            s
        })
    }

    /// State of the elastic stored element of `cable` (R = A + ρ e_out → A), if it exists.
    #[inline]
    fn stored_element(&self, y: &[f64], cable: usize) -> Option<ElementState> {
        let ri = self.rho_index(cable)?;
        let np = self.positions_len();
        let li = self.l_index(cable);
        let e_out = Vector2::new(TOWARD_REEL[cable], 0.0);
        let a = self.pulley(cable);
        Some(ElementState::new(
            (a + e_out * y[ri], e_out * y[np + ri]),
            (a, Vector2::zeros()),
            y[np + li],
            self.modelled_length - y[li],
            -1.0,
        ))
    }

    /// Chord j of the chain from the last assembly's pass.
    #[inline]
    fn chord_at(&self, j: usize) -> Chord {
        Chord {
            length: self.chord_length[j],
            inv_length: self.chord_inv_length[j],
        }
    }

    /// Strain and tension (ε, N_e) of element e (1…N) of `cable` [–, N].
    pub fn element_tension(&self, y: &[f64], cable: usize, e: usize) -> (f64, f64) {
        self.free_element(y, cable, e)
            .chord_tension(self.material.ea)
    }

    /// Strain and tension of the stored element of `cable` (None for the rigid stored cable).
    pub fn stored_tension(&self, y: &[f64], cable: usize) -> Option<(f64, f64)> {
        Some(
            self.stored_element(y, cable)?
                .chord_tension(self.material.ea),
        )
    }

    /// Unstrained free length l_i [m].
    pub fn free_length(&self, y: &[f64], cable: usize) -> f64 {
        y[self.l_index(cable)]
    }

    /// Stored length: ρ_i (distance pulley → reel end) for the elastic stored element, the
    /// unstrained L0 − l_i for the rigid one [m].
    pub fn stored_length(&self, y: &[f64], cable: usize) -> f64 {
        match self.rho_index(cable) {
            Some(r) => y[r],
            None => self.modelled_length - y[self.l_index(cable)],
        }
    }

    /// Total cable mass 2 μ L0 [kg] (constant: the span and stored parts exchange material).
    pub fn cable_mass(&self) -> f64 {
        2.0 * self.material.mu * self.modelled_length
    }
}

impl CableModel<2> for Fe {
    fn name(&self) -> &'static str {
        "fe"
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
        let np = self.positions_len();
        let (dq, dv) = rate.split_at_mut(np);
        dq.copy_from_slice(&y[np..]);
        if !self.accelerations(y, [tensions[0], tensions[1]], dv) {
            // M is not positive definite (an element or the stored cable collapsed): no motion is
            // defined; NaN makes the integrator stop with a non-finite state.
            dv.fill(f64::NAN);
        }
    }

    fn effector(&self, y: &[f64]) -> Effector<2> {
        let (position, velocity) = self.node(y, 0, self.elements);
        Effector { position, velocity }
    }

    /// dE/dt = Σ T_i ρ_i' (FE.7): the reel end moving away from the pulley takes cable in. Rigid
    /// stored cable: −l_i'.
    fn reel_speeds(&self, y: &[f64]) -> PerCable {
        let np = self.positions_len();
        PerCable::from_fn(2, |c| match self.rho_index(c) {
            Some(r) => y[np + r],
            None => -y[np + self.l_index(c)],
        })
    }

    fn energy(&self, y: &[f64]) -> Energy {
        let mat = &self.material;
        let np = self.positions_len();
        let mut e = Energy::default();
        for cable in 0..2 {
            for (s, coefficients) in self.span(y, cable).zip(&self.coefficients) {
                let (k, u, g) = element::energies(mat, coefficients, &s);
                e.kinetic += k;
                e.elastic += u;
                e.gravity += g;
            }
            match self.stored_element(y, cable) {
                Some(s) => {
                    let (k, u, _) = element::energies(mat, &self.stored_coefficients, &s);
                    e.kinetic += k;
                    e.elastic += u;
                }
                None => {
                    let li = self.l_index(cable);
                    let ld = y[np + li];
                    e.kinetic += 0.5 * mat.mu * (self.modelled_length - y[li]) * ld * ld;
                }
            }
        }
        let (p, v) = self.node(y, 0, self.elements);
        e.kinetic += 0.5 * self.effector_mass * v.norm_squared();
        e.gravity += self.effector_mass * mat.gravity * p.y;
        e
    }

    /// Power of the Kelvin–Voigt damping (FE.5.7), Σ over taut elements (stored one included) of
    /// h N_d ε' ≥ 0, so that dE/dt = Σ T_i ρ_i' − D and the runner's `e_residual` audits the
    /// damped model too.
    fn dissipation(&self, y: &[f64]) -> f64 {
        if self.axial_damping == 0.0 {
            return 0.0;
        }
        let c = self.axial_damping;
        let mut d = 0.0;
        for cable in 0..2 {
            for s in self.span(y, cable) {
                d += element::dissipation(&self.material, &s, c);
            }
            if let Some(s) = self.stored_element(y, cable) {
                d += element::dissipation(&self.material, &s, c);
            }
        }
        d
    }

    fn channel_names(&self) -> Vec<String> {
        cdpr_core::channel::Channel::cable_channel_names(2)
    }

    fn channel_units(&self) -> Vec<&'static str> {
        cdpr_core::channel::Channel::cable_channel_units(2, "m")
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

    /// Element tensions N_N (at the effector) and N_1 (at the pulley) [N], free unstrained lengths
    /// l_i [m], stored lengths ρ_i [m].
    fn channels(&self, y: &[f64], _tensions: &[f64], out: &mut [f64]) {
        let n = self.elements;
        // Elements N (at the effector) and 1 (at the pulley) of each cable, from one span each
        // (this runs per output sample); the same states as `element_tension`'s, bit for bit.
        let [(effector_1, pulley_1), (effector_2, pulley_2)] = [0, 1].map(|cable| {
            let span = self.span_of(y, cable);
            let tension = |e: usize| {
                self.element_of(&span, y, cable, e)
                    .chord_tension(self.material.ea)
                    .1
            };
            (tension(n), tension(1))
        });
        out.copy_from_slice(&[
            effector_1,
            effector_2,
            pulley_1,
            pulley_2,
            self.free_length(y, 0),
            self.free_length(y, 1),
            self.stored_length(y, 0),
            self.stored_length(y, 1),
        ]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The span walker must hand the kernels exactly the states `free_element` gives the
    /// channels (so a reported tension is bit for bit the one in the forces), for both cables'
    /// numbering directions and both stored variants.
    #[test]
    fn span_walk_matches_free_elements_bit_for_bit() {
        for (elements, stored) in [
            (1, FeStored::Elastic),
            (4, FeStored::Rigid),
            (10, FeStored::Elastic),
        ] {
            let params = Params {
                elements,
                stored,
                ..Params::default()
            };
            let fe = Fe::new(&Scenario::paper(), params).unwrap();
            let y: Vec<f64> = (0..2 * fe.positions_len())
                .map(|i| 0.3 + 0.1 * (i as f64 * 0.77).sin())
                .collect();
            for cable in 0..2 {
                let walked: Vec<_> = fe.span(&y, cable).collect();
                assert_eq!(walked.len(), elements);
                for (e, state) in (1..).zip(&walked) {
                    assert_eq!(
                        *state,
                        fe.free_element(&y, cable, e),
                        "cable {cable}, e {e}"
                    );
                }
            }
            // The channels' end tensions, computed per span, are `element_tension`'s.
            let mut out = vec![0.0; fe.channel_names().len()];
            fe.channels(&y, &[100.0, 100.0], &mut out);
            let n = elements;
            let expected =
                [(0, n), (1, n), (0, 1), (1, 1)].map(|(c, e)| fe.element_tension(&y, c, e).1);
            assert_eq!(out[..4], expected);
        }
    }
}
