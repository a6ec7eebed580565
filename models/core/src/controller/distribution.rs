//! From a force on the effector to cable tensions: the paper's closed-form split of two opposed
//! cables with ΣT fixed (Pott et al. 2009), the structure matrix W = [u1 u2] that maps tensions to
//! the force on the effector for any desired force, and the tension limits every controller obeys.

use crate::Vector2;
use crate::scenario;
use nalgebra::Matrix2;

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

/// The tension limits [t_min, t_max] [N] every controller's command is clamped to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensionLimits {
    /// Lower limit [N] (−∞ = off).
    pub t_min: f64,
    /// Upper limit [N] (+∞ = off).
    pub t_max: f64,
}

impl From<&scenario::Controller> for TensionLimits {
    fn from(c: &scenario::Controller) -> Self {
        Self {
            t_min: c.t_min.unwrap_or(f64::NEG_INFINITY),
            t_max: c.t_max.unwrap_or(f64::INFINITY),
        }
    }
}

impl TensionLimits {
    /// The commanded tensions clamped to the limits, and whether either was clamped.
    #[inline]
    pub fn clamp(&self, tensions: [f64; 2]) -> ([f64; 2], bool) {
        let clamped = tensions.map(|t| t.clamp(self.t_min, self.t_max));
        (clamped, clamped != tensions)
    }
}

/// The structure matrix W = [u1 u2] at effector position `p` [m] with the pulleys at A1 = (0, 0)
/// and A2 = (d, 0): u_i the unit vector from the effector to pulley i, so that the cables pull
/// the effector with W [T1, T2]ᵀ (paper eq. 2–3 with massless cables).
pub fn structure_matrix(p: Vector2<f64>, anchor_distance: f64) -> Matrix2<f64> {
    let u1 = (Vector2::zeros() - p).normalize();
    let u2 = (Vector2::new(anchor_distance, 0.0) - p).normalize();
    Matrix2::from_columns(&[u1, u2])
}

/// Tensions [T1, T2] [N] with W [T1, T2]ᵀ = `force` [N] at effector position `p`: T = W⁻¹ f.
/// W is invertible while the effector is off the pulleys' line (z ≠ 0); on it, non-finite
/// tensions come back, which the runner refuses as it refuses slack.
///
/// # Examples
///
/// The effector hanging midway, 10 cm below the pulleys 1 m apart: each cable carries half the
/// weight over sin θ.
///
/// ```
/// use cdpr_core::Vector2;
/// use cdpr_core::controller::tensions_for_force;
///
/// let t = tensions_for_force(Vector2::new(0.5, -0.1), 1.0, Vector2::new(0.0, 9.81));
/// let sin = 0.1 / 0.5f64.hypot(0.1);
/// assert!((t[0] - 9.81 / (2.0 * sin)).abs() < 1e-9 && (t[0] - t[1]).abs() < 1e-9);
/// ```
pub fn tensions_for_force(p: Vector2<f64>, anchor_distance: f64, force: Vector2<f64>) -> [f64; 2] {
    let w = structure_matrix(p, anchor_distance);
    let det = w[(0, 0)] * w[(1, 1)] - w[(0, 1)] * w[(1, 0)];
    [
        (w[(1, 1)] * force.x - w[(0, 1)] * force.y) / det,
        (w[(0, 0)] * force.y - w[(1, 0)] * force.x) / det,
    ]
}

/// The geometric stiffness G = ∂(W T)/∂p = −Σ T_i (I − u_i u_iᵀ)/l_i [N/m] at fixed tensions:
/// how the cables' pull changes as the effector moves (MODELS.md §3's linearisation).
pub fn geometric_stiffness(
    p: Vector2<f64>,
    anchor_distance: f64,
    tensions: [f64; 2],
) -> Matrix2<f64> {
    let pulleys = [Vector2::zeros(), Vector2::new(anchor_distance, 0.0)];
    let mut g = Matrix2::zeros();
    for (a, t) in pulleys.iter().zip(tensions) {
        let chord = a - p;
        let l = chord.norm();
        let u = chord / l;
        g -= (Matrix2::identity() - u * u.transpose()) * (t / l);
    }
    g
}
