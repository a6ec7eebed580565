//! The variable-length FE cable in space (MODELS.md §5 along each cable's own path, §11): m
//! arms of N elements each from the pulleys A_i to the effector P, every cable's stored part one
//! elastic element from its reel end R_i = A_i + ρ_i r_i (r_i the reel direction) to A_i. The
//! same element kernel as the plane ([`crate::element`], in three dimensions), the same
//! Lagrangian, so dE/dt = Σ T_i ρ_i' − D exactly (FE.7) and the runner audits it.
//!
//! Generalised coordinates: per cable i its free nodes k = 1 … N − 1 (x, y, z each, cable-major),
//! then P, then per cable (l_i, ρ_i); n = 3m(N − 1) + 3 + 2m, the state (q, q'). M q'' = F is
//! solved on the star of arms in O(N m) ([`star`]); the implicit path's form is [`implicit`];
//! reels driven by length prescribe l_i ([`prescribed`]). The stored cable is elastic (FE.1.3's
//! reference variant); the rigid variant is planar only.

mod block_lanes;
mod blocks;
mod implicit;
mod lanes;
mod prescribed;
mod star;
mod statics;

use crate::element::{self, Chord, ElementState, MassCoefficients, Material};
use crate::params::{FeMass, FeStored, Params};
use cdpr_core::model::{CableModel, Energy, Equilibrium, ModelError, RestRule};
use cdpr_core::robot::{Effector, PerCable, Robot};
use cdpr_core::scenario::Scenario;
use nalgebra::Vector3;
use star::StarSystem;

/// The spatial robot with variable-length FE cables.
#[derive(Debug, Clone, PartialEq)]
pub struct FeSpatial {
    robot: Robot<3>,
    /// Elements per free span N.
    pub elements: usize,
    /// Total unstrained length per cable L0 (stored + free) [m].
    pub modelled_length: f64,
    /// EA [N], μ [kg/m], g [m/s²].
    pub material: Material,
    /// Kelvin–Voigt axial damping C [N s] (FE.5.7).
    pub axial_damping: f64,
    /// Unit reel direction r_i per cable.
    reels: Vec<Vector3<f64>>,
    /// Mass coefficients of the free elements e = 1 … N, and of the stored element.
    coefficients: Vec<MassCoefficients>,
    stored_coefficients: MassCoefficients,
    system: StarSystem,
    /// The implicit residual's span element rows ([`lanes`](self::lanes)).
    rows: lanes::StarRows,
    /// Accelerations of the free nodes (cable-major) and of (l_i, ρ_i), per solve.
    node_accelerations: Vec<Vector3<f64>>,
    border_accelerations: Vec<[f64; 2]>,
    /// The coloured differences of the tests' reference matrix (built at its first call).
    differences: Option<cdpr_numerics::differences::ColouredDifferences>,
    /// Where the element blocks' entries go in the iteration pattern (built at the first
    /// element-by-element matrix, [`blocks`]).
    block_slots: Vec<usize>,
    /// The free elements' blocks in lanes ([`block_lanes`]; built at the first matrix).
    block_lanes: block_lanes::BlockLanes,
    /// Where Du's form rewrites them, and its scratch ([`blocks::DrivenSlots`]).
    driven_slots: blocks::DrivenSlots,
    /// Reels driven by length (the scenario's `length` controller): the free lengths l_i are
    /// prescribed (MODELS.md FE.5.6, Du's form), the stored cable is on the reel and not
    /// modelled; `drive` holds the commanded (l̇0_i, l̈0_i) from the last
    /// [`CableModel::drive_reels`].
    length_driven: bool,
    drive: Option<(PerCable, PerCable)>,
    /// The prescribing forces Q_l,i of the last solve [N] and the state it was at.
    prescribing: Vec<f64>,
    prescribing_state: Vec<f64>,
}

impl FeSpatial {
    /// The scenario's spatial robot (`[robot] anchors`, `reel_directions`) with FE cables of
    /// `params`: elastic stored cables only.
    pub fn from_scenario(scenario: &Scenario, params: Params) -> Result<Self, ModelError> {
        let robot = scenario.spatial_robot().ok_or(ModelError::Parameter {
            name: "robot.anchors",
            value: f64::NAN,
            allowed: "the anchors of a spatial robot".into(),
        })?;
        let n = params.elements;
        if n < 1 {
            return Err(ModelError::Parameter {
                name: "model.elements",
                value: n as f64,
                allowed: "≥ 1 for the FE model".into(),
            });
        }
        if params.stored != FeStored::Elastic {
            return Err(ModelError::Parameter {
                name: "model.fe_stored",
                value: f64::NAN,
                allowed: "\"elastic\" for FE cables in space (the rigid stored cable is planar \
                          only)"
                    .into(),
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
        let reels = cdpr_core::robot::reels::scenario_reel_directions(scenario, &robot)?;
        let mut model = Self::new(
            robot,
            reels,
            params.mass,
            n,
            cable.modelled_length,
            Material {
                ea: cable.axial_stiffness(),
                mu: cable.mass_per_length(),
                gravity: scenario.robot.gravity,
            },
            cable.axial_damping,
        );
        model.length_driven =
            scenario.controller.kind == cdpr_core::scenario::ControllerKind::Length;
        Ok(model)
    }

    fn new(
        robot: Robot<3>,
        reels: Vec<Vector3<f64>>,
        mass: FeMass,
        n: usize,
        modelled_length: f64,
        material: Material,
        axial_damping: f64,
    ) -> Self {
        let m = robot.cables();
        let w = |k: usize| 1.0 - k as f64 / n as f64;
        let coefficients: Vec<MassCoefficients> = (1..=n)
            .map(|e| MassCoefficients::new(mass, w(e - 1), w(e)))
            .collect();
        let stored = MassCoefficients::new(mass, 0.0, 1.0);
        Self {
            robot,
            elements: n,
            modelled_length,
            material,
            axial_damping,
            reels,
            rows: lanes::StarRows::new(m, &coefficients, &stored),
            coefficients,
            stored_coefficients: stored,
            system: StarSystem::new(m, n - 1),
            node_accelerations: vec![Vector3::zeros(); m * (n - 1)],
            border_accelerations: vec![[0.0; 2]; m],
            differences: None,
            block_slots: Vec::new(),
            block_lanes: block_lanes::BlockLanes::default(),
            driven_slots: blocks::DrivenSlots::default(),
            length_driven: false,
            drive: None,
            prescribing: vec![0.0; m],
            prescribing_state: Vec::new(),
        }
    }

    /// Number of generalised coordinates n = 3m(N − 1) + 3 + 2m.
    pub fn positions_len(&self) -> usize {
        3 * self.robot.cables() * (self.elements - 1) + 3 + 2 * self.robot.cables()
    }

    /// Index in q of coordinate `axis` of free node k (1 … N − 1) of `cable`.
    #[inline]
    pub fn node_index(&self, cable: usize, k: usize, axis: usize) -> usize {
        3 * (cable * (self.elements - 1) + k - 1) + axis
    }

    /// Index in q of the effector's coordinate `axis`.
    #[inline]
    pub fn effector_index(&self, axis: usize) -> usize {
        3 * self.robot.cables() * (self.elements - 1) + axis
    }

    /// Index in q of l_i; ρ_i follows it.
    #[inline]
    pub fn l_index(&self, cable: usize) -> usize {
        self.effector_index(3) + 2 * cable
    }

    /// Pulley point A_i [m].
    pub fn pulley(&self, cable: usize) -> Vector3<f64> {
        self.robot.anchor(cable)
    }

    /// The unit reel direction r_i of `cable`.
    pub fn reel(&self, cable: usize) -> Vector3<f64> {
        self.reels[cable]
    }

    /// Position and velocity of node k (0 … N) of `cable` in `y` [m, m/s]: the pulley at k = 0,
    /// the effector at k = N.
    #[inline]
    pub fn node(&self, y: &[f64], cable: usize, k: usize) -> (Vector3<f64>, Vector3<f64>) {
        let np = self.positions_len();
        let at = |i: usize| {
            (
                Vector3::new(y[i], y[i + 1], y[i + 2]),
                Vector3::new(y[np + i], y[np + i + 1], y[np + i + 2]),
            )
        };
        if k == 0 {
            (self.pulley(cable), Vector3::zeros())
        } else if k == self.elements {
            at(self.effector_index(0))
        } else {
            at(self.node_index(cable, k, 0))
        }
    }

    /// Free unstrained length l_i [m] and stored length ρ_i [m].
    pub fn free_length(&self, y: &[f64], cable: usize) -> f64 {
        y[self.l_index(cable)]
    }

    pub fn stored_length(&self, y: &[f64], cable: usize) -> f64 {
        y[self.l_index(cable) + 1]
    }

    /// Element e (1 … N) of `cable`'s span.
    fn free_element(&self, y: &[f64], cable: usize, e: usize) -> ElementState<3> {
        let n = self.elements as f64;
        let li = self.l_index(cable);
        let l_rate = y[self.positions_len() + li];
        ElementState::new(
            self.node(y, cable, e - 1),
            self.node(y, cable, e),
            l_rate,
            y[li] / n,
            1.0 / n,
        )
    }

    /// The free elements e = 1 … N of `cable`'s span in order, each node read once and carried
    /// to the next element ([`Self::free_element`]'s states).
    fn free_elements<'a>(
        &'a self,
        y: &'a [f64],
        cable: usize,
    ) -> impl Iterator<Item = ElementState<3>> + 'a {
        let n = self.elements as f64;
        let li = self.l_index(cable);
        let (h, l_rate) = (y[li] / n, y[self.positions_len() + li]);
        let mut a = self.node(y, cable, 0);
        (1..=self.elements).map(move |e| {
            let b = self.node(y, cable, e);
            let s = ElementState::new(a, b, l_rate, h, 1.0 / n);
            a = b;
            s
        })
    }

    /// The stored element of `cable`: R = A + ρ r → A, unstrained L0 − l, h' = −1.
    fn stored_element(&self, y: &[f64], cable: usize) -> ElementState<3> {
        let (li, np) = (self.l_index(cable), self.positions_len());
        let (a, r) = (self.pulley(cable), self.reels[cable]);
        ElementState::new(
            (a + r * y[li + 1], r * y[np + li + 1]),
            (a, Vector3::zeros()),
            y[np + li],
            self.modelled_length - y[li],
            -1.0,
        )
    }

    /// Assembles M(q) and F(q, q', T) (FE.5.3) on the star; with the reels driven by length,
    /// the l_i rows prescribe l_i'' ([`Self::prescribe_lengths`]).
    fn assemble(&mut self, y: &[f64], tensions: &[f64]) {
        let mut sys = std::mem::take(&mut self.system);
        self.assemble_into(&mut sys, y, tensions, !self.length_driven);
        if self.length_driven {
            self.prescribe_lengths(&mut sys, y);
        }
        self.system = sys;
    }

    /// M(q) and F(q, q', T) (FE.5.3) into `sys`: the spans, the stored elements if `stored`
    /// (not when the reels are driven by length: the stored cable is then on the reel) and the
    /// effector.
    fn assemble_into(&self, sys: &mut StarSystem, y: &[f64], tensions: &[f64], stored: bool) {
        sys.clear();
        let (n, nn) = (self.elements, self.elements - 1);
        let mat = self.material;
        for (cable, &tension) in tensions.iter().enumerate().take(self.robot.cables()) {
            let o = cable * nn;
            let border = &mut sys.border[cable];
            for (e, s) in (1..=n).zip(self.free_elements(y, cable)) {
                let k = &self.coefficients[e - 1];
                let t = element::terms_at_chord(&mat, k, &s, self.axial_damping, Chord::of(&s));
                if e > 1 {
                    let a = o + e - 2;
                    sys.diag[a] += t.m_diag;
                    sys.force[a] += t.fa;
                    sys.l_column[a] += t.m_al;
                }
                if e < n {
                    let b = o + e - 1;
                    sys.diag[b] += t.m_diag;
                    sys.force[b] += t.fb;
                    sys.l_column[b] += t.m_bl;
                    if e > 1 {
                        sys.off[b - 1] += t.m_off;
                    }
                } else {
                    sys.effector_mass += t.m_diag;
                    sys.effector_force += t.fb;
                    sys.effector_l[cable] += t.m_bl;
                    if e > 1 {
                        sys.node_effector[cable] += t.m_off;
                    }
                }
                border[0] += t.m_ll;
                border[3] += t.fl;
            }
            if !stored {
                continue;
            }
            // Row ρ: the kernel's R-node terms along r (R = A + ρ r), plus the commanded tension
            // pulling R away from the pulley (FE.5.3).
            let s = self.stored_element(y, cable);
            let t = element::terms_damped(&mat, &self.stored_coefficients, &s, self.axial_damping);
            let r = self.reels[cable];
            border[0] += t.m_ll;
            border[1] += t.m_al.dot(&r);
            border[2] += t.m_diag;
            border[3] += t.fl;
            border[4] += t.fa.dot(&r) + tension;
        }
        sys.effector_mass += self.robot.effector_mass;
        sys.effector_force.z -= self.robot.effector_mass * mat.gravity;
    }

    /// q'' = M⁻¹F for state `y` and `tensions` into `qdd` (length n) [m/s²]; false if M is not
    /// positive definite (the state left the model's domain, FE.9.4).
    pub fn accelerations(&mut self, y: &[f64], tensions: &[f64], qdd: &mut [f64]) -> bool {
        self.assemble(y, tensions);
        let mut effector = Vector3::zeros();
        if !self.system.solve(
            &mut self.node_accelerations,
            &mut effector,
            &mut self.border_accelerations,
        ) {
            return false;
        }
        if self.length_driven {
            self.system.held_l_residuals(
                &self.node_accelerations,
                &effector,
                &self.border_accelerations,
                &mut self.prescribing,
            );
            self.prescribing_state.clear();
            self.prescribing_state.extend_from_slice(y);
        }
        let nodes = self.node_accelerations.len();
        for (j, a) in self.node_accelerations.iter().enumerate() {
            qdd[3 * j..3 * j + 3].copy_from_slice(a.as_slice());
        }
        qdd[3 * nodes..3 * nodes + 3].copy_from_slice(effector.as_slice());
        for (i, b) in self.border_accelerations.iter().enumerate() {
            qdd[3 * nodes + 3 + 2 * i..3 * nodes + 5 + 2 * i].copy_from_slice(b);
        }
        true
    }

    /// The forces F(q, 0, T) at rest [N], in q's order (the statics' residual).
    /// At rest the reels hold the cables' tensions whatever drives them later, so the stored
    /// elements take part and no length is prescribed.
    fn rest_forces(&mut self, y: &[f64], tensions: &[f64], out: &mut [f64]) {
        let mut sys = std::mem::take(&mut self.system);
        self.assemble_into(&mut sys, y, tensions, true);
        self.system = sys;
        let s = &self.system;
        for (j, f) in s.force.iter().enumerate() {
            out[3 * j..3 * j + 3].copy_from_slice(f.as_slice());
        }
        let p = 3 * s.force.len();
        out[p..p + 3].copy_from_slice(s.effector_force.as_slice());
        for (i, b) in s.border.iter().enumerate() {
            out[p + 3 + 2 * i] = b[3];
            out[p + 4 + 2 * i] = b[4];
        }
    }

    /// Element e's tension N [N] (1: at the pulley, N: at the effector).
    pub fn element_tension(&self, y: &[f64], cable: usize, e: usize) -> f64 {
        self.free_element(y, cable, e)
            .chord_tension(self.material.ea)
            .1
    }
}

impl CableModel<3> for FeSpatial {
    fn name(&self) -> &'static str {
        "fe"
    }

    fn robot(&self) -> &Robot<3> {
        &self.robot
    }

    fn state_len(&self) -> usize {
        2 * self.positions_len()
    }

    fn equilibrium(&mut self, rule: &dyn RestRule<3>) -> Result<Equilibrium, ModelError> {
        statics::equilibrium(self, rule)
    }

    fn rhs(&mut self, _t: f64, y: &[f64], tensions: &[f64], rate: &mut [f64]) {
        let np = self.positions_len();
        let (dq, dv) = rate.split_at_mut(np);
        dq.copy_from_slice(&y[np..]);
        if !self.accelerations(y, tensions, dv) {
            // M is not positive definite: no motion is defined; NaN stops the integrator.
            dv.fill(f64::NAN);
        }
    }

    fn effector(&self, y: &[f64]) -> Effector<3> {
        let (position, velocity) = self.node(y, 0, self.elements);
        Effector { position, velocity }
    }

    /// dE/dt = Σ T_i ρ_i' (FE.7): the reel end moving away from the pulley takes cable in;
    /// driven by length, the line the reel takes in, −l_i'.
    fn reel_speeds(&self, y: &[f64]) -> PerCable {
        let np = self.positions_len();
        PerCable::from_fn(self.robot.cables(), |c| {
            if self.length_driven {
                -y[np + self.l_index(c)]
            } else {
                y[np + self.l_index(c) + 1]
            }
        })
    }

    /// The free lengths can be prescribed (Du's form, MODELS.md FE.5.6).
    fn reels_follow_lengths(&self) -> bool {
        true
    }

    fn drive_reels(&mut self, rates: &PerCable, accelerations: &PerCable) {
        self.drive = Some((*rates, *accelerations));
    }

    /// Σ T_i ρ_i' under tension; driven by length, Σ Q_l,i l_i' with Q_l,i the force that
    /// imposes l_i (FE.7's identity for prescribed lengths).
    fn reel_power(&self, y: &[f64], tensions: &PerCable, reel_speeds: &PerCable) -> f64 {
        if !self.length_driven {
            return tensions.dot(reel_speeds);
        }
        // The closed loop asks right after the right-hand side at the same state, whose
        // solve kept the forces; anywhere else they are solved afresh.
        let np = self.positions_len();
        let power = |q: &[f64]| -> f64 {
            q.iter()
                .enumerate()
                .map(|(c, q)| q * y[np + self.l_index(c)])
                .sum()
        };
        if self.prescribing_state.as_slice() == y {
            power(&self.prescribing)
        } else {
            power(&self.prescribing_forces(y))
        }
    }

    fn energy(&self, y: &[f64]) -> Energy {
        let mat = &self.material;
        let mut e = Energy::default();
        for cable in 0..self.robot.cables() {
            for (s, k) in self.free_elements(y, cable).zip(&self.coefficients) {
                let (k, u, g) = element::energies(mat, k, &s);
                e.kinetic += k;
                e.elastic += u;
                e.gravity += g;
            }
            if self.length_driven {
                continue; // the stored cable is on the reel
            }
            let s = self.stored_element(y, cable);
            let (k, u, g) = element::energies(mat, &self.stored_coefficients, &s);
            e.kinetic += k;
            e.elastic += u;
            e.gravity += g;
        }
        let (p, v) = self.node(y, 0, self.elements);
        e.kinetic += 0.5 * self.robot.effector_mass * v.norm_squared();
        e.gravity += self.robot.effector_mass * mat.gravity * p.z;
        e
    }

    /// Power of the Kelvin–Voigt damping (FE.5.7) over every taut element, stored ones included.
    fn dissipation(&self, y: &[f64]) -> f64 {
        if self.axial_damping == 0.0 {
            return 0.0;
        }
        let mut d = 0.0;
        for cable in 0..self.robot.cables() {
            for s in self.free_elements(y, cable) {
                d += element::dissipation(&self.material, &s, self.axial_damping);
            }
            if !self.length_driven {
                let s = self.stored_element(y, cable);
                d += element::dissipation(&self.material, &s, self.axial_damping);
            }
        }
        d
    }

    fn second_order(&self) -> Option<&dyn cdpr_core::second_order::SecondOrderForm> {
        Some(self)
    }

    fn second_order_mut(&mut self) -> Option<&mut dyn cdpr_core::second_order::SecondOrderForm> {
        Some(self)
    }

    /// The pulley, the free nodes and the effector.
    fn cable_paths(&self, y: &[f64]) -> Vec<Vec<Vector3<f64>>> {
        (0..self.robot.cables())
            .map(|c| (0..=self.elements).map(|k| self.node(y, c, k).0).collect())
            .collect()
    }

    fn channel_names(&self) -> Vec<String> {
        cdpr_core::channel::Channel::cable_channel_names(self.robot.cables())
    }

    fn channel_units(&self) -> Vec<&'static str> {
        cdpr_core::channel::Channel::cable_channel_units(self.robot.cables(), "m")
    }

    /// Element tensions at the effector and at the pulley [N], l_i and ρ_i [m], each group
    /// cable 1 first.
    fn channels(&self, y: &[f64], _tensions: &[f64], out: &mut [f64]) {
        let m = self.robot.cables();
        for c in 0..m {
            out[c] = self.element_tension(y, c, self.elements);
            out[m + c] = self.element_tension(y, c, 1);
            out[2 * m + c] = self.free_length(y, c);
            out[3 * m + c] = self.stored_length(y, c);
        }
    }

    /// The effector, each free node with its chord's tangent, l_i and ρ_i moving material —
    /// held (frozen) when the reels drive the lengths or are locked.
    fn modal_layout(&self, y: &[f64]) -> cdpr_core::modal_layout::ModalLayout {
        use cdpr_core::modal_layout::{Dof, ModalLayout};
        let mut dofs = vec![Dof::Effector {
            coordinates: (0..3).map(|a| self.effector_index(a)).collect(),
            mass: self.robot.effector_mass,
        }];
        let mu = self.material.mu;
        let mut frozen = Vec::new();
        for c in 0..self.robot.cables() {
            let l = self.free_length(y, c);
            let h = l / self.elements as f64;
            for k in 1..self.elements {
                let (a, _) = self.node(y, c, k - 1);
                let (b, _) = self.node(y, c, k + 1);
                let t = (b - a).normalize();
                dofs.push(Dof::Node {
                    cable: c,
                    coordinates: (0..3).map(|ax| self.node_index(c, k, ax)).collect(),
                    tangent: t.as_slice().to_vec(),
                    mass: mu * h,
                });
            }
            let li = self.l_index(c);
            if self.length_driven {
                frozen.extend([li, li + 1]);
                continue;
            }
            dofs.push(Dof::Axial {
                cable: c,
                index: li,
                mass: mu * l,
            });
            dofs.push(Dof::Axial {
                cable: c,
                index: li + 1,
                mass: mu * (self.modelled_length - l),
            });
        }
        ModalLayout { dofs, frozen }
    }
}
