//! `lqr`: linear-quadratic state feedback with integral action on x and z, designed on the
//! linearisation of the elastic loop (rigid massless cables) at the move's end point (x2, z0):
//!
//! ```text
//! M δp̈ = W* δT + G* δp,   σ̇ = δp                     (δ: deviation from (x2, z0) at rest)
//! ξ = (δp, δṗ, σ),  ξ̇ = A ξ + B δT,  A = [0 I 0; G*/M 0 0; I 0 0],  B = [0; W*/M; 0]
//! min ∫ ξᵀ Q ξ + δTᵀ R δT dt  ⇒  δT = −K ξ,  K = R⁻¹ Bᵀ X  (X: the CARE's stabilising solution)
//! ```
//!
//! W* and G* = −Σ T_i (I − u_i u_iᵀ)/l_i are the structure matrix and geometric stiffness at the
//! design point, T* = W*⁻¹ (0, M g). In the loop the deviation is taken from the reference, and
//! the tensions that hold the reference on rigid cables are fed forward:
//! T = W(p_ref)⁻¹ M (a_ref − g) + K (e, ė, ∫e),  e = p_ref − p. Q = diag(q_position I,
//! q_velocity I, q_integral I), R = r I. The velocity error is measured through
//! [`VelocityFilter`] (the design ignores the filter: its corner lies far above the loop's
//! poles). Anti-windup: the integrals hold while the command is clamped.

use super::error_states::{self, ErrorStates};
use super::velocity_filter::VelocityFilter;
use super::{
    ControlError, Controller, Measures, Output, Plant, Reference, Rest, StepStart,
    geometric_stiffness, structure_matrix,
};
use crate::Vector2;
use crate::model::Effector;
use crate::scenario::{ControllerKind, Scenario};
use nalgebra::{Matrix2, SMatrix};

/// Number of design states ξ = (δx, δz, δẋ, δż, σx, σz).
pub const DESIGN_STATES: usize = 6;

/// The LQR design and controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Lqr {
    /// K (2 × 6) on ξ = (e, ė, ∫e) [N/m, N s/m, N/(m s)].
    pub gain: SMatrix<f64, 2, DESIGN_STATES>,
    /// The design point (x2, z) [m].
    pub design_point: Vector2<f64>,
    /// max |residual| of the CARE at the returned X.
    pub care_residual: f64,
    pub plant: Plant,
    /// The integral and filtered-velocity error states.
    pub errors: ErrorStates,
    weights: [f64; 4],
}

impl Lqr {
    /// Not yet designed (K = 0): the design point's height is the start equilibrium's z0,
    /// which the closed loop passes to [`Controller::hold_height`] before any run.
    pub fn new(scenario: &Scenario, plant: Plant) -> Self {
        let c = &scenario.controller;
        Self {
            gain: SMatrix::zeros(),
            design_point: Vector2::new(scenario.trajectory.x2, f64::NAN),
            care_residual: f64::NAN,
            plant,
            errors: ErrorStates {
                filter: VelocityFilter {
                    omega: c.velocity_filter,
                },
            },
            weights: [c.q_position, c.q_velocity, c.q_integral, c.r],
        }
    }

    /// Designs at (x2, z0) [m].
    pub fn designed_at(mut self, z0: f64) -> Result<Self, ControlError> {
        self.hold_height(z0)?;
        Ok(self)
    }

    /// The linearised plant (A, B) at the design point, row-major.
    pub fn linearisation(&self) -> ([f64; 36], [f64; 12]) {
        let p = &self.plant;
        let pd = self.design_point;
        let w = structure_matrix(pd, p.anchor_distance);
        let hold = p.tensions_for_acceleration(pd, Vector2::zeros());
        let g: Matrix2<f64> = geometric_stiffness(pd, p.anchor_distance, hold) / p.effector_mass;
        let mut a = [0.0; 36];
        let mut b = [0.0; 12];
        for i in 0..2 {
            a[i * 6 + 2 + i] = 1.0; // δṗ = δv
            a[(4 + i) * 6 + i] = 1.0; // σ̇ = δp
            for j in 0..2 {
                a[(2 + i) * 6 + j] = g[(i, j)];
                b[(2 + i) * 2 + j] = w[(i, j)] / p.effector_mass;
            }
        }
        (a, b)
    }

    /// Solves the CARE at the design point.
    pub fn design(&mut self) -> Result<(), ControlError> {
        let (a, b) = self.linearisation();
        let [qp, qv, qi, r] = self.weights;
        let mut q = [0.0; 36];
        for (k, w) in [qp, qp, qv, qv, qi, qi].into_iter().enumerate() {
            q[k * 6 + k] = w;
        }
        let r = [r, 0.0, 0.0, r];
        let (gain, residual, _) =
            cdpr_numerics::riccati::lqr_gain(6, 2, &a, &b, &q, &r).map_err(|e| {
                ControlError::Design {
                    x: self.design_point.x,
                    z: self.design_point.y,
                    why: e.to_string(),
                }
            })?;
        self.gain = SMatrix::from_row_slice(&gain);
        self.care_residual = residual;
        Ok(())
    }

    fn xi(&self, reference: &Reference, effector: &Effector, states: &[f64]) -> SMatrix<f64, 6, 1> {
        let e = reference.position - effector.position;
        let de = self.errors.velocity_error(reference, effector, states);
        SMatrix::<f64, 6, 1>::from([e.x, e.y, de.x, de.y, states[0], states[1]])
    }
}

impl Controller for Lqr {
    fn kind(&self) -> ControllerKind {
        ControllerKind::Lqr
    }
    fn state_len(&self) -> usize {
        error_states::STATES
    }
    fn uses_reference_derivatives(&self) -> bool {
        true
    }
    fn measures(&self) -> Measures {
        Measures {
            z: true,
            velocity: true,
        }
    }
    fn output(&self, reference: &Reference, effector: &Effector, states: &[f64]) -> Output {
        let ff = self
            .plant
            .tensions_for_acceleration(reference.position, reference.acceleration);
        let dt = self.gain * self.xi(reference, effector, states);
        let tensions = [ff[0] + dt[0], ff[1] + dt[1]];
        let w = structure_matrix(effector.position, self.plant.anchor_distance);
        Output {
            force: (w * Vector2::new(tensions[0], tensions[1])).x,
            tensions,
        }
    }
    fn state_rate(
        &self,
        reference: &Reference,
        effector: &Effector,
        states: &[f64],
        saturated: bool,
        rate: &mut [f64],
    ) {
        self.errors
            .rate(reference, effector, states, saturated, rate);
    }
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart,
        reference: &Reference,
        effector: &Effector,
        out: &mut [f64],
    ) {
        self.errors
            .trapezoidal_step(h, start, reference, effector, out);
    }
    fn rest_states(&self, reference: &Reference, _: &Effector, rest: &Rest, out: &mut [f64]) {
        // K_σ σ = T_rest − T_ff at zero error.
        let ff = self
            .plant
            .tensions_for_acceleration(reference.position, Vector2::zeros());
        let k_sigma = self.gain.fixed_view::<2, 2>(0, 4).into_owned();
        let need = Vector2::new(rest.tensions[0] - ff[0], rest.tensions[1] - ff[1]);
        let sigma = k_sigma
            .try_inverse()
            .map_or(Vector2::zeros(), |inv| inv * need);
        ErrorStates::rest(sigma, out);
    }
    fn hold_height(&mut self, z0: f64) -> Result<(), ControlError> {
        self.design_point.y = z0;
        self.design()
    }
    fn gains(&self) -> Vec<(&'static str, Vec<f64>)> {
        vec![
            ("lqr_gain", self.gain.transpose().iter().copied().collect()),
            (
                "lqr_design_point",
                vec![self.design_point.x, self.design_point.y],
            ),
            ("care_residual", vec![self.care_residual]),
        ]
    }
}
