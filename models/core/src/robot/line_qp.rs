//! The exact QP min ‖T‖² s.t. W T = w and the box for a robot with one degree of redundancy
//! (m = D + 1: Hangprinter's four cables in space), without iterating and without the Gram
//! matrix: the null vector of W from its maximal minors and the least-norm tensions from one
//! square sub-system, then the point of the solution line nearest the least-norm one.

use super::StructureMatrix;
use super::cables::{CableId, MAX_CABLES, Tensions};
use super::distribution::{BOX_TOLERANCE, Bound, Distribution, DistributionError};
use super::distribution::{TensionBox, inside};
use super::space::Vector;

/// The QP's answer on the line: the tensions, whether they lie in the box, and the cable it put
/// on a bound (the lean form a controller's right-hand side takes; [`Distribution`] adds the
/// list of clamped cables).
pub(super) struct LinePoint {
    pub tensions: Tensions,
    pub feasible: bool,
    pub on_bound: Option<(CableId, Bound)>,
}

impl From<LinePoint> for Distribution {
    fn from(p: LinePoint) -> Self {
        Distribution {
            tensions: p.tensions,
            feasible: p.feasible,
            clamped: p.on_bound.into_iter().collect(),
        }
    }
}

/// The QP on the line of solutions T(s) = W⁺w + s n (n a null vector of W; W⁺w ⟂ n, so
/// ‖T(s)‖² = ‖W⁺w‖² + s² ‖n‖² is least at the s of the box's interval [s_lo, s_hi] nearest 0).
///
/// n_i = (−1)^i det W_{−i} (W without column i): Σ_i n_i u_i is the expansion of a
/// (D+1) × (D+1) determinant with a repeated row, so W n = 0, and ‖n‖² = det(W Wᵀ)
/// (Cauchy–Binet). A particular solution comes from the square system without the column k of
/// the largest |n_k| (the best-conditioned one: the projector I − W⁺W's largest diagonal
/// n_k²/‖n‖²) by Cramer's rule, and W⁺w is it with its component along n removed. An empty
/// interval: no distribution; W⁺w is returned, infeasible.
pub(super) fn qp_on_the_line<const D: usize>(
    w: &StructureMatrix<D>,
    wrench: &Vector<D>,
    limits: TensionBox,
) -> Result<LinePoint, DistributionError> {
    // m = D + 1 as a constant (the callers' precondition): the loops over the cables unroll.
    let m = D + 1;
    debug_assert_eq!(w.columns().len(), m, "one degree of redundancy");
    let u = &w.columns()[..m];
    let null = Tensions::from_fn(m, |i| {
        let minor = determinant(&without(u, i, None));
        if i % 2 == 0 { minor } else { -minor }
    });
    let norm2 = null.dot(&null);
    // Full row rank: det(W Wᵀ) above 1e-12 m^D (then W Wᵀ's least eigenvalue exceeds
    // 1e-12 m, the Cholesky rank test of the other methods, since none exceeds m).
    if norm2.is_nan() || norm2 <= 1e-12 * (m as f64).powi(D as i32) {
        return Err(DistributionError::RankDeficient { axes: D });
    }
    let k = (0..m)
        .map(|i| (i, null[i].abs()))
        .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a })
        .0;
    // Cramer's rule on B = W_{−k}, det B = (−1)^k n_k: x_j = det(B with column j ← w) / det B,
    // with the one division 1/(det B ‖n‖²) serving both it and the projection.
    let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
    let per_det_norm2 = sign / (null[k] * norm2);
    let per_det = per_det_norm2 * norm2;
    let x: [f64; D] = std::array::from_fn(|j| determinant(&without(u, k, Some((j, wrench)))));
    let cramer = Tensions::from_fn(m, |i| match i.cmp(&k) {
        std::cmp::Ordering::Less => x[i],
        std::cmp::Ordering::Equal => 0.0,
        std::cmp::Ordering::Greater => x[i - 1],
    });
    let along = cramer.dot(&null) * per_det_norm2;
    let minimum_norm = Tensions::from_fn(m, |i| cramer[i] * per_det - along * null[i]);
    Ok(nearest_on_the_line(m, &minimum_norm, &null, limits))
}

/// det [c_1 … c_D] by its closed form: the plane's 2 × 2, space's triple product
/// c_1 · (c_2 × c_3) (the only dimensions a robot has; another D does not compile).
fn determinant<const D: usize>(c: &[Vector<D>; D]) -> f64 {
    const { assert!(D == 2 || D == 3, "a robot's space has 2 or 3 axes") };
    if D == 2 {
        return c[0][0] * c[1][1] - c[1][0] * c[0][1];
    }
    c[0][0] * (c[1][1] * c[2][2] - c[2][1] * c[1][2])
        - c[1][0] * (c[0][1] * c[2][2] - c[2][1] * c[0][2])
        + c[2][0] * (c[0][1] * c[1][2] - c[1][1] * c[0][2])
}

/// The D columns of `u` (D + 1 of them) without column `skip`, column j replaced by the given
/// vector where one is given.
fn without<const D: usize>(
    u: &[Vector<D>],
    skip: usize,
    replace: Option<(usize, &Vector<D>)>,
) -> [Vector<D>; D] {
    std::array::from_fn(|j| match replace {
        Some((r, v)) if r == j => *v,
        _ => u[if j < skip { j } else { j + 1 }],
    })
}

/// The point of the line T(s) = `minimum_norm` + s `null` (`m` cables) inside the box with
/// the least |s|, the cable that sets s put exactly on its bound. `null` need not be a unit
/// vector: T(s) is the same point whatever its length, and a cable whose share of it is below
/// 1e-14 of its length does not move along the line. Inlined, so that `m` is the caller's
/// constant.
#[inline]
fn nearest_on_the_line(
    m: usize,
    minimum_norm: &Tensions,
    null: &Tensions,
    limits: TensionBox,
) -> LinePoint {
    let level = 1e-14 * null.dot(null).sqrt();
    // Cable i keeps T_i in the box for s in [from_i, to_i] (all s where it does not move).
    // Written as selects and min/max, so the interval [lo, hi] is found without the branches
    // an integrator's changing wrenches mispredict.
    let (mut from, mut to) = ([f64::NEG_INFINITY; MAX_CABLES], [f64::INFINITY; MAX_CABLES]);
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..m {
        let (t, n) = (minimum_norm[i], null[i]);
        let per_s = 1.0 / n;
        let (a, b) = ((limits.t_min - t) * per_s, (limits.t_max - t) * per_s);
        (from[i], to[i]) = match (n.abs() >= level, n > 0.0) {
            (false, _) => (f64::NEG_INFINITY, f64::INFINITY),
            (true, true) => (a, b),
            (true, false) => (b, a),
        };
        lo = lo.max(from[i]);
        hi = hi.min(to[i]);
    }
    let still_outside =
        |i: usize| null[i].abs() < level && limits.violation(minimum_norm[i]) > BOX_TOLERANCE;
    if lo > hi || (0..m).any(still_outside) {
        return LinePoint {
            feasible: inside(minimum_norm, limits),
            tensions: *minimum_norm,
            on_bound: None,
        };
    }
    let s = 0.0f64.clamp(lo, hi);
    // The first cable that sets the end `s` lies on (the upper end or the lower). T_i grows
    // with s where n_i > 0: the lower end is then cable i's t_min, the upper its t_max; the
    // other way round where n_i < 0.
    let setting = |upper: bool| {
        let end = if upper { hi } else { lo };
        (0..m)
            .find(|&i| (if upper { to[i] } else { from[i] }) == end)
            .map(|i| (i, (null[i] > 0.0) == upper))
    };
    let on_max = if s == lo && lo > f64::NEG_INFINITY {
        setting(false)
    } else if s == hi && hi < f64::INFINITY {
        setting(true)
    } else {
        None
    };
    // That cable sits exactly on its bound (not an ulp past it, which a clamp downstream
    // would count as saturation).
    let (cable, bound) = match on_max {
        Some((cable, true)) => (cable, limits.t_max),
        Some((cable, false)) => (cable, limits.t_min),
        None => (usize::MAX, 0.0),
    };
    let tensions = Tensions::from_fn(m, |i| {
        if i == cable {
            bound
        } else {
            minimum_norm[i] + s * null[i]
        }
    });
    let on_bound = on_max.map(|(i, max)| (CableId(i), if max { Bound::Max } else { Bound::Min }));
    LinePoint {
        feasible: inside(&tensions, limits),
        tensions,
        on_bound,
    }
}
