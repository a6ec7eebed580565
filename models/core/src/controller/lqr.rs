//! `lqr`: linear-quadratic state feedback with integral action on every axis, designed on the
//! linearisation of the elastic loop (rigid massless cables) at the move's end point (x2, z0):
//!
//! ```text
//! M δp̈ = W* δT + G* δp,   σ̇ = δp                     (δ: deviation from (x2, z0) at rest)
//! ξ = (δp, δṗ, σ),  ξ̇ = A ξ + B δT,  A = [0 I 0; G*/M 0 0; I 0 0],  B = [0; W*/M; 0]
//! min ∫ ξᵀ Q ξ + δTᵀ R δT dt  ⇒  δT = −K ξ,  K = R⁻¹ Bᵀ X  (X: the CARE's stabilising solution)
//! ```
//!
//! W* and G* = −Σ T_i (I − u_i u_iᵀ)/l_i are the structure matrix and geometric stiffness at the
//! design point, T* = W*⁻¹ (0, M g) (a redundant robot's: its distribution of M g). In the loop the deviation is taken from the reference, and
//! the tensions that hold the reference on rigid cables are fed forward:
//! T = W(p_ref)⁻¹ M (a_ref − g) + K (e, ė, ∫e),  e = p_ref − p. Q = diag(q_position I,
//! q_velocity I, q_integral I), R = r I. The velocity error is measured through
//! [`VelocityFilter`] (the design ignores the filter: its corner lies far above the loop's
//! poles). Anti-windup: the integrals hold while the command is clamped. The design needs as many
//! cables as axes (W* square); a redundant robot's LQR designs through its tension distribution.

use super::distribution::TensionSolver;
use super::error_states::{self, ErrorStates};
use super::velocity_filter::VelocityFilter;
use super::{ControlError, Controller, Measures, Output, Reference, Rest, StepStart};
use crate::robot::{Effector, Matrix, Robot, Tensions, Vector, vertical};
use crate::scenario::{ControllerKind, Scenario};

/// The LQR design and controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Lqr<const D: usize> {
    /// K (m × 3D, row-major) on ξ = (e, ė, ∫e) [N/m, N s/m, N/(m s)].
    pub gain: Vec<f64>,
    /// The design point (x2, z0) [m].
    pub design_point: Vector<D>,
    /// max |residual| of the CARE at the returned X.
    pub care_residual: f64,
    pub robot: Robot<D>,
    /// The integral and filtered-velocity error states.
    pub errors: ErrorStates,
    /// The feedforward's W T = M (a − g⃗): directly, or by the distribution of a redundant
    /// robot (whose feedback K ξ then lies in the range of Wᵀ, leaving the internal force to
    /// the distribution).
    pub solver: TensionSolver,
    weights: [f64; 4],
}

impl<const D: usize> Lqr<D> {
    /// Number of design states ξ = (δp, δṗ, σ).
    pub const DESIGN_STATES: usize = 3 * D;

    /// Not yet designed (K = 0): the design point's height is the start equilibrium's z0,
    /// which the closed loop passes to [`Controller::hold_height`] before any run.
    pub fn new(scenario: &Scenario, robot: Robot<D>) -> Self {
        let c = &scenario.controller;
        let mut design_point = Vector::zeros();
        design_point[0] = scenario.trajectory.x2;
        design_point[vertical::<D>()] = f64::NAN;
        // A spatial move's end pose (its height set again by `hold_height`).
        if let (Some(end), 3) = (&scenario.trajectory.end, D) {
            design_point = Vector::from_iterator(end.iter().copied());
        }
        Self {
            gain: vec![0.0; robot.cables() * Self::DESIGN_STATES],
            design_point,
            care_residual: f64::NAN,
            robot,
            errors: ErrorStates {
                filter: VelocityFilter {
                    omega: c.velocity_filter,
                },
            },
            solver: TensionSolver::from(c),
            weights: [c.q_position, c.q_velocity, c.q_integral, c.r],
        }
    }

    /// Designs at (x2, z0) [m].
    pub fn designed_at(mut self, z0: f64) -> Result<Self, ControlError> {
        self.hold_height(z0)?;
        Ok(self)
    }

    /// The linearised plant (A, B) at the design point, row-major: A is 3D × 3D, B 3D × m.
    pub fn linearisation(&self) -> (Vec<f64>, Vec<f64>) {
        let r = &self.robot;
        let pd = self.design_point;
        let (n, m) = (Self::DESIGN_STATES, r.cables());
        let w = r.structure_matrix(&pd);
        let hold = self.solver.for_acceleration(r, &pd, &Vector::zeros());
        let g: Matrix<D> = r.geometric_stiffness(&pd, &hold) / r.effector_mass;
        let mut a = vec![0.0; n * n];
        let mut b = vec![0.0; n * m];
        for i in 0..D {
            a[i * n + D + i] = 1.0; // δṗ = δv
            a[(2 * D + i) * n + i] = 1.0; // σ̇ = δp
            for j in 0..D {
                a[(D + i) * n + j] = g[(i, j)];
            }
            for j in 0..m {
                b[(D + i) * m + j] = w.column(j)[i] / r.effector_mass;
            }
        }
        (a, b)
    }

    /// Solves the CARE at the design point.
    pub fn design(&mut self) -> Result<(), ControlError> {
        let (n, m) = (Self::DESIGN_STATES, self.robot.cables());
        let error = |why: String| ControlError::Design {
            point: self.design_point.iter().copied().collect(),
            why,
        };
        if m < D {
            return Err(error(format!(
                "{m} cables on {D} axes: the design needs at least as many cables as axes"
            )));
        }
        let (a, b) = self.linearisation();
        let [qp, qv, qi, r] = self.weights;
        let mut q = vec![0.0; n * n];
        for k in 0..n {
            q[k * n + k] = [qp, qv, qi][k / D];
        }
        let mut rr = vec![0.0; m * m];
        for k in 0..m {
            rr[k * m + k] = r;
        }
        let (gain, residual, _) = cdpr_numerics::riccati::lqr_gain(n, m, &a, &b, &q, &rr)
            .map_err(|e| error(e.to_string()))?;
        self.gain = gain;
        self.care_residual = residual;
        Ok(())
    }

    /// ξ = (e, ė, σ).
    fn design_state(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
        out: &mut [f64],
    ) {
        let e = reference.position - effector.position;
        let de = self.errors.velocity_error(reference, effector, states);
        for k in 0..D {
            out[k] = e[k];
            out[D + k] = de[k];
            out[2 * D + k] = states[k];
        }
    }

    /// K ξ, each row summed from its first column (the order of nalgebra's matrix-vector
    /// product, so the plane's runs keep their bits).
    fn feedback(&self, xi: &[f64]) -> Tensions {
        let n = Self::DESIGN_STATES;
        Tensions::from_fn(self.robot.cables(), |i| {
            let row = &self.gain[i * n..(i + 1) * n];
            let mut sum = row[0] * xi[0];
            for j in 1..n {
                sum += row[j] * xi[j];
            }
            sum
        })
    }
}

impl<const D: usize> Controller<D> for Lqr<D> {
    fn kind(&self) -> ControllerKind {
        ControllerKind::Lqr
    }
    fn state_len(&self) -> usize {
        error_states::states::<D>()
    }
    /// K_d/K_p per axis as the columns' norms of K: ‖K ė_k‖/‖K e_k‖.
    fn state_weights(&self, out: &mut [f64]) {
        let n = Self::DESIGN_STATES;
        let column = |j: usize| {
            (0..self.robot.cables())
                .map(|i| self.gain[i * n + j].powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let velocity_time = Vector::<D>::from_fn(|k, _| column(D + k) / column(k));
        self.errors.weights::<D>(velocity_time, out);
    }
    fn uses_reference_derivatives(&self) -> bool {
        true
    }
    fn measures(&self) -> Measures {
        Measures {
            all_axes: true,
            velocity: true,
        }
    }
    fn output(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
    ) -> Output<D> {
        let ff =
            self.solver
                .for_acceleration(&self.robot, &reference.position, &reference.acceleration);
        let mut xi = [0.0; 3 * crate::robot::MAX_AXES];
        self.design_state(reference, effector, states, &mut xi);
        let dt = self.feedback(&xi);
        let tensions = Tensions::from_fn(ff.len(), |i| ff[i] + dt[i]);
        let w = self.robot.structure_matrix(&effector.position);
        let wrench = w.force(&tensions);
        if self.robot.cables() > D {
            // A redundant robot: the same wrench, distributed again so that the feedback keeps
            // the box (K ξ alone would push a cable the distribution put on a bound past it).
            return Output {
                wrench,
                tensions: self.solver.for_force_with(&w, &wrench),
            };
        }
        Output { wrench, tensions }
    }
    fn state_rate(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
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
        start: &StepStart<D>,
        reference: &Reference<D>,
        effector: &Effector<D>,
        out: &mut [f64],
    ) {
        self.errors
            .trapezoidal_step(h, start, reference, effector, out);
    }
    fn rest_states(&self, reference: &Reference<D>, _: &Effector<D>, rest: &Rest, out: &mut [f64]) {
        // K_σ σ = T_rest − T_ff at zero error.
        let ff = self
            .solver
            .for_acceleration(&self.robot, &reference.position, &Vector::zeros());
        let n = Self::DESIGN_STATES;
        let sigma = if self.robot.cables() == D {
            let k_sigma = Matrix::<D>::from_fn(|i, j| self.gain[i * n + 2 * D + j]);
            let need = Vector::<D>::from_fn(|i, _| rest.tensions[i] - ff[i]);
            k_sigma
                .try_inverse()
                .map_or(Vector::zeros(), |inv| inv * need)
        } else {
            Vector::zeros()
        };
        ErrorStates::rest(sigma, out);
    }
    fn hold_height(&mut self, z0: f64) -> Result<(), ControlError> {
        self.design_point[vertical::<D>()] = z0;
        self.design()
    }
    fn gains(&self) -> Vec<(&'static str, Vec<f64>)> {
        vec![
            ("lqr_gain", self.gain.clone()),
            (
                "lqr_design_point",
                self.design_point.iter().copied().collect(),
            ),
            ("care_residual", vec![self.care_residual]),
        ]
    }
}
