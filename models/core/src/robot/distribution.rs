//! Tension distribution for redundantly actuated robots (MODELS.md §11): from the wrench w the
//! cables must supply and the box [t_min, t_max], the m tensions T with W T = w. The robot's
//! structure matrix W (D × m, m ≥ D) has m − D degrees of redundancy; each method picks one
//! solution and says whether it lies in the box and which cables it clamped.
//!
//! - closed form (Pott et al. 2009): T = T_m − W⁺(W T_m − w), T_m the box's middle;
//! - improved closed form (Pott 2014): clamp the worst violator, move its force into w, re-solve on
//!   the free cables;
//! - puncture: on T(s) = W⁺w + s (I − W⁺W) T_m the first s ∈ [0, 1] inside the box;
//! - QP: min ‖T‖² subject to W T = w and the box, solved exactly by a semismooth Newton method on
//!   its dual (each iterate's active set is that of clamp(Wᵀλ); the step is exact once the set is
//!   right) with a line search, and, should that not settle, enumeration of every active set;
//! - the margin: the largest s with W T = w and t_min + s ≤ T ≤ t_max − s (< 0: none exists).
//!
//! W⁺ = Wᵀ(WWᵀ)⁻¹ needs W of full row rank (the anchors not all in one plane through p, in 3-D).

use super::StructureMatrix;
use super::cables::{CableId, MAX_CABLES, Tensions};
use super::gram::gram_inverse;
use super::line_qp::qp_on_the_line;
use super::space::{Matrix, Vector};

/// A tension distribution method (`[controller] distribution`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum DistributionMethod {
    ClosedForm,
    ImprovedClosedForm,
    Puncture,
    Qp,
}

impl DistributionMethod {
    /// Every method, in the order of MODELS.md §11.
    pub const ALL: [DistributionMethod; 4] = [
        DistributionMethod::ClosedForm,
        DistributionMethod::ImprovedClosedForm,
        DistributionMethod::Puncture,
        DistributionMethod::Qp,
    ];

    /// The scenario file's spelling.
    pub fn name(self) -> &'static str {
        match self {
            DistributionMethod::ClosedForm => "closed-form",
            DistributionMethod::ImprovedClosedForm => "improved-closed-form",
            DistributionMethod::Puncture => "puncture",
            DistributionMethod::Qp => "qp",
        }
    }
}

/// Which end of the box a clamped cable was fixed at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Bound {
    Min,
    Max,
}

/// The cables a method fixed at a bound, in order: at most one per cable, held inline so that a
/// distribution on the right-hand side's path allocates nothing. Reads as a slice.
#[derive(Clone, Copy)]
pub struct Clamped {
    items: [(CableId, Bound); MAX_CABLES],
    len: usize,
}

impl Clamped {
    /// None clamped.
    pub const fn new() -> Self {
        Clamped {
            items: [(CableId(0), Bound::Min); MAX_CABLES],
            len: 0,
        }
    }

    /// Appends a cable (at most [`MAX_CABLES`]: one entry per cable).
    pub fn push(&mut self, item: (CableId, Bound)) {
        self.items[self.len] = item;
        self.len += 1;
    }
}

impl Default for Clamped {
    fn default() -> Self {
        Self::new()
    }
}

impl std::ops::Deref for Clamped {
    type Target = [(CableId, Bound)];
    fn deref(&self) -> &Self::Target {
        &self.items[..self.len]
    }
}

impl PartialEq for Clamped {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl std::fmt::Debug for Clamped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl FromIterator<(CableId, Bound)> for Clamped {
    fn from_iter<I: IntoIterator<Item = (CableId, Bound)>>(iter: I) -> Self {
        let mut c = Clamped::new();
        for item in iter {
            c.push(item);
        }
        c
    }
}

/// The tension box [t_min, t_max] every cable shares [N].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensionBox {
    pub t_min: f64,
    pub t_max: f64,
}

impl TensionBox {
    /// The box's middle T_m [N].
    pub fn middle(&self) -> f64 {
        0.5 * (self.t_min + self.t_max)
    }

    /// How far `t` lies outside the box [N] (≤ 0 inside).
    pub(super) fn violation(&self, t: f64) -> f64 {
        (self.t_min - t).max(t - self.t_max)
    }
}

/// A cable counts as outside the box when it is more than this beyond a bound [N]
/// (MODELS.md §11): round-off of W⁺ applied to kN wrenches is ~1e-12 N.
pub const BOX_TOLERANCE: f64 = 1e-9;

/// What a method found.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution {
    /// The tensions, in the robot's cable order [N]. Where the method found none in the box, the
    /// last solution it had (W T = w still holds where W had full rank).
    pub tensions: Tensions,
    /// All tensions within the box (to [`BOX_TOLERANCE`]).
    pub feasible: bool,
    /// The cables the method fixed at a bound, in clamping order (the improved closed form's;
    /// the QP's active set, cable order; empty for the others).
    pub clamped: Clamped,
}

/// Why no distribution could be computed at all.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DistributionError {
    #[error(
        "the structure matrix has rank below {axes}: the cables cannot supply a wrench in every direction at this pose"
    )]
    RankDeficient { axes: usize },
    #[error("wrench {wrench:?} N is not finite")]
    NotFinite { wrench: Vec<f64> },
    #[error("tension box [{t_min}, {t_max}] N: need finite t_min < t_max")]
    Box { t_min: f64, t_max: f64 },
}

/// Distributes `wrench` [N] over the cables of `w` by `method` within `limits`.
pub fn distribute<const D: usize>(
    method: DistributionMethod,
    w: &StructureMatrix<D>,
    wrench: &Vector<D>,
    limits: TensionBox,
) -> Result<Distribution, DistributionError> {
    check(wrench, limits)?;
    let m = w.columns().len();
    let all = [true; MAX_CABLES];
    match method {
        DistributionMethod::ClosedForm => {
            let tensions = closed_form(w, &all[..m], wrench, limits.middle())
                .ok_or(DistributionError::RankDeficient { axes: D })?;
            let feasible = inside(&tensions, limits);
            Ok(Distribution {
                tensions,
                feasible,
                clamped: Clamped::new(),
            })
        }
        DistributionMethod::ImprovedClosedForm => improved_closed_form(w, wrench, limits),
        DistributionMethod::Puncture => puncture(w, wrench, limits),
        DistributionMethod::Qp => qp(w, wrench, limits),
    }
}

/// The tensions of [`distribute`] alone, for a controller's right-hand side: the QP of one
/// degree of redundancy (Hangprinter) skips the bookkeeping of which cables it clamped.
pub fn distribute_tensions<const D: usize>(
    method: DistributionMethod,
    w: &StructureMatrix<D>,
    wrench: &Vector<D>,
    limits: TensionBox,
) -> Result<Tensions, DistributionError> {
    if method == DistributionMethod::Qp && w.columns().len() == D + 1 {
        check(wrench, limits)?;
        return qp_on_the_line(w, wrench, limits).map(|p| p.tensions);
    }
    distribute(method, w, wrench, limits).map(|d| d.tensions)
}

fn check<const D: usize>(wrench: &Vector<D>, limits: TensionBox) -> Result<(), DistributionError> {
    if !wrench.iter().all(|v| v.is_finite()) {
        return Err(DistributionError::NotFinite {
            wrench: wrench.iter().copied().collect(),
        });
    }
    if !(limits.t_min.is_finite() && limits.t_max.is_finite() && limits.t_min < limits.t_max) {
        return Err(DistributionError::Box {
            t_min: limits.t_min,
            t_max: limits.t_max,
        });
    }
    Ok(())
}

pub(super) fn inside(t: &Tensions, limits: TensionBox) -> bool {
    t.iter().all(|&v| limits.violation(v) <= BOX_TOLERANCE)
}

/// (W Wᵀ)⁻¹ over every cable; W of full row rank or the error.
fn full_gram_inverse<const D: usize>(
    w: &StructureMatrix<D>,
) -> Result<Matrix<D>, DistributionError> {
    w.gram_inverse()
        .ok_or(DistributionError::RankDeficient { axes: D })
}

/// The closed form on the free cables: T_i = T_m − u_iᵀ λ with (W_F W_Fᵀ) λ = W_F T_m − w
/// (cables not free keep nothing: the caller has moved their force into `wrench`).
fn closed_form<const D: usize>(
    w: &StructureMatrix<D>,
    free: &[bool],
    wrench: &Vector<D>,
    middle: f64,
) -> Option<Tensions> {
    let g_inv = gram_inverse(w, free)?;
    let mut residual = -wrench;
    for (u, _) in w.columns().iter().zip(free).filter(|(_, f)| **f) {
        residual += u * middle;
    }
    let lambda = g_inv * residual;
    let mut t = Tensions::from_fn(free.len(), |i| {
        if free[i] {
            middle - w.column(i).dot(&lambda)
        } else {
            0.0
        }
    });
    // One step of iterative refinement: with few free cables the Gram matrix can be poorly
    // conditioned, and W_F T_F − w would keep its round-off (seen: 9e-10 N at 1 kN tensions).
    let correction = g_inv * (wrench - w.force(&t));
    for (i, ti) in t.iter_mut().enumerate() {
        if free[i] {
            *ti += w.column(i).dot(&correction);
        }
    }
    Some(t)
}

/// Pott's improved closed form: while some cable is outside the box by more than
/// [`BOX_TOLERANCE`], fix the worst violator (a lower-bound violation wins a tie) at its bound,
/// move its force into the wrench and re-solve on the free cables; infeasible when fewer than D
/// cables remain free.
fn improved_closed_form<const D: usize>(
    w: &StructureMatrix<D>,
    wrench: &Vector<D>,
    limits: TensionBox,
) -> Result<Distribution, DistributionError> {
    let m = w.columns().len();
    let mut free = [true; MAX_CABLES];
    let mut fixed = Tensions::zeros(m);
    let mut remaining = *wrench;
    let mut clamped = Clamped::new();
    loop {
        let Some(solved) = closed_form(w, &free[..m], &remaining, limits.middle()) else {
            if clamped.is_empty() {
                return Err(DistributionError::RankDeficient { axes: D });
            }
            return Ok(Distribution {
                tensions: fixed,
                feasible: false,
                clamped,
            });
        };
        let tensions = Tensions::from_fn(m, |i| if free[i] { solved[i] } else { fixed[i] });
        let mut worst: Option<(usize, f64, bool)> = None;
        for i in (0..m).filter(|&i| free[i]) {
            let v = limits.violation(tensions[i]);
            let lower = tensions[i] < limits.t_min;
            let worse = match worst {
                None => true,
                Some((_, bv, bl)) => v > bv || (v == bv && lower && !bl),
            };
            if worse {
                worst = Some((i, v, lower));
            }
        }
        let Some((i, _, _)) = worst.filter(|&(_, v, _)| v > BOX_TOLERANCE) else {
            return Ok(Distribution {
                tensions,
                feasible: true,
                clamped,
            });
        };
        let (value, bound) = if tensions[i] < limits.t_min {
            (limits.t_min, Bound::Min)
        } else {
            (limits.t_max, Bound::Max)
        };
        free[i] = false;
        fixed[i] = value;
        remaining -= w.column(i) * value;
        clamped.push((CableId(i), bound));
        if free[..m].iter().filter(|f| **f).count() < D {
            return Ok(Distribution {
                tensions,
                feasible: false,
                clamped,
            });
        }
    }
}

/// The puncture method on T(s) = W⁺w + s (I − W⁺W) T_m: s = 0 if W⁺w is in the box, else the
/// smallest s ∈ [0, 1] at which every bound holds; infeasible when no s ∈ [0, 1] does.
fn puncture<const D: usize>(
    w: &StructureMatrix<D>,
    wrench: &Vector<D>,
    limits: TensionBox,
) -> Result<Distribution, DistributionError> {
    let m = w.columns().len();
    let g_inv = full_gram_inverse(w)?;
    let lambda = g_inv * wrench;
    let minimum_norm = Tensions::from_fn(m, |i| w.column(i).dot(&lambda));
    let closed = closed_form(w, &[true; MAX_CABLES][..m], wrench, limits.middle())
        .ok_or(DistributionError::RankDeficient { axes: D })?;
    // T(s) = a + s b, b = T(1) − T(0): each bound is an interval of s.
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for i in 0..m {
        let (a, b) = (minimum_norm[i], closed[i] - minimum_norm[i]);
        for (bound, sign) in [(limits.t_min, 1.0), (limits.t_max, -1.0)] {
            // sign (a + s b − bound) ≥ 0
            let (c, d) = (sign * (a - bound), sign * b);
            if d > 0.0 {
                lo = lo.max(-c / d);
            } else if d < 0.0 {
                hi = hi.min(-c / d);
            } else if c < 0.0 {
                hi = -1.0;
            }
        }
    }
    // The first s the bounds allow (exactly); within BOX_TOLERANCE of an empty interval it is
    // still accepted, as every method accepts.
    let s = if lo <= hi { lo } else { lo.min(1.0) };
    let tensions = Tensions::from_fn(m, |i| minimum_norm[i] + s * (closed[i] - minimum_norm[i]));
    let feasible = inside(&tensions, limits);
    Ok(Distribution {
        tensions,
        feasible,
        clamped: Clamped::new(),
    })
}

/// The QP min ½‖T‖² s.t. W T = w, t_min ≤ T ≤ t_max. Its dual is max_λ q(λ) = λᵀw − Σ φ(u_iᵀλ)
/// with φ the conjugate of the boxed square; for any λ the Lagrangian's minimiser is
/// T(λ) = clamp(Wᵀλ), so a λ with W T(λ) = w makes T(λ) the optimum (KKT hold by construction).
/// Newton on ∇q = w − W T(λ) with the free cables' Gram matrix and a backtracking line search;
/// if it does not settle (an infeasible problem's dual is unbounded), every active set is tried.
/// One degree of redundancy has its exact closed form (`line_qp`).
fn qp<const D: usize>(
    w: &StructureMatrix<D>,
    wrench: &Vector<D>,
    limits: TensionBox,
) -> Result<Distribution, DistributionError> {
    let m = w.columns().len();
    if m == D + 1 {
        return qp_on_the_line(w, wrench, limits).map(Distribution::from);
    }
    let g_inv = full_gram_inverse(w)?;
    let scale = wrench.norm() + limits.t_max.abs().max(limits.t_min.abs());
    let tol = 1e-13 * scale;
    let clamp = |z: f64| z.clamp(limits.t_min, limits.t_max);
    let tensions_at = |lambda: &Vector<D>| Tensions::from_fn(m, |i| clamp(w.column(i).dot(lambda)));
    let gradient = |t: &Tensions| wrench - w.force(t);
    let dual = |lambda: &Vector<D>| {
        let phi: f64 = (0..m)
            .map(|i| {
                let z = w.column(i).dot(lambda);
                let t = clamp(z);
                z * t - 0.5 * t * t
            })
            .sum();
        lambda.dot(wrench) - phi
    };
    let mut lambda = g_inv * wrench;
    for _ in 0..50 {
        let t = tensions_at(&lambda);
        let g = gradient(&t);
        if g.norm() <= tol {
            return Ok(qp_result(w, &lambda, t, limits));
        }
        let free: [bool; MAX_CABLES] = std::array::from_fn(|i| {
            i < m && {
                let z = w.column(i).dot(&lambda);
                z > limits.t_min && z < limits.t_max
            }
        });
        let Some(hessian_inv) = gram_inverse(w, &free[..m]) else {
            break;
        };
        let step = hessian_inv * g;
        let q0 = dual(&lambda);
        let slope = g.dot(&step);
        let mut alpha = 1.0;
        while alpha > 1e-12 && dual(&(lambda + step * alpha)) < q0 + 1e-4 * alpha * slope {
            alpha *= 0.5;
        }
        lambda += step * alpha;
    }
    Ok(qp_by_enumeration(w, wrench, limits, tol))
}

fn qp_result<const D: usize>(
    w: &StructureMatrix<D>,
    lambda: &Vector<D>,
    tensions: Tensions,
    limits: TensionBox,
) -> Distribution {
    let clamped = (0..tensions.len())
        .filter_map(|i| {
            let z = w.column(i).dot(lambda);
            if z <= limits.t_min {
                Some((CableId(i), Bound::Min))
            } else if z >= limits.t_max {
                Some((CableId(i), Bound::Max))
            } else {
                None
            }
        })
        .collect();
    Distribution {
        tensions,
        feasible: true,
        clamped,
    }
}

/// Every active set (each cable free, at t_min or at t_max; 3^m ≤ 6561): the free cables'
/// tensions T_F = W_Fᵀλ with (W_F W_Fᵀ) λ = w − W_A T_A, accepted when T_F lies in the box and
/// each fixed cable's u_iᵀλ lies beyond its bound (the KKT conditions). None accepted: no
/// distribution exists; the minimum-norm solution W⁺w is returned, infeasible.
fn qp_by_enumeration<const D: usize>(
    w: &StructureMatrix<D>,
    wrench: &Vector<D>,
    limits: TensionBox,
    tol: f64,
) -> Distribution {
    let m = w.columns().len();
    for code in 0..3usize.pow(m as u32) {
        let state: [u8; MAX_CABLES] = std::array::from_fn(|i| {
            if i < m {
                (code / 3usize.pow(i as u32) % 3) as u8
            } else {
                0
            }
        });
        let free: [bool; MAX_CABLES] = std::array::from_fn(|i| i < m && state[i] == 0);
        let mut rhs = *wrench;
        for i in (0..m).filter(|&i| !free[i]) {
            let value = if state[i] == 1 {
                limits.t_min
            } else {
                limits.t_max
            };
            rhs -= w.column(i) * value;
        }
        let Some(g_inv) = gram_inverse(w, &free[..m]) else {
            continue;
        };
        // One step of iterative refinement: an ill-conditioned free set's inverse leaves
        // W_F W_Fᵀ λ = rhs to ~cond·ε, the residual's correction takes it to round-off.
        let mut lambda = g_inv * rhs;
        let mut residual = rhs;
        for i in (0..m).filter(|&i| free[i]) {
            residual -= w.column(i) * w.column(i).dot(&lambda);
        }
        lambda += g_inv * residual;
        let consistent = (0..m).all(|i| {
            let z = w.column(i).dot(&lambda);
            match state[i] {
                0 => z >= limits.t_min - tol && z <= limits.t_max + tol,
                1 => z <= limits.t_min + tol,
                _ => z >= limits.t_max - tol,
            }
        });
        if consistent {
            let tensions = Tensions::from_fn(m, |i| match state[i] {
                0 => w.column(i).dot(&lambda),
                1 => limits.t_min,
                _ => limits.t_max,
            });
            let mut result = qp_result(w, &lambda, tensions, limits);
            result.clamped = (0..m)
                .filter(|&i| state[i] != 0)
                .map(|i| {
                    (
                        CableId(i),
                        if state[i] == 1 {
                            Bound::Min
                        } else {
                            Bound::Max
                        },
                    )
                })
                .collect();
            return result;
        }
    }
    let all = [true; MAX_CABLES];
    let tensions = closed_form(w, &all[..m], wrench, 0.0).unwrap_or_else(|| Tensions::zeros(m));
    Distribution {
        tensions,
        feasible: false,
        clamped: Clamped::new(),
    }
}

/// The largest uniform margin s [N]: W T = w with t_min + s ≤ T ≤ t_max − s for some T; negative
/// where no distribution in the box exists. Bisection on s with the QP's exact feasibility, to
/// 1e-9 N (the LP's optimum lies within that of the returned value).
pub fn margin<const D: usize>(
    w: &StructureMatrix<D>,
    wrench: &Vector<D>,
    limits: TensionBox,
) -> Result<f64, DistributionError> {
    check(wrench, limits)?;
    let feasible = |s: f64| -> Result<bool, DistributionError> {
        let shrunk = TensionBox {
            t_min: limits.t_min + s,
            t_max: limits.t_max - s,
        };
        Ok(qp(w, wrench, shrunk)?.feasible)
    };
    let half = 0.5 * (limits.t_max - limits.t_min);
    // s < half keeps the box non-empty; below, widen until feasible (W has full rank, so a wide
    // enough box holds any wrench).
    let mut hi = half * (1.0 - 1e-12);
    if feasible(hi)? {
        return Ok(hi);
    }
    let mut lo = 0.0;
    let mut width = half.max(1.0);
    while !feasible(lo)? {
        hi = lo;
        lo -= width;
        width *= 2.0;
        if lo < -1e12 {
            return Ok(f64::NEG_INFINITY);
        }
    }
    while hi - lo > BOX_TOLERANCE {
        let mid = 0.5 * (lo + hi);
        if feasible(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(lo)
}
