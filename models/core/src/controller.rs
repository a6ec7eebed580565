//! The paper's controller (§3.2, MODELS.md §2): a parallel PID with a first-order derivative filter
//! computing the horizontal force F on the effector, and the closed-form tension distribution of two
//! opposed cables (Pott's method) turning F into the commanded tensions T1, T2.
//!
//! The controller is part of the ODE: its integral state w and filter state f are integrated with the
//! model, so its transfer function C(s) = P + I/s + D N_f s/(s + N_f) holds exactly.

use crate::scenario;

/// PID with derivative filter, Simulink parallel form: C(s) = P + I/s + D·N_f·s/(s + N_f).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pid {
    /// Proportional gain P [N/m].
    pub p: f64,
    /// Integral gain I [N/(m s)].
    pub i: f64,
    /// Derivative gain D [N s/m].
    pub d: f64,
    /// Derivative filter coefficient N_f [1/s].
    pub filter: f64,
}

impl From<&scenario::Controller> for Pid {
    fn from(c: &scenario::Controller) -> Self {
        Self {
            p: c.p,
            i: c.i,
            d: c.d,
            filter: c.filter,
        }
    }
}

/// The PID's two states: w = ∫e dt and the filter state f (f' = N_f (e − f)).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PidState {
    pub integral: f64,
    pub filter: f64,
}

impl Pid {
    /// Force F = P e + I w + D N_f (e − f) [N] for the tracking error e = x_ref − x [m].
    #[inline]
    pub fn force(&self, error: f64, state: PidState) -> f64 {
        self.p * error + self.i * state.integral + self.d * self.filter * (error - state.filter)
    }

    /// State derivatives (w', f') = (e, N_f (e − f)).
    pub fn state_rate(&self, error: f64, state: PidState) -> PidState {
        PidState {
            integral: error,
            filter: self.filter * (error - state.filter),
        }
    }

    /// The states at the end of a step of size h [s] by the trapezoidal rule (MODELS.md FE.9.3),
    /// from the states and error e_n at its start and the error e_{n+1} at its end:
    /// w_{n+1} = w_n + h (e_n + e_{n+1})/2,
    /// f_{n+1} = [f_n (1 − h N_f/2) + h N_f (e_n + e_{n+1})/2] / (1 + h N_f/2).
    /// A-stable for the filter pole −N_f at any step, second order like the generalised-α step.
    pub fn trapezoidal_step(&self, start: PidState, e_start: f64, e_end: f64, h: f64) -> PidState {
        let mean = 0.5 * (e_start + e_end);
        let k = 0.5 * h * self.filter;
        PidState {
            integral: start.integral + h * mean,
            filter: (start.filter * (1.0 - k) + 2.0 * k * mean) / (1.0 + k),
        }
    }

    /// State that makes the controller output `force` at zero error and rest: w = F0/I, f = e = 0.
    /// Without integral action (I = 0) no state can hold a force at zero error: `None`.
    pub fn state_holding(&self, force: f64) -> Option<PidState> {
        if force == 0.0 {
            return Some(PidState::default());
        }
        (self.i > 0.0).then(|| PidState {
            integral: force / self.i,
            filter: 0.0,
        })
    }
}

/// The closed-form split of two opposed cables' tensions (paper §3.2, MODELS.md §2): the
/// tensions [T1, T2] = [(ΣT − F)/2, (ΣT + F)/2] [N] that sum to `tension_sum` ΣT and pull the
/// effector toward A2 with the horizontal force `force` F [N]. The controller's distribution and
/// every model's static equilibrium (with F = F0) use it.
///
/// # Examples
///
/// ```
/// use cdpr_core::controller::split_tensions;
///
/// let [t1, t2] = split_tensions(200.0, 10.0);
/// assert_eq!((t1, t2), (95.0, 105.0));
/// assert_eq!(t1 + t2, 200.0);
/// ```
#[inline]
pub fn split_tensions(tension_sum: f64, force: f64) -> [f64; 2] {
    [0.5 * (tension_sum - force), 0.5 * (tension_sum + force)]
}

/// Closed-form tension distribution of two opposed cables (paper §3.2, Pott et al. 2009):
/// T1 = (ΣT − F)/2, T2 = (ΣT + F)/2, F > 0 pulling toward A2; optional saturation to [t_min, t_max].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensionDistribution {
    /// Pretension sum ΣT [N].
    pub tension_sum: f64,
    /// Lower saturation [N] (−∞ = off).
    pub t_min: f64,
    /// Upper saturation [N] (+∞ = off).
    pub t_max: f64,
}

impl From<&scenario::Controller> for TensionDistribution {
    fn from(c: &scenario::Controller) -> Self {
        Self {
            tension_sum: c.tension_sum,
            t_min: c.t_min.unwrap_or(f64::NEG_INFINITY),
            t_max: c.t_max.unwrap_or(f64::INFINITY),
        }
    }
}

impl TensionDistribution {
    /// Commanded tensions [T1, T2] [N] for the horizontal force F [N].
    #[inline]
    pub fn tensions(&self, force: f64) -> [f64; 2] {
        split_tensions(self.tension_sum, force).map(|t| t.clamp(self.t_min, self.t_max))
    }
}
