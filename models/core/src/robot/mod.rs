//! The robot, knowing no cable model: the effector (a point mass M), the anchors A_i where each
//! of its m cables leaves its pulley towards the effector, gravity along −z, and the geometry
//! every controller and the massless-cable model share — each cable's length and direction
//! (eq. 3), the structure matrix W = [u_1 … u_m] that maps tensions to the force on the
//! effector (eq. 2), the geometric stiffness of taut cables, and the workspace. The dimension D
//! is a type parameter ([`space`]): the paper's robot is `Robot<2>` with anchors (0, 0) and
//! (d, 0).
//!
//! # Examples
//!
//! The paper's robot holding its effector midway, 0.1 m below the pulleys: the tensions that
//! balance the weight pull it along W.
//!
//! ```
//! use cdpr_core::robot::{Robot, Vector};
//!
//! let robot = Robot::<2>::new(&[Vector::<2>::new(0.0, 0.0), Vector::<2>::new(1.0, 0.0)], 1.0, 9.81)?;
//! let p = Vector::<2>::new(0.5, -0.1);
//! let t = robot.tensions_for_force(&p, &-robot.weight()).expect("two cables, two axes");
//! let held = robot.structure_matrix(&p).force(&t) + robot.weight();
//! assert!(held.norm() < 1e-12);
//! # Ok::<(), cdpr_core::robot::RobotError>(())
//! ```

pub mod cables;
pub mod distribution;
mod gram;
mod line_qp;
pub mod reels;
pub mod space;

pub use cables::{CableId, MAX_CABLES, PerCable, Tensions};

/// Most axes a robot has (space).
pub const MAX_AXES: usize = 3;
pub use space::{Matrix, Vector, along_vertical, axis_name, height, vertical};

/// Position and velocity of the effector (the point mass C of the paper) [m, m/s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effector<const D: usize> {
    pub position: Vector<D>,
    pub velocity: Vector<D>,
}

impl<const D: usize> Default for Effector<D> {
    fn default() -> Self {
        Self {
            position: Vector::zeros(),
            velocity: Vector::zeros(),
        }
    }
}

/// Why a robot's description was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RobotError {
    #[error("{0} anchors: a robot has 2 … {MAX_CABLES} cables")]
    Cables(usize),
    #[error("anchor {cable} = {value:?} is not finite")]
    NotFinite { cable: CableId, value: Vec<f64> },
    #[error(
        "effector_mass = {0} kg must be finite and > 0, gravity = {1} m/s² finite and ≥ 0 (0: a weightless test robot)"
    )]
    Weight(f64, f64),
}

/// The robot: anchors, effector mass and gravity. Copy: it holds its anchors inline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Robot<const D: usize> {
    anchors: [Vector<D>; MAX_CABLES],
    cables: usize,
    /// Effector mass M [kg].
    pub effector_mass: f64,
    /// Gravitational acceleration g [m/s²], along −z.
    pub gravity: f64,
}

/// One cable's straight chord from the effector to its anchor (eq. 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chord<const D: usize> {
    /// l_i = |A_i − p| [m].
    pub length: f64,
    /// u_i = (A_i − p)/l_i: the direction the cable pulls the effector.
    pub direction: Vector<D>,
}

/// The structure matrix W = [u_1 … u_m] at one effector position: each cable's unit vector from
/// the effector towards its anchor (eq. 2–3 with massless cables).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StructureMatrix<const D: usize> {
    columns: [Vector<D>; MAX_CABLES],
    cables: usize,
}

impl<const D: usize> StructureMatrix<D> {
    /// Column i, u_i.
    pub fn column(&self, i: usize) -> Vector<D> {
        self.columns[i]
    }

    /// The columns u_1 … u_m.
    pub fn columns(&self) -> &[Vector<D>] {
        &self.columns[..self.cables]
    }

    /// W T: the force the tensions `t` pull the effector with [N], summed from cable 1.
    pub fn force(&self, t: &[f64]) -> Vector<D> {
        let mut terms = self.columns().iter().zip(t);
        let Some((u, t0)) = terms.next() else {
            return Vector::zeros();
        };
        terms.fold(u * *t0, |f, (u, t)| f + u * *t)
    }

    /// (W Wᵀ)⁻¹, through which W⁺ = Wᵀ (W Wᵀ)⁻¹ maps a wrench to its least-norm tensions; None
    /// when the cables span fewer than D directions.
    pub fn gram_inverse(&self) -> Option<Matrix<D>> {
        gram::gram_inverse(self, &[true; MAX_CABLES][..self.cables])
    }

    /// W as a D × D matrix, for robots with as many cables as axes (None otherwise).
    pub fn square(&self) -> Option<Matrix<D>> {
        (self.cables == D).then(|| Matrix::from_fn(|r, c| self.columns[c][r]))
    }

    /// T = W⁻¹ f [N] for a robot with as many cables as axes (None for others), as
    /// [`Robot::tensions_for_force`] with W already formed.
    pub fn tensions_for_force(&self, force: &Vector<D>) -> Option<Tensions> {
        let w = self.square()?;
        if D == 2 {
            let det = w[(0, 0)] * w[(1, 1)] - w[(0, 1)] * w[(1, 0)];
            return Some(Tensions::pair([
                (w[(1, 1)] * force[0] - w[(0, 1)] * force[1]) / det,
                (w[(0, 0)] * force[1] - w[(1, 0)] * force[0]) / det,
            ]));
        }
        let t = w
            .try_inverse()
            .map_or_else(|| Vector::from_element(f64::NAN), |inv| inv * force);
        Some(Tensions::from_slice(t.as_slice()))
    }
}

impl<const D: usize> Robot<D> {
    /// The robot with cables from `anchors` [m] to an effector of `effector_mass` [kg] under
    /// `gravity` [m/s²].
    pub fn new(
        anchors: &[Vector<D>],
        effector_mass: f64,
        gravity: f64,
    ) -> Result<Self, RobotError> {
        if !(2..=MAX_CABLES).contains(&anchors.len()) {
            return Err(RobotError::Cables(anchors.len()));
        }
        if let Some((i, a)) = anchors
            .iter()
            .enumerate()
            .find(|(_, a)| !a.iter().all(|v| v.is_finite()))
        {
            return Err(RobotError::NotFinite {
                cable: CableId(i),
                value: a.iter().copied().collect(),
            });
        }
        if !(effector_mass.is_finite()
            && effector_mass > 0.0
            && gravity.is_finite()
            && gravity >= 0.0)
        {
            return Err(RobotError::Weight(effector_mass, gravity));
        }
        let mut stored = [Vector::zeros(); MAX_CABLES];
        stored[..anchors.len()].copy_from_slice(anchors);
        Ok(Self {
            anchors: stored,
            cables: anchors.len(),
            effector_mass,
            gravity,
        })
    }

    /// Number of cables m.
    pub fn cables(&self) -> usize {
        self.cables
    }

    /// The anchors A_1 … A_m [m].
    pub fn anchors(&self) -> &[Vector<D>] {
        &self.anchors[..self.cables]
    }

    /// Anchor A_i of cable i (0-based) [m].
    pub fn anchor(&self, i: usize) -> Vector<D> {
        self.anchors[i]
    }

    /// The effector's weight as a force, M g⃗ = (0, …, −M g) [N].
    pub fn weight(&self) -> Vector<D> {
        along_vertical(-self.effector_mass * self.gravity)
    }

    /// Cable i's chord from the effector at `p` to its anchor (eq. 3).
    #[inline]
    pub fn chord(&self, i: usize, p: &Vector<D>) -> Chord<D> {
        let to_anchor = self.anchors[i] - p;
        let length = to_anchor.norm();
        Chord {
            length,
            direction: to_anchor / length,
        }
    }

    /// W at effector position `p` [m].
    #[inline]
    pub fn structure_matrix(&self, p: &Vector<D>) -> StructureMatrix<D> {
        let mut columns = [Vector::zeros(); MAX_CABLES];
        for (i, column) in columns.iter_mut().enumerate().take(self.cables) {
            *column = unit(self.anchors[i] - p);
        }
        StructureMatrix {
            columns,
            cables: self.cables,
        }
    }

    /// The tensions with W T = `force` [N] at `p`, for a robot with as many cables as axes:
    /// T = W⁻¹ f (the plane's 2 × 2 by its closed form). None for other robots (they need a
    /// tension distribution). W is invertible while no two cables are collinear; on a
    /// degenerate pose non-finite tensions come back, which the runner refuses as it refuses
    /// slack.
    pub fn tensions_for_force(&self, p: &Vector<D>, force: &Vector<D>) -> Option<Tensions> {
        self.structure_matrix(p).tensions_for_force(force)
    }

    /// The geometric stiffness G = ∂(W T)/∂p = −Σ T_i (I − u_i u_iᵀ)/l_i [N/m] at fixed
    /// tensions: how the cables' pull changes as the effector moves.
    pub fn geometric_stiffness(&self, p: &Vector<D>, tensions: &[f64]) -> Matrix<D> {
        let mut g = Matrix::zeros();
        for (i, t) in tensions.iter().enumerate().take(self.cables) {
            let chord = self.chord(i, p);
            let u = chord.direction;
            g -= (Matrix::identity() - u * u.transpose()) * (t / chord.length);
        }
        g
    }

    /// Whether `p` lies in the workspace: below the highest anchor and, seen from above, inside
    /// the anchors' convex hull (the plane, and two cables in space: strictly between the
    /// pulleys and below them).
    pub fn in_workspace(&self, p: &Vector<D>) -> bool {
        let top = self
            .anchors()
            .iter()
            .map(height)
            .fold(f64::NEG_INFINITY, f64::max);
        if height(p) >= top || height(p).is_nan() {
            return false;
        }
        if D == 3 && self.cables == 2 {
            // Two cables in space (the paper's robot in a vertical plane): strictly between
            // the anchors along their line.
            let (a, b) = (self.anchors[0], self.anchors[1]);
            let s = (p - a).dot(&(b - a)) / (b - a).norm_squared();
            return s > 0.0 && s < 1.0;
        }
        match D {
            2 => {
                let xs = self.anchors().iter().map(|a| a[0]);
                let lo = xs.clone().fold(f64::INFINITY, f64::min);
                let hi = xs.fold(f64::NEG_INFINITY, f64::max);
                p[0] > lo && p[0] < hi
            }
            _ => inside_hull(self.anchors().iter().map(|a| [a[0], a[1]]), [p[0], p[1]]),
        }
    }
}

/// v/|v|. The plane divides each component by the length (the paper's bits); space multiplies
/// by the length's reciprocal, a third of the divisions (divisions and square roots bound a
/// spatial right-hand side).
#[inline]
fn unit<const D: usize>(v: Vector<D>) -> Vector<D> {
    if D == 2 {
        v / v.norm()
    } else {
        v * (1.0 / v.norm())
    }
}

/// Whether `q` lies strictly inside the convex hull of the points `points` in the plane.
fn inside_hull(points: impl Iterator<Item = [f64; 2]>, q: [f64; 2]) -> bool {
    let mut pts: Vec<[f64; 2]> = points.collect();
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup();
    if pts.len() < 3 {
        return false;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    // Andrew's monotone chain: the hull counter-clockwise.
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in [false, true] {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass {
            Box::new(pts.iter().rev())
        } else {
            Box::new(pts.iter())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull.len() >= 3 && (0..hull.len()).all(|k| cross(hull[k], hull[(k + 1) % hull.len()], q) > 0.0)
}
