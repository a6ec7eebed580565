//! A damped spring's end-force derivatives for the implicit path's analytic iteration matrix, in
//! the plane and in space: with eq. 5's T = k0 (λ − l0) + c λ̇ (c = C/l0; 0 while slack or
//! clipped), the rate λ̇ depends on the positions through the spring's direction, which makes
//! the blocks unsymmetric, and the forces depend on the velocities.
//! - A chord, u = (b − a)/λ, P = I − u uᵀ, w = P (v_b − v_a)/λ = ∂λ̇/∂b:
//!   ∂F_a/∂b = u (k0 u + c w)ᵀ + (T/λ) P = −∂F_a/∂a = ∂F_b/∂a = −∂F_b/∂b, and
//!   ∂F_a/∂v_b = c u uᵀ with the same signs.
//! - The straddling spring pulls each end toward the pulley A (eq. 4), u_a = (A − a)/|A − a|,
//!   λ̇ = −u_a·v_a − u_b·v_b, g_a = ∂T/∂a = −k0 u_a + c P_a v_a/|A − a|:
//!   ∂F_a/∂a = u_a g_aᵀ − (T/|A − a|) P_a, ∂F_a/∂b = u_a g_bᵀ, and ∂F_a/∂v_b = −c u_a u_bᵀ.
//!
//! Undamped springs have their own blocks ([`undamped_blocks`]: the same derivatives with c = 0,
//! computed as they always were, so undamped runs stay the same to the bit). Both models, the
//! planar one and the spatial one, take their blocks here.

use crate::spring_tension;
use cdpr_numerics::differences::CBRT_EPSILON;
use nalgebra::{SMatrix, SVector};

/// A spring's end-force derivatives in the order (a, a), (a, b), (b, a), (b, b): by position
/// [N/m], and by velocity [N s/m] for a damped spring.
pub(crate) struct SpringBlocks<const D: usize> {
    pub(crate) position: [SMatrix<f64, D, D>; 4],
    pub(crate) rate: Option<[SMatrix<f64, D, D>; 4]>,
}

/// A straddling spring's end sits exactly at its pulley, where its direction is undefined.
pub(crate) struct AtPulley;

/// The blocks of a damped spring with ends `ends` = [(a, v_a), (b, v_b)], over `pulley` if it
/// straddles one, of stiffness, segment and damping (k0, l0, c); None while it pulls nothing.
pub(crate) fn damped_blocks<const D: usize>(
    [(a, va), (b, vb)]: [(SVector<f64, D>, SVector<f64, D>); 2],
    pulley: Option<SVector<f64, D>>,
    (k, l0, c): (f64, f64, f64),
) -> Result<Option<SpringBlocks<D>>, AtPulley> {
    let identity = SMatrix::<f64, D, D>::identity();
    let Some(pulley) = pulley else {
        let d = b - a;
        let length = d.norm();
        if length <= l0 {
            return Ok(None);
        }
        let u = d / length;
        let dv = vb - va;
        let t = spring_tension(k, l0, c, length, u.dot(&dv));
        if t <= 0.0 {
            return Ok(None);
        }
        let along = u * u.transpose();
        let across = identity - along;
        let w = across * dv / length;
        let g = u * (u * k + w * c).transpose() + across * (t / length);
        let d = along * c;
        return Ok(Some(SpringBlocks {
            position: [-g, g, g, -g],
            rate: Some([-d, d, d, -d]),
        }));
    };
    let (da, db) = (pulley - a, pulley - b);
    let (la, lb) = (da.norm(), db.norm());
    if la == 0.0 || lb == 0.0 {
        return Err(AtPulley);
    }
    if la + lb <= l0 {
        return Ok(None);
    }
    let (ua, ub) = (da / la, db / lb);
    let t = spring_tension(k, l0, c, la + lb, -ua.dot(&va) - ub.dot(&vb));
    if t <= 0.0 {
        return Ok(None);
    }
    let (across_a, across_b) = (
        identity - ua * ua.transpose(),
        identity - ub * ub.transpose(),
    );
    let ga = -ua * k + across_a * va * (c / la);
    let gb = -ub * k + across_b * vb * (c / lb);
    Ok(Some(SpringBlocks {
        position: [
            ua * ga.transpose() - across_a * (t / la),
            ua * gb.transpose(),
            ub * ga.transpose(),
            ub * gb.transpose() - across_b * (t / lb),
        ],
        rate: Some([
            -ua * ua.transpose() * c,
            -ua * ub.transpose() * c,
            -ub * ua.transpose() * c,
            -ub * ub.transpose() * c,
        ]),
    }))
}

/// The blocks of an undamped spring from `a` to `b`, over `pulley` if it straddles one, of
/// stiffness and segment (k0, l0); None while slack. A taut chord's ∂F_a/∂b = k u uᵀ +
/// (T/λ)(I − u uᵀ); the straddling spring's ∂F_a/∂a = −k u_a u_aᵀ − (T/|A − a|)(I − u_a u_aᵀ),
/// ∂F_a/∂b = −k u_a u_bᵀ.
pub(crate) fn undamped_blocks<const D: usize>(
    (a, b): (SVector<f64, D>, SVector<f64, D>),
    pulley: Option<SVector<f64, D>>,
    (k, l0): (f64, f64),
) -> Result<Option<SpringBlocks<D>>, AtPulley> {
    let identity = SMatrix::<f64, D, D>::identity();
    let outer = |u: SVector<f64, D>, w: SVector<f64, D>| u * w.transpose();
    let Some(pulley) = pulley else {
        let d = b - a;
        let length = d.norm();
        let stretch = length - l0;
        if stretch <= 0.0 {
            return Ok(None);
        }
        let u = d / length;
        let along = outer(u, u);
        let tangent = along * k + (identity - along) * (k * stretch / length);
        return Ok(Some(SpringBlocks {
            position: [-tangent, tangent, tangent, -tangent],
            rate: None,
        }));
    };
    let (da, db) = (pulley - a, pulley - b);
    let (la, lb) = (da.norm(), db.norm());
    if la == 0.0 || lb == 0.0 {
        return Err(AtPulley);
    }
    let stretch = la + lb - l0;
    if stretch <= 0.0 {
        return Ok(None);
    }
    let t = k * stretch;
    let (ua, ub) = (da / la, db / lb);
    let across_a = (identity - outer(ua, ua)) * (t / la);
    let across_b = (identity - outer(ub, ub)) * (t / lb);
    Ok(Some(SpringBlocks {
        position: [
            -outer(ua, ua) * k - across_a,
            -outer(ua, ub) * k,
            -outer(ub, ua) * k,
            -outer(ub, ub) * k - across_b,
        ],
        rate: None,
    }))
}

/// How far a spring's ends may move with its force smooth [m]: a quarter of its |stretch| s =
/// λ − l0 (the tension-only kink) and, for a damped taut spring that stretches or shortens, of
/// the distance |k0 s + c λ̇|/k0 to the damping's clip at T = 0 (at rest that is s itself).
pub(crate) fn smooth_reach((k, l0, c): (f64, f64, f64), length: f64, rate: f64) -> f64 {
    let stretch = length - l0;
    let reach = 0.25 * stretch.abs();
    if c == 0.0 || rate == 0.0 || stretch <= 0.0 {
        return reach;
    }
    reach.min(0.25 * ((k * stretch + c * rate) / k).abs())
}

/// The reach ([`smooth_reach`]) of a chain's spring and, where it straddles a pulley (`straddle`:
/// the pulley and the spring's two ends), at most ε^(1/3) of each end's distance d to it: the
/// path's direction turns on the scale d (truncation (δ/d)² ≈ 4e-11).
pub(crate) fn chain_reach<const D: usize>(
    spring: (f64, f64, f64),
    (length, rate): (f64, f64),
    straddle: Option<(SVector<f64, D>, [SVector<f64, D>; 2])>,
) -> f64 {
    let mut limit = smooth_reach(spring, length, rate);
    if let Some((pulley, ends)) = straddle {
        for end in ends {
            limit = limit.min(CBRT_EPSILON * (end - pulley).norm());
        }
    }
    limit
}
