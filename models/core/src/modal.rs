//! Linearisation of the closed loop about a state and its eigenvalues (faer), for the closed-loop
//! vertical eigenfrequency that MODELS.md §8 compares with the spectral peak.

use crate::closed_loop::ClosedLoop;
use crate::integrate::OdeSystem;
use crate::model::CableModel;
use faer::Mat;

pub use faer::linalg::evd::EvdError;

/// A continuous-time eigenvalue λ = σ + iω [1/s].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Mode {
    /// Growth rate σ [1/s] (> 0: growing).
    pub growth: f64,
    /// Angular frequency ω ≥ 0 [rad/s].
    pub omega: f64,
}

impl Mode {
    /// Damping ratio ζ = −σ/|λ|.
    pub fn damping_ratio(&self) -> f64 {
        -self.growth / self.growth.hypot(self.omega)
    }
}

/// Jacobian ∂y'/∂y of the closed loop (model and PID states; the audit states are left out) at
/// (t, y) by central differences. Step h_j = ε^(1/3)·max(|y_j|, 1e-3): truncation O(h²) and
/// round-off O(ε/h) balance near 1e-10 relative for the smooth right-hand sides here.
pub fn closed_loop_jacobian<M: CableModel>(sys: &mut ClosedLoop<M>, t: f64, y: &[f64]) -> Mat<f64> {
    let n = sys.model_len() + 2;
    let full = sys.dimension();
    let mut yp = y.to_vec();
    let mut fp = vec![0.0; full];
    let mut fm = vec![0.0; full];
    let mut jac = Mat::<f64>::zeros(n, n);
    for j in 0..n {
        let h = f64::EPSILON.cbrt() * y[j].abs().max(1e-3);
        yp[j] = y[j] + h;
        sys.rhs(t, &yp, &mut fp);
        yp[j] = y[j] - h;
        sys.rhs(t, &yp, &mut fm);
        yp[j] = y[j];
        for i in 0..n {
            jac[(i, j)] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    jac
}

/// Eigenvalues of `jac` with ω ≥ 0 (one of each conjugate pair), sorted by frequency.
pub fn modes(jac: &Mat<f64>) -> Result<Vec<Mode>, EvdError> {
    let mut modes: Vec<Mode> = jac
        .eigenvalues()?
        .into_iter()
        .filter(|l| l.im >= 0.0)
        .map(|l| Mode {
            growth: l.re,
            omega: l.im,
        })
        .collect();
    modes.sort_by(|a, b| {
        a.omega
            .total_cmp(&b.omega)
            .then(a.growth.total_cmp(&b.growth))
    });
    Ok(modes)
}

/// The oscillatory mode whose frequency is closest to `omega_guess` [rad/s].
pub fn nearest_mode(modes: &[Mode], omega_guess: f64) -> Option<Mode> {
    modes
        .iter()
        .filter(|m| m.omega > 0.0)
        .min_by(|a, b| {
            (a.omega - omega_guess)
                .abs()
                .total_cmp(&(b.omega - omega_guess).abs())
        })
        .copied()
}
