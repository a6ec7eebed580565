//! Dormand–Prince 5(4) with Hairer's dense output, exactly as dopri5.f (Hairer, Nørsett & Wanner,
//! Solving ODEs I, §II.5 and II.6; MODELS.md §6): error norm over the whole state, HINIT start step,
//! step factor err^(0.2−0.75β)/facold^β with safety 0.9 and 0.2 ≤ h_new/h ≤ 10, no step increase right
//! after a rejection, no step-count limit and no stiffness abort.
//!
//! The integrator is driven one accepted step at a time so that a caller can sample the dense output,
//! look for events and restart with a changed state between steps.

use crate::ode::{IntegratorError, OdeSystem, SolverStats, Stepper};

// Butcher tableau (dopri5.f, CDOPRI).
const C2: f64 = 0.2;
const C3: f64 = 0.3;
const C4: f64 = 0.8;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 0.2;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Error estimate: 5th minus 4th order weights.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Dense output of order 4 (Shampine).
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// dopri5.f's unit round-off for the step-underflow test.
const UROUND: f64 = 2.3e-16;

/// Settings of [`Dopri5`]; the defaults are dopri5.f's with MODELS.md §1 tolerances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dopri5Options {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (every component).
    pub atol: f64,
    /// Step-size controller β (0.04 Hairer, 0 scipy's RK45).
    pub beta: f64,
    /// Safety factor.
    pub safety: f64,
    /// Lower bound of h_new/h.
    pub min_factor: f64,
    /// Upper bound of h_new/h.
    pub max_factor: f64,
    /// Largest step [s]; `None`: the whole interval, as dopri5.f.
    pub max_step: Option<f64>,
    /// Initial step [s]; `None`: Hairer's HINIT.
    pub initial_step: Option<f64>,
    /// Only the first `norm_components` components enter the error norm (audit states excluded);
    /// `None`: all.
    pub norm_components: Option<usize>,
}

impl Default for Dopri5Options {
    fn default() -> Self {
        Self {
            rtol: 1e-5,
            atol: 1e-9,
            beta: 0.04,
            safety: 0.9,
            min_factor: 0.2,
            max_factor: 10.0,
            max_step: None,
            initial_step: None,
            norm_components: None,
        }
    }
}

/// Dormand–Prince 5(4) integrator state: the current point, the stage buffers (allocated once) and
/// the dense-output coefficients of the last accepted step.
#[derive(Debug, Clone)]
pub struct Dopri5 {
    opts: Dopri5Options,
    t: f64,
    t_old: f64,
    h: f64,
    /// Step of the last accepted step (restart value).
    h_accepted: f64,
    facold: f64,
    y: Vec<f64>,
    y1: Vec<f64>,
    ysti: Vec<f64>,
    k1: Vec<f64>,
    k2: Vec<f64>,
    k3: Vec<f64>,
    k4: Vec<f64>,
    k5: Vec<f64>,
    k6: Vec<f64>,
    /// rcont1..rcont5 of dopri5.f.
    cont: [Vec<f64>; 5],
    stats: SolverStats,
    started: bool,
    /// Whether the system's last right-hand side was at (t, y) (see
    /// [`Stepper::last_rhs_at_state`]).
    last_rhs_at_state: bool,
}

impl Dopri5 {
    /// Allocates all buffers for a system of `dimension` components.
    pub fn new(dimension: usize, opts: Dopri5Options) -> Self {
        let v = || vec![0.0; dimension];
        Self {
            opts,
            t: 0.0,
            t_old: 0.0,
            h: 0.0,
            h_accepted: 0.0,
            facold: 1e-4,
            y: v(),
            y1: v(),
            ysti: v(),
            k1: v(),
            k2: v(),
            k3: v(),
            k4: v(),
            k5: v(),
            k6: v(),
            cont: [v(), v(), v(), v(), v()],
            stats: SolverStats::default(),
            started: false,
            last_rhs_at_state: false,
        }
    }

    /// Current time [s] (end of the last accepted step).
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Start of the last accepted step [s].
    pub fn previous_time(&self) -> f64 {
        self.t_old
    }

    /// Current state.
    pub fn state(&self) -> &[f64] {
        &self.y
    }

    /// Derivative at the current state (the FSAL stage).
    pub fn derivative(&self) -> &[f64] {
        &self.k1
    }

    /// Step size proposed for the next step [s].
    pub fn step_size(&self) -> f64 {
        self.h
    }

    /// Counters so far.
    pub fn stats(&self) -> SolverStats {
        self.stats
    }

    /// Begins an integration at (t0, y0) heading for `t_end`: evaluates f once and picks the first
    /// step (HINIT, one more evaluation) unless one was given.
    pub fn start<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        t_end: f64,
    ) -> Result<(), IntegratorError> {
        if y0.len() != self.y.len() || sys.dimension() != self.y.len() {
            return Err(IntegratorError::Usage(
                "state length differs from the integrator's dimension",
            ));
        }
        if t_end <= t0 {
            return Err(IntegratorError::Usage("t_end must be after t0"));
        }
        self.t = t0;
        self.t_old = t0;
        self.y.copy_from_slice(y0);
        self.facold = 1e-4;
        sys.rhs(t0, &self.y, &mut self.k1);
        let h_max = self.opts.max_step.unwrap_or(t_end - t0);
        self.h = match self.opts.initial_step {
            Some(h) => h.min(h_max),
            None => self.initial_step(sys, h_max),
        };
        self.stats.rhs_evals += 2;
        self.h_accepted = self.h;
        self.started = true;
        // HINIT's probe was the last evaluation, away from y0.
        self.last_rhs_at_state = self.opts.initial_step.is_some();
        Ok(())
    }

    /// Continues from a changed state `y` at time `t` within the last accepted step (after a model
    /// event): re-evaluates the derivative and keeps the step size of the last accepted step
    /// (MODELS.md §6). The dense output of the abandoned step is discarded.
    pub fn restart<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) {
        self.t = t;
        self.y.copy_from_slice(y);
        sys.rhs(self.t, &self.y, &mut self.k1);
        self.stats.rhs_evals += 1;
        self.stats.restarts += 1;
        self.h = self.h_accepted;
        self.t_old = self.t;
        self.last_rhs_at_state = true;
    }

    /// Hairer's HINIT: h such that h⁵·max(‖f0‖, ‖f'‖) = 0.01, from one explicit Euler probe.
    fn initial_step<S: OdeSystem>(&mut self, sys: &mut S, h_max: f64) -> f64 {
        let (atol, rtol) = (self.opts.atol, self.opts.rtol);
        let n = self.norm_len();
        let mut dnf = 0.0;
        let mut dny = 0.0;
        for i in 0..n {
            let sk = atol + rtol * self.y[i].abs();
            dnf += (self.k1[i] / sk).powi(2);
            dny += (self.y[i] / sk).powi(2);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            (dny / dnf).sqrt() * 0.01
        };
        h = h.min(h_max);
        for i in 0..self.y.len() {
            self.y1[i] = self.y[i] + h * self.k1[i];
        }
        sys.rhs(self.t + h, &self.y1, &mut self.k2);
        let mut der2 = 0.0;
        for i in 0..n {
            let sk = atol + rtol * self.y[i].abs();
            der2 += ((self.k2[i] - self.k1[i]) / sk).powi(2);
        }
        der2 = der2.sqrt() / h;
        let der12 = der2.abs().max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(1.0 / 5.0)
        };
        (100.0 * h).min(h1).min(h_max)
    }

    fn norm_len(&self) -> usize {
        self.opts
            .norm_components
            .unwrap_or(self.y.len())
            .min(self.y.len())
    }

    /// Advances by one accepted step, never past `t_end` (the step that reaches it lands on it
    /// exactly). Rejected attempts are retried internally with a smaller step.
    pub fn step<S: OdeSystem>(&mut self, sys: &mut S, t_end: f64) -> Result<(), IntegratorError> {
        if !self.started {
            return Err(IntegratorError::Usage("step() before start()"));
        }
        if self.t >= t_end {
            return Err(IntegratorError::Usage("already at t_end"));
        }
        let h_max = self.opts.max_step.unwrap_or(f64::INFINITY);
        let expo1 = 0.2 - self.opts.beta * 0.75;
        let facc1 = 1.0 / self.opts.min_factor;
        let facc2 = 1.0 / self.opts.max_factor;
        let safe = self.opts.safety;
        let mut reject = false;
        loop {
            if 0.1 * self.h.abs() <= self.t.abs() * UROUND {
                return Err(IntegratorError::StepSizeUnderflow {
                    t: self.t,
                    h: self.h,
                });
            }
            let mut last = false;
            if self.t + 1.01 * self.h - t_end > 0.0 {
                self.h = t_end - self.t;
                last = true;
            }
            self.stats.steps_attempted += 1;
            let err = self.attempt(sys);
            self.stats.rhs_evals += 6;
            if err.is_nan() {
                // A NaN never passes the error test; shrinking is the only way out, but say where.
                if let Some(component) = self.y1.iter().position(|v| !v.is_finite())
                    && self.h.abs() <= self.t.abs().max(1.0) * 1e-14
                {
                    return Err(IntegratorError::NonFinite {
                        t: self.t,
                        component,
                    });
                }
                self.h *= self.opts.min_factor;
                reject = true;
                self.stats.steps_rejected += 1;
                continue;
            }
            let fac11 = err.powf(expo1);
            // Lund stabilisation (PI control): divide by facold^β.
            let fac = (fac11 / self.facold.powf(self.opts.beta) / safe).clamp(facc2, facc1);
            let mut h_new = self.h / fac;
            if err <= 1.0 {
                self.facold = err.max(1e-4);
                self.stats.steps_accepted += 1;
                self.accept();
                self.t_old = self.t;
                self.t = if last { t_end } else { self.t + self.h };
                self.h_accepted = self.h;
                if h_new.abs() > h_max {
                    h_new = h_max;
                }
                if reject {
                    h_new = h_new.abs().min(self.h.abs());
                }
                self.h = h_new;
                // The FSAL stage k7 = f(t + h, y1) was the last evaluation; y1 is now y (t is
                // t + h as the stage computed it, or t_end on the last step).
                self.last_rhs_at_state = true;
                return Ok(());
            }
            h_new = self.h / facc1.min(fac11 / safe);
            reject = true;
            self.stats.steps_rejected += 1;
            self.h = h_new;
        }
    }

    /// One attempted step of size h from (t, y): the 7 stages, the solution in `y1`, its derivative
    /// (FSAL) in `k2`, the dense-output term rcont5 and the scaled error norm.
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S) -> f64 {
        let (t, h) = (self.t, self.h);
        let n = self.y.len();
        // Every buffer re-sliced to n: the compiler then drops the bounds checks and vectorises.
        let (y, y1, ysti) = (&self.y[..n], &mut self.y1[..n], &mut self.ysti[..n]);
        let (k1, k2, k3, k4, k5, k6) = (
            &self.k1[..n],
            &mut self.k2[..n],
            &mut self.k3[..n],
            &mut self.k4[..n],
            &mut self.k5[..n],
            &mut self.k6[..n],
        );
        for i in 0..n {
            y1[i] = y[i] + h * A21 * k1[i];
        }
        sys.rhs(t + C2 * h, y1, k2);
        for i in 0..n {
            y1[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        sys.rhs(t + C3 * h, y1, k3);
        for i in 0..n {
            y1[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        sys.rhs(t + C4 * h, y1, k4);
        for i in 0..n {
            y1[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        sys.rhs(t + C5 * h, y1, k5);
        for i in 0..n {
            ysti[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        sys.rhs(t + h, ysti, k6);
        for i in 0..n {
            y1[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        // k2 now holds k7 = f(t + h, y1) (first same as last).
        sys.rhs(t + h, y1, k2);
        let rcont5 = &mut self.cont[4][..n];
        for i in 0..n {
            rcont5[i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k2[i]);
        }
        let (atol, rtol) = (self.opts.atol, self.opts.rtol);
        let m = self.opts.norm_components.unwrap_or(n).min(n);
        // (ê_i/sc_i)² in one vectorisable sweep (into ysti, free after k6), then summed in four
        // interleaved partial sums: a fixed order, so still reproducible.
        let q2 = &mut ysti[..m];
        for i in 0..m {
            let e =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k2[i]);
            let q = e / (atol + rtol * y[i].abs().max(y1[i].abs()));
            // y1·0 is 0, or NaN exactly when y1 is NaN or ±∞ (`max` above would hide it).
            q2[i] = q * q + y1[i] * 0.0;
        }
        let mut lanes = [0.0f64; 4];
        let chunks = q2.chunks_exact(4);
        let tail = chunks.remainder();
        for c in chunks {
            lanes[0] += c[0];
            lanes[1] += c[1];
            lanes[2] += c[2];
            lanes[3] += c[3];
        }
        for &v in tail {
            lanes[0] += v;
        }
        let err = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
        // A non-finite component outside the norm (audit states) must fail the test too; those
        // inside already made `err` NaN in the same sweep.
        if y1[m..].iter().any(|v| !v.is_finite()) {
            return f64::NAN;
        }
        (err / m as f64).sqrt()
    }

    /// Stores the dense-output coefficients of the accepted step and moves to its end point.
    fn accept(&mut self) {
        let h = self.h;
        let n = self.y.len();
        let [c1, c2, c3, c4, _] = &mut self.cont;
        let (c1, c2, c3, c4) = (&mut c1[..n], &mut c2[..n], &mut c3[..n], &mut c4[..n]);
        let (y, y1, k1, k2) = (&self.y[..n], &self.y1[..n], &self.k1[..n], &self.k2[..n]);
        for i in 0..n {
            let ydiff = y1[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            c1[i] = y[i];
            c2[i] = ydiff;
            c3[i] = bspl;
            c4[i] = -h * k2[i] + ydiff - bspl;
        }
        std::mem::swap(&mut self.k1, &mut self.k2);
        std::mem::swap(&mut self.y, &mut self.y1);
    }

    /// Dense output (order 4) at t in [t_old, t] of the last accepted step, into `out` (the first
    /// `out.len()` components).
    #[inline]
    pub fn dense_output(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_old;
        if h <= 0.0 {
            // Right after start() or restart(): no step to interpolate yet.
            out.copy_from_slice(&self.y[..out.len()]);
            return;
        }
        let theta = (t - self.t_old) / h;
        let theta1 = 1.0 - theta;
        let [c1, c2, c3, c4, c5] = &self.cont;
        for (i, o) in out.iter_mut().enumerate() {
            *o = c1[i] + theta * (c2[i] + theta1 * (c3[i] + theta * (c4[i] + theta1 * c5[i])));
        }
    }
}

impl<S: OdeSystem> Stepper<S> for Dopri5 {
    fn start(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        t_end: f64,
    ) -> Result<(), IntegratorError> {
        Dopri5::start(self, sys, t0, y0, t_end)
    }
    fn step(&mut self, sys: &mut S, t_end: f64) -> Result<(), IntegratorError> {
        Dopri5::step(self, sys, t_end)
    }
    fn restart(&mut self, sys: &mut S, t: f64, y: &[f64]) {
        Dopri5::restart(self, sys, t, y)
    }
    fn time(&self) -> f64 {
        Dopri5::time(self)
    }
    fn previous_time(&self) -> f64 {
        Dopri5::previous_time(self)
    }
    fn state(&self) -> &[f64] {
        Dopri5::state(self)
    }
    fn dense_output(&self, t: f64, out: &mut [f64]) {
        Dopri5::dense_output(self, t, out)
    }
    fn stats(&self) -> SolverStats {
        Dopri5::stats(self)
    }
    fn last_rhs_at_state(&self) -> bool {
        self.last_rhs_at_state
    }
}
