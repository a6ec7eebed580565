//! A critically damped second-order low-pass on the velocity error ė = v_ref − v of each axis,
//! for the controllers that feed velocity back (computed-torque, LQR):
//!
//! ```text
//! ë_f + 2 ω_f ė_f' + ω_f² ė_f = ω_f² ė        (per axis; states ė_f and ė_f')
//! ```
//!
//! Why: the reels command tension at one end of a cable and the velocity is measured at the
//! other. On the massive-cable models the first axial mode of each cable (≈ 5 800 rad/s at x2,
//! no material damping in the paper's cable) sees the raw velocity feedback as negative damping:
//! its growth rate is ≈ 0.67 K_d [1/s] (measured: 20.2 1/s at K_d = 30 1/s on FE). A
//! second-order filter lags 180° there, so the feedback damps the mode instead, by a factor
//! (ω_f/ω)² weaker; at the control bandwidth (60 rad/s) it costs 2·60/ω_f rad of phase.
//! Filtering the error rather than the velocity keeps a perfectly tracked move error-free.

/// The filter's per-axis state (ė_f, ė_f') for both axes: [ė_f,x, ė_f,z, ė_f'_x, ė_f'_z].
/// Number of states per axis: the filtered error and its rate (layout: every axis's filtered
/// error, then every axis's rate).
pub const STATES_PER_AXIS: usize = 2;

/// The low-pass of corner ω_f [rad/s]; ω_f = ∞ passes the velocity error unfiltered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityFilter {
    pub omega: f64,
}

impl VelocityFilter {
    /// Whether the filter is on (finite corner).
    pub fn is_on(&self) -> bool {
        self.omega.is_finite()
    }

    /// The filtered velocity error [m/s] of axis k from the states, or the raw `error` when off.
    #[inline]
    pub fn output(&self, states: &[f64], k: usize, error: f64) -> f64 {
        if self.is_on() { states[k] } else { error }
    }

    /// d/dt of the states for the raw velocity errors `error`, one per axis.
    pub fn rate(&self, states: &[f64], error: &[f64], rate: &mut [f64]) {
        let w = self.omega;
        let n = error.len();
        for k in 0..n {
            let (v, dv) = (states[k], states[n + k]);
            rate[k] = dv;
            rate[n + k] = if self.is_on() {
                w * w * (error[k] - v) - 2.0 * w * dv
            } else {
                0.0
            };
        }
    }

    /// The trapezoidal step of size h [s] from `start` with the raw errors at the step's start
    /// and end: (I − h/2 A) s₁ = (I + h/2 A) s₀ + h/2 B (u₀ + u₁), A = [0 1; −ω² −2ω],
    /// B = [0; ω²], solved in closed form (A-stable for the filter's double pole at −ω_f).
    pub fn trapezoidal_step(
        &self,
        start: &[f64],
        e_start: &[f64],
        e_end: &[f64],
        h: f64,
        out: &mut [f64],
    ) {
        let n = e_start.len();
        if !self.is_on() {
            out[..STATES_PER_AXIS * n].fill(0.0);
            return;
        }
        let (w, k) = (self.omega, 0.5 * h);
        for axis in 0..n {
            let (v0, d0) = (start[axis], start[n + axis]);
            let u = e_start[axis] + e_end[axis];
            // Right-hand side (I + kA) s₀ + k B u.
            let r0 = v0 + k * d0;
            let r1 = d0 + k * (-w * w * v0 - 2.0 * w * d0) + k * w * w * u;
            // (I − kA) = [1, −k; k ω², 1 + 2kω].
            let (a, b, c, d) = (1.0, -k, k * w * w, 1.0 + 2.0 * k * w);
            let det = a * d - b * c;
            out[axis] = (d * r0 - b * r1) / det;
            out[n + axis] = (a * r1 - c * r0) / det;
        }
    }
}
