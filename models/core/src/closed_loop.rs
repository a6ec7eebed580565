//! The closed loop of the paper's Fig. 4: `step5` reference → PID → tension distribution → cable
//! model, as one ODE ([`ClosedLoop`]), in first-order form for DOPRI5 and in second-order form
//! for generalised-α. The runner that integrates it is [`crate::runner`].
//!
//! State layout: `[model state (n) | w | f | W | D]`: the PID integral and filter states, then two
//! audit states excluded from the error norm, the reels' work W = ∫ Σ T_i v_reel,i dt and the energy
//! dissipated inside the model D. They make the energy balance E(t) − E(0) − W(t) + D(t) − ΣΔE = 0
//! (ΔE the energy changes of model events) a channel of every run.

use crate::controller::{Pid, PidState, TensionDistribution};
use crate::model::{CableModel, Equilibrium, ModelError};
use crate::scenario::Scenario;
use crate::trajectory::Step5;
use cdpr_numerics::{MatrixCost, OdeSystem, SecondOrderSystem};

/// Where the commanded tensions come from.
pub enum Actuation {
    /// The paper's PID and tension distribution.
    Pid,
    /// Tensions prescribed as functions of time [s] → [T1, T2] [N]; the PID states still integrate
    /// the error but do not act (energy and verification runs).
    Prescribed(Box<dyn Fn(f64) -> [f64; 2] + Send + Sync>),
}

/// What the controller commands at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// x_ref [m].
    pub reference: f64,
    /// e = x_ref − x [m].
    pub error: f64,
    /// PID force F [N] (pulls toward A2 when positive).
    pub force: f64,
    /// Commanded tensions [T1, T2] [N].
    pub tensions: [f64; 2],
}

/// Model + controller as one [`OdeSystem`].
pub struct ClosedLoop<M: CableModel> {
    pub model: M,
    pub trajectory: Step5,
    pub pid: Pid,
    pub distribution: TensionDistribution,
    pub actuation: Actuation,
    /// The start of the current implicit step (the trapezoidal controller and audit updates).
    step_start: StepStart,
    /// Two residuals for the tension column of the implicit iteration matrix (allocated once).
    residual_scratch: [Vec<f64>; 2],
}

/// What an implicit step needs from its start (t_n, y_n) besides the integrator's own state.
#[derive(Debug, Clone, Copy, Default)]
struct StepStart {
    h: f64,
    error: f64,
    pid: PidState,
    /// Reel power Σ T_i v_reel,i [W] and model dissipation [W] at t_n.
    power: f64,
    dissipation: f64,
    /// W and D at t_n [J].
    work: f64,
    dissipated: f64,
}

/// Number of controller and audit states after the model's.
pub const EXTRA_STATES: usize = 4;

impl<M: CableModel> ClosedLoop<M> {
    /// The paper's loop for `model` with the scenario's controller and trajectory.
    pub fn new(model: M, scenario: &Scenario) -> Self {
        Self {
            model,
            trajectory: Step5::from(&scenario.trajectory),
            pid: Pid::from(&scenario.controller),
            distribution: TensionDistribution::from(&scenario.controller),
            actuation: Actuation::Pid,
            step_start: StepStart::default(),
            residual_scratch: Default::default(),
        }
    }

    /// Length of the model's part of the state.
    pub fn model_len(&self) -> usize {
        self.model.state_len()
    }

    /// Splits a closed-loop state into the model state and the PID state.
    pub fn split<'a>(&self, y: &'a [f64]) -> (&'a [f64], PidState) {
        let n = self.model_len();
        (
            &y[..n],
            PidState {
                integral: y[n],
                filter: y[n + 1],
            },
        )
    }

    /// Reference, error, force and commanded tensions at (t, y).
    #[inline]
    pub fn command(&self, t: f64, y: &[f64]) -> Command {
        let (model_state, pid_state) = self.split(y);
        let x = self.model.effector(model_state).position.x;
        self.command_at(t, x, |_| pid_state).0
    }

    /// The command at time t for effector position x [m], with the PID states `pid(e)` for the
    /// error e (the states themselves, or their implicit-step update), and those states.
    #[inline]
    fn command_at(&self, t: f64, x: f64, pid: impl FnOnce(f64) -> PidState) -> (Command, PidState) {
        let reference = self.trajectory.position(t);
        let error = reference - x;
        let pid_state = pid(error);
        let force = self.pid.force(error, pid_state);
        let tensions = match &self.actuation {
            Actuation::Pid => self.distribution.tensions(force),
            Actuation::Prescribed(f) => f(t),
        };
        let command = Command {
            reference,
            error,
            force,
            tensions,
        };
        (command, pid_state)
    }

    /// Rates of the states after the model's, (w', f', W', D'), at state `y` under `cmd`.
    fn controller_and_audit_rates(&self, y: &[f64], cmd: &Command, out: &mut [f64]) {
        let (model_state, pid_state) = self.split(y);
        let pid_rate = self.pid.state_rate(cmd.error, pid_state);
        let reel = self.model.reel_speeds(model_state);
        out[0] = pid_rate.integral;
        out[1] = pid_rate.filter;
        out[2] = cmd.tensions[0] * reel[0] + cmd.tensions[1] * reel[1];
        out[3] = self.model.dissipation(model_state);
    }

    /// Initial state by the rule of MODELS.md §2: the model's static equilibrium with the effector
    /// at x_ref(0) and F0 unknown, velocities zero, w(0) = F0/I, f(0) = e(0) = 0, audits zero.
    /// Without integral action (I = 0) no controller state holds F0; w(0) = 0 then.
    pub fn initial_state(&mut self) -> Result<(Vec<f64>, Equilibrium), ModelError> {
        self.rest_state(self.trajectory.position(0.0))
    }

    /// The closed loop at rest with the effector at x [m]: the model's static equilibrium there,
    /// the PID states holding its force F0 (w = F0/I, f = 0), audits zero (the start of a run,
    /// and the point a linearisation is taken about).
    pub fn rest_state(&mut self, x: f64) -> Result<(Vec<f64>, Equilibrium), ModelError> {
        let eq = self.model.equilibrium(x, self.distribution.tension_sum)?;
        let pid = self.pid.state_holding(eq.force).unwrap_or_default();
        let mut y = eq.state.clone();
        y.extend_from_slice(&[pid.integral, pid.filter, 0.0, 0.0]);
        Ok((y, eq))
    }
}

impl<M: CableModel> OdeSystem for ClosedLoop<M> {
    fn dimension(&self) -> usize {
        self.model_len() + EXTRA_STATES
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.model_len();
        let cmd = self.command(t, y);
        let (model_rate, tail) = dy.split_at_mut(n);
        self.model.rhs(t, &y[..n], cmd.tensions, model_rate);
        self.controller_and_audit_rates(y, &cmd, tail);
    }
}

/// The implicit path (MODELS.md FE.9.3): the model's second-order form with the PID states updated
/// by the trapezoidal rule inside the same residual, so the tensions at t_{n+1} follow the effector
/// position of the iterate, and the audit states W, D by the trapezoidal rule after convergence.
/// Only for models that offer [`CableModel::second_order`] (the runner checks first).
impl<M: CableModel> SecondOrderSystem for ClosedLoop<M> {
    fn dofs(&self) -> usize {
        self.model.second_order().map_or(0, |f| f.dofs())
    }

    fn iteration_pattern(&self) -> Vec<(usize, usize)> {
        let Some(form) = self.model.second_order() else {
            return Vec::new();
        };
        let mut pattern = form.iteration_pattern();
        let x = form.effector_x();
        pattern.extend(form.tension_rows().into_iter().map(|row| (row, x)));
        pattern
    }

    /// The model's own, and the effector's x: the controller feeds it back into the tension
    /// rows at the reel ends, which closes the cables' chains (reel, …, effector, …, reel) into
    /// a loop.
    fn coupled_unknowns(&self) -> Vec<usize> {
        let Some(form) = self.model.second_order() else {
            return Vec::new();
        };
        let mut coupled = form.coupled_unknowns();
        if !form.tension_rows().is_empty() {
            coupled.push(form.effector_x());
        }
        coupled
    }

    fn begin_step(&mut self, t: f64, y: &[f64], h: f64) {
        let n = self.model_len();
        let cmd = self.command(t, y);
        let (model_state, pid) = self.split(y);
        let reel = self.model.reel_speeds(model_state);
        self.step_start = StepStart {
            h,
            error: cmd.error,
            pid,
            power: cmd.tensions[0] * reel[0] + cmd.tensions[1] * reel[1],
            dissipation: self.model.dissipation(model_state),
            work: y[n + 2],
            dissipated: y[n + 3],
        };
    }

    fn residual(&mut self, t: f64, y: &[f64], qdd: &[f64], r: &mut [f64]) {
        let n = self.model_len();
        let tensions = self.step_end_command(t, &y[..n]).0.tensions;
        if let Some(form) = self.model.second_order_mut() {
            form.residual(&y[..n], qdd, tensions, r);
        }
    }

    fn iteration_matrix(
        &mut self,
        t: f64,
        y: &[f64],
        qdd: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        let n = self.model_len();
        // dT/dx of the effector through the trapezoidal PID: T is affine in x (unless saturated),
        // so a unit difference is exact.
        let x = self.model.effector(&y[..n]).position.x;
        let tensions = self.step_end_command_at(t, x).0.tensions;
        let moved = self.step_end_command_at(t, x + 1.0).0.tensions;
        let slope = [moved[0] - tensions[0], moved[1] - tensions[1]];
        let [base, probe] = &mut self.residual_scratch;
        let Some(form) = self.model.second_order_mut() else {
            return MatrixCost::default();
        };
        // The pattern is the model's, then one entry (row, x) per tension row.
        let rows = form.tension_rows();
        let (model_values, tension_values) = values.split_at_mut(values.len() - rows.len());
        let mut cost = form.iteration_matrix(&y[..n], qdd, tensions, c_v, c_q, model_values);
        if slope != [0.0, 0.0] && !rows.is_empty() {
            // Column x of ∂R/∂T · dT/dx, by two more residuals (R is linear in T).
            base.resize(form.dofs(), 0.0);
            probe.resize(form.dofs(), 0.0);
            form.residual(&y[..n], qdd, tensions, base);
            let pulled = [tensions[0] + slope[0], tensions[1] + slope[1]];
            form.residual(&y[..n], qdd, pulled, probe);
            cost = cost.plus_residuals(2);
            for (value, &row) in tension_values.iter_mut().zip(&rows) {
                *value = c_q * (probe[row] - base[row]);
            }
        } else {
            tension_values.fill(0.0);
        }
        cost
    }

    fn tail_rate(&mut self, t: f64, y: &[f64], out: &mut [f64]) {
        let cmd = self.command(t, y);
        self.controller_and_audit_rates(y, &cmd, out);
    }

    fn residual_round_off(&self, y: &[f64]) -> f64 {
        let n = self.model_len();
        self.model
            .second_order()
            .map_or(0.0, |f| f.residual_round_off(&y[..n]))
    }

    fn end_step(&mut self, t: f64, y: &mut [f64]) {
        let n = self.model_len();
        let s = self.step_start;
        let (cmd, pid) = self.step_end_command(t, &y[..n]);
        y[n] = pid.integral;
        y[n + 1] = pid.filter;
        let reel = self.model.reel_speeds(&y[..n]);
        let power = cmd.tensions[0] * reel[0] + cmd.tensions[1] * reel[1];
        let dissipation = self.model.dissipation(&y[..n]);
        y[n + 2] = s.work + 0.5 * s.h * (s.power + power);
        y[n + 3] = s.dissipated + 0.5 * s.h * (s.dissipation + dissipation);
    }
}

impl<M: CableModel> ClosedLoop<M> {
    /// The command at the end t of the current implicit step for the model state `model_state`:
    /// the PID states advanced by the trapezoidal rule from the step's start.
    fn step_end_command(&self, t: f64, model_state: &[f64]) -> (Command, PidState) {
        self.step_end_command_at(t, self.model.effector(model_state).position.x)
    }

    /// As [`Self::step_end_command`], for effector position x [m].
    fn step_end_command_at(&self, t: f64, x: f64) -> (Command, PidState) {
        let s = self.step_start;
        self.command_at(t, x, |error| {
            self.pid.trapezoidal_step(s.pid, s.error, error, s.h)
        })
    }
}
