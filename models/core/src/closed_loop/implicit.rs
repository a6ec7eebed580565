//! The implicit path (MODELS.md FE.9.3): the model's second-order form with the controller's
//! states updated by its A-stable trapezoidal step inside the same residual, so the tensions at
//! t_{n+1} follow the effector state of the iterate, and the audit states W, D by the
//! trapezoidal rule after convergence. Only for models that offer
//! [`CableModel::second_order`] (the runner checks first).

use super::{ClosedLoop, Command, MAX_CONTROLLER_STATES};
use crate::controller::{self, Controller, Reference};
use crate::model::CableModel;
use crate::robot::{Effector, MAX_AXES, Tensions};
use cdpr_numerics::{MatrixCost, SecondOrderSystem};
use std::cell::Cell;

/// What an implicit step needs from its start (t_n, y_n) besides the integrator's own state.
#[derive(Debug, Clone, Default)]
pub(super) struct StepStart<const D: usize> {
    h: f64,
    reference: Reference<D>,
    effector: Effector<D>,
    states: [f64; MAX_CONTROLLER_STATES],
    saturated: bool,
    /// Reel power Σ T_i v_reel,i [W] and model dissipation [W] at t_n.
    power: f64,
    dissipation: f64,
    /// W and D at t_n [J].
    work: f64,
    dissipated: f64,
    /// The time the model's reels were last driven at (reels driven by length; set by
    /// `ClosedLoop::drive_reels`, the loop's only setter of the drive): the Newton iterations of
    /// a step, its end and the next step's start evaluate at one time, so the commanded
    /// lengths' rates (three distributions) are computed once per time.
    pub(super) driven_at: Option<f64>,
    /// The time of the last audit rates (reel power, dissipation) at the implicit path's step
    /// end, and their values: the step's end, the tail's rate there and the next step's start
    /// all ask at one state, and a damped model's dissipation sums every element. Any other
    /// evaluation (the right-hand side, which a restart calls) forgets them.
    pub(super) audited_at: Option<f64>,
    audited: (f64, f64),
    /// The last reference the implicit path asked for, and its time: a step's start, its
    /// Newton iterations, its matrix's tension columns, its end and the next step's start ask
    /// at two times, and a print's reference convolves the plan with the shapers. Forgotten
    /// ([`ClosedLoop::forget_reference`]) when a run starts (the runner; the path, the shaper
    /// or the trajectory may have been replaced since the last run) and when the hold moves.
    remembered: Cell<Option<(f64, Reference<D>)>>,
}

impl<M: CableModel<D>, const D: usize> ClosedLoop<M, D> {
    /// The reels' power Σ T_i v_reel,i (or a driven reel's) and the model's dissipation [W] at
    /// t and `model_state` under `cmd`, the command there: remembered from the last call at t
    /// (see [`StepStart::audited_at`]).
    fn audits_at(&mut self, t: f64, model_state: &[f64], cmd: &Command) -> (f64, f64) {
        if self.step_start.audited_at == Some(t) {
            return self.step_start.audited;
        }
        let reel = self.model.reel_speeds(model_state);
        let audits = self.audit_rates(model_state, &cmd.tensions, &reel);
        self.step_start.audited_at = Some(t);
        self.step_start.audited = audits;
        audits
    }

    /// Hands the model the commanded lengths' rates at t when its reels are driven by length
    /// (as the right-hand side does), unless this step already did at t.
    fn drive_reels_at(&mut self, t: f64) {
        if self.drives_reels_by_length() && self.step_start.driven_at != Some(t) {
            self.drive_reels(t);
        }
    }

    /// Forgets the implicit path's remembered reference ([`StepStart::remembered`]).
    pub(crate) fn forget_reference(&self) {
        self.step_start.remembered.set(None);
    }

    /// [`ClosedLoop::reference`] at t, remembered from the last call at t (see
    /// [`StepStart::remembered`]).
    fn step_reference(&self, t: f64) -> Reference<D> {
        if let Some((at, reference)) = self.step_start.remembered.get()
            && at == t
        {
            return reference;
        }
        let reference = self.reference(t);
        self.step_start.remembered.set(Some((t, reference)));
        reference
    }

    /// The command at the end t of the current implicit step for the effector state `effector`,
    /// and the controller states advanced there from the step's start (into `states`).
    fn step_end_command(
        &self,
        t: f64,
        effector: &Effector<D>,
        states: &mut [f64; MAX_CONTROLLER_STATES],
    ) -> Command {
        let s = &self.step_start;
        let c = self.controller_len();
        let reference = self.step_reference(t);
        let start = controller::StepStart {
            reference: s.reference,
            effector: s.effector,
            states: &s.states[..c],
            saturated: s.saturated,
        };
        self.controller
            .trapezoidal_step(s.h, &start, &reference, effector, &mut states[..c]);
        self.command_with(t, &reference, effector, &states[..c])
    }

    /// The effector columns of the iteration matrix that close the loop through the tension
    /// rows: x, then the other axes where the controller measures them (the first `count` of
    /// the array).
    fn effector_columns(&self) -> ([usize; MAX_AXES], usize) {
        let mut columns = [0; MAX_AXES];
        let Some(form) = self.model.second_order() else {
            return (columns, 0);
        };
        let count = if self.controller.measures().all_axes {
            D
        } else {
            1
        };
        for (k, column) in columns.iter_mut().enumerate().take(count) {
            *column = form.effector_coordinate(k);
        }
        (columns, count)
    }

    /// dT/dq_k + (c_v/c_q) dT/dq'_k of the step-end tensions for the effector coordinate k
    /// (0: x, …), by one-sided differences of the controller's advised step (exact for an
    /// affine controller with a unit step).
    fn tension_slope(
        &self,
        t: f64,
        effector: &Effector<D>,
        tensions: &Tensions,
        k: usize,
        c_v: f64,
        c_q: f64,
    ) -> Tensions {
        let delta = self.controller.difference_step();
        let mut buffer = [0.0; MAX_CONTROLLER_STATES];
        let mut moved = *effector;
        moved.position[k] += delta;
        let at = self.step_end_command(t, &moved, &mut buffer).tensions;
        let mut slope = Tensions::from_fn(tensions.len(), |i| (at[i] - tensions[i]) / delta);
        if self.controller.measures().velocity {
            let mut moving = *effector;
            moving.velocity[k] += delta;
            let at = self.step_end_command(t, &moving, &mut buffer).tensions;
            for i in 0..tensions.len() {
                slope[i] += c_v / c_q * (at[i] - tensions[i]) / delta;
            }
        }
        slope
    }

    /// S of the loop at the iterate for (c_v, c_q) into `values`: the model's part (evaluated,
    /// or with `reweighted` re-weighted from its kept parts; None if it keeps none, or if the
    /// model has no second-order form), then the tension rows' columns of the measured effector
    /// coordinates, ∂R/∂T · dT/dq, by residuals (R is linear in T) at the iterate.
    fn loop_matrix(
        &mut self,
        t: f64,
        y: &[f64],
        qdd: &[f64],
        (c_v, c_q): (f64, f64),
        values: &mut [f64],
        reweighted: bool,
    ) -> Option<MatrixCost> {
        let columns = self.effector_columns().1;
        let form = self.model.second_order()?;
        // The pattern is the model's, then one entry (row, column) per tension row and column.
        let model_entries = values.len() - form.tension_rows().len() * columns;
        if reweighted && !form.reweighted_matrix(c_v, c_q, &mut values[..model_entries]) {
            return None;
        }
        self.drive_reels_at(t);
        let n = self.model_len();
        let effector = self.model.effector(&y[..n]);
        let mut states = [0.0; MAX_CONTROLLER_STATES];
        let tensions = self.step_end_command(t, &effector, &mut states).tensions;
        let mut slopes = [Tensions::zeros(tensions.len()); MAX_AXES];
        for (k, slope) in slopes.iter_mut().enumerate().take(columns) {
            *slope = self.tension_slope(t, &effector, &tensions, k, c_v, c_q);
        }
        let [base, probe] = &mut self.residual_scratch;
        let form = self.model.second_order_mut()?;
        let rows = form.tension_rows();
        let (model_values, tension_values) = values.split_at_mut(model_entries);
        let mut cost = if reweighted {
            MatrixCost::default()
        } else {
            form.iteration_matrix(&y[..n], qdd, &tensions, c_v, c_q, model_values)
        };
        base.resize(form.dofs(), 0.0);
        probe.resize(form.dofs(), 0.0);
        let mut base_done = false;
        for (slope, column_values) in slopes[..columns]
            .iter()
            .zip(tension_values.chunks_mut(rows.len().max(1)))
        {
            if slope.iter().all(|&s| s == 0.0) || rows.is_empty() {
                column_values.fill(0.0);
                continue;
            }
            if !base_done {
                form.residual(&y[..n], qdd, &tensions, base);
                cost = cost.plus_residuals(1);
                base_done = true;
            }
            let pulled = Tensions::from_fn(tensions.len(), |i| tensions[i] + slope[i]);
            form.residual(&y[..n], qdd, &pulled, probe);
            cost = cost.plus_residuals(1);
            for (value, &row) in column_values.iter_mut().zip(&rows) {
                *value = c_q * (probe[row] - base[row]);
            }
        }
        Some(cost)
    }
}

impl<M: CableModel<D>, const D: usize> SecondOrderSystem for ClosedLoop<M, D> {
    fn dofs(&self) -> usize {
        self.model.second_order().map_or(0, |f| f.dofs())
    }

    fn iteration_pattern(&self) -> Vec<(usize, usize)> {
        let Some(form) = self.model.second_order() else {
            return Vec::new();
        };
        let mut pattern = form.iteration_pattern();
        let rows = form.tension_rows();
        let (columns, count) = self.effector_columns();
        for &column in &columns[..count] {
            pattern.extend(rows.iter().map(|&row| (row, column)));
        }
        pattern
    }

    /// The model's own, and the effector's measured coordinates: the controller feeds them back
    /// into the tension rows at the reel ends, which closes the cables' chains (reel, …,
    /// effector, …, reel) into a loop.
    fn coupled_unknowns(&self) -> Vec<usize> {
        let Some(form) = self.model.second_order() else {
            return Vec::new();
        };
        let mut coupled = form.coupled_unknowns();
        if !form.tension_rows().is_empty() {
            let (columns, count) = self.effector_columns();
            coupled.extend_from_slice(&columns[..count]);
        }
        coupled
    }

    fn begin_step(&mut self, t: f64, y: &[f64], h: f64) {
        self.drive_reels_at(t);
        let n = self.model_len();
        let c = self.controller_len();
        let model_state = &y[..n];
        let effector = self.model.effector(model_state);
        let reference = self.step_reference(t);
        let cmd = self.command_with(t, &reference, &effector, &y[n..n + c]);
        let (power, dissipation) = self.audits_at(t, model_state, &cmd);
        let s = &mut self.step_start;
        s.h = h;
        s.reference = reference;
        s.effector = effector;
        s.states[..c].copy_from_slice(&y[n..n + c]);
        s.saturated = cmd.saturated;
        s.power = power;
        s.dissipation = dissipation;
        s.work = y[n + c];
        s.dissipated = y[n + c + 1];
    }

    fn residual(&mut self, t: f64, y: &[f64], qdd: &[f64], r: &mut [f64]) {
        self.drive_reels_at(t);
        let n = self.model_len();
        let effector = self.model.effector(&y[..n]);
        let mut states = [0.0; MAX_CONTROLLER_STATES];
        let tensions = self.step_end_command(t, &effector, &mut states).tensions;
        if let Some(form) = self.model.second_order_mut() {
            form.residual(&y[..n], qdd, &tensions, r);
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
        self.loop_matrix(t, y, qdd, (c_v, c_q), values, false)
            .unwrap_or_default()
    }

    fn reweighted_matrix(
        &mut self,
        t: f64,
        y: &[f64],
        qdd: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> Option<MatrixCost> {
        self.loop_matrix(t, y, qdd, (c_v, c_q), values, true)
    }

    fn tail_rate(&mut self, t: f64, y: &[f64], out: &mut [f64]) {
        self.drive_reels_at(t);
        let n = self.model_len();
        let c = self.controller_len();
        let effector = self.model.effector(&y[..n]);
        let reference = self.step_reference(t);
        let cmd = self.command_with(t, &reference, &effector, &y[n..n + c]);
        let audits = self.audits_at(t, &y[..n], &cmd);
        self.controller_and_audit_rates(y, (&reference, &effector), cmd.saturated, audits, out);
    }

    /// The effector's coordinates.
    fn principal_positions(&self) -> Vec<usize> {
        self.model.second_order().map_or_else(Vec::new, |f| {
            (0..D).map(|k| f.effector_coordinate(k)).collect()
        })
    }

    /// The model's and the controller's states; the energy audits stay out of the norm.
    fn error_len(&self) -> usize {
        self.dynamic_len()
    }

    /// 1 for the model's own tail, the controller's [`Controller::state_weights`] for its
    /// states.
    fn tail_weights(&self) -> Vec<f64> {
        let tail = self.dynamic_len() - 2 * SecondOrderSystem::dofs(self);
        let mut weights = vec![1.0; tail];
        self.controller
            .state_weights(&mut weights[tail - self.controller_len()..]);
        weights
    }

    fn residual_round_off(&self, y: &[f64]) -> f64 {
        let n = self.model_len();
        self.model
            .second_order()
            .map_or(0.0, |f| f.residual_round_off(&y[..n]))
    }

    fn end_step(&mut self, t: f64, y: &mut [f64]) {
        self.drive_reels_at(t);
        let n = self.model_len();
        let c = self.controller_len();
        let effector = self.model.effector(&y[..n]);
        let mut states = [0.0; MAX_CONTROLLER_STATES];
        let cmd = self.step_end_command(t, &effector, &mut states);
        y[n..n + c].copy_from_slice(&states[..c]);
        self.step_start.audited_at = None;
        let (power, dissipation) = self.audits_at(t, &y[..n], &cmd);
        let s = &self.step_start;
        y[n + c] = s.work + 0.5 * s.h * (s.power + power);
        y[n + c + 1] = s.dissipated + 0.5 * s.h * (s.dissipation + dissipation);
    }
}
