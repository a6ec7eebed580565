//! From a force on the effector to cable tensions: the paper's closed-form split of two opposed
//! cables with ΣT fixed (Pott et al. 2009), and the tension limits every controller obeys. (The
//! structure matrix that maps tensions to the force for any desired force is the robot's:
//! [`crate::robot::Robot::structure_matrix`].)

use crate::robot::distribution::{DistributionMethod, TensionBox, distribute_tensions};
use crate::robot::{Robot, StructureMatrix, Tensions, Vector, vertical};
use crate::scenario;

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
    /// The commanded tensions clamped to the limits, and whether any was clamped.
    #[inline]
    pub fn clamp(&self, tensions: &Tensions) -> (Tensions, bool) {
        // Compared cable by cable as each is clamped (a NaN counts as clamped): comparing the
        // whole inline array afterwards reads it back in wide loads just after its narrow
        // stores, a store-forwarding stall that was a fifth of the planar RHS.
        // Built as one array expression, so that the command it is copied into does not wait
        // on narrow stores either.
        let mut saturated = false;
        let clamped = Tensions::from_fn(tensions.len(), |i| {
            let c = tensions[i].clamp(self.t_min, self.t_max);
            saturated |= c != tensions[i];
            c
        });
        (clamped, saturated)
    }

    /// How far the farthest tension lies outside the limits [N] (≤ 0: all inside).
    pub fn excess(&self, tensions: &Tensions) -> f64 {
        tensions
            .iter()
            .map(|&t| (self.t_min - t).max(t - self.t_max))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// How a controller's force on the effector becomes m tensions (MODELS.md §11): W T = f solved
/// directly for a robot with as many cables as axes (the plane's 2 × 2 by its closed form), by
/// the scenario's distribution in the box [t_min, t_max] for a redundant robot. A distribution
/// that finds no tensions in the box still returns its best (the limits then clamp it and the
/// run counts the saturated time); a degenerate W gives NaN, which the runner refuses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensionSolver {
    pub method: DistributionMethod,
    pub limits: TensionBox,
}

impl From<&scenario::Controller> for TensionSolver {
    fn from(c: &scenario::Controller) -> Self {
        Self {
            method: c.distribution,
            limits: TensionBox {
                t_min: c.t_min.unwrap_or(0.0),
                t_max: c.t_max.unwrap_or(f64::INFINITY),
            },
        }
    }
}

impl TensionSolver {
    /// Tensions T with W(p) T = `force` [N].
    #[inline]
    pub fn for_force<const D: usize>(
        &self,
        robot: &Robot<D>,
        p: &Vector<D>,
        force: &Vector<D>,
    ) -> Tensions {
        self.for_force_with(&robot.structure_matrix(p), force)
    }

    /// [`TensionSolver::for_force`] with W at the effector already formed: W T = f directly
    /// where there are as many cables as axes, the distribution otherwise.
    #[inline]
    pub fn for_force_with<const D: usize>(
        &self,
        w: &StructureMatrix<D>,
        force: &Vector<D>,
    ) -> Tensions {
        if let Some(t) = w.tensions_for_force(force) {
            return t;
        }
        distribute_tensions(self.method, w, force, self.limits)
            .unwrap_or_else(|_| Tensions::from_fn(w.columns().len(), |_| f64::NAN))
    }

    /// Tensions that give the effector at `p` the acceleration `a` [m/s²] on rigid massless
    /// cables: W T = M (a − g⃗).
    #[inline]
    pub fn for_acceleration<const D: usize>(
        &self,
        robot: &Robot<D>,
        p: &Vector<D>,
        a: &Vector<D>,
    ) -> Tensions {
        let v = vertical::<D>();
        let mut lift = *a;
        lift[v] = a[v] + robot.gravity;
        self.for_force(robot, p, &(lift * robot.effector_mass))
    }
}
