//! One spring of a lumped cable along its path (MODELS.md §4 eq. 4), in the plane or in space:
//! its length, its rate and the unit vectors along which it pulls its two ends — over the pulley
//! for the straddling spring, along the chord for the others; and the cable's unstrained length
//! on the free side of its pulley.

use nalgebra::SVector;

/// Length λ of a spring with ends `a`, `b` along its path: over the pulley at `pulley` (eq. 4)
/// when it straddles it, else the chord ([`spring_path`] without the rate and directions, for
/// the energy and the output channels).
#[inline]
pub(crate) fn path_length<const D: usize>(
    (a, b): (SVector<f64, D>, SVector<f64, D>),
    pulley: Option<SVector<f64, D>>,
) -> f64 {
    match pulley {
        Some(pulley) => (pulley - a).norm() + (pulley - b).norm(),
        None => (b - a).norm(),
    }
}

/// Unstrained length between the pulley and the effector [m] of a cable of `springs` springs of
/// unstrained length `segment`, `stored` of its nodes behind the pulley at `pulley`: the free
/// springs plus the free-side share of the straddling spring (uniform strain along it), whose
/// stored and free ends are `straddling` (None when no node is stored).
#[inline]
pub(crate) fn free_length<const D: usize>(
    (springs, stored, segment): (usize, usize, f64),
    pulley: SVector<f64, D>,
    straddling: Option<(SVector<f64, D>, SVector<f64, D>)>,
) -> f64 {
    let free_springs = (springs - stored) as f64 * segment;
    let Some((behind, free)) = straddling else {
        return free_springs;
    };
    let length = path_length((behind, free), Some(pulley));
    free_springs + segment * (pulley - free).norm() / length
}

/// Length λ, rate λ̇ and the unit vectors along which a spring with ends `a`, `b` (velocities
/// `va`, `vb`) pulls them. Straddling the pulley at `pulley`, λ = |A − a| + |A − b| and both
/// ends are pulled toward A (eq. 4); otherwise the chord.
#[inline]
pub(crate) fn spring_path<const D: usize>(
    (a, b): (SVector<f64, D>, SVector<f64, D>),
    (va, vb): (SVector<f64, D>, SVector<f64, D>),
    pulley: Option<SVector<f64, D>>,
) -> (f64, f64, SVector<f64, D>, SVector<f64, D>) {
    if let Some(pulley) = pulley {
        let (da, db) = (pulley - a, pulley - b);
        let (la, lb) = (da.norm(), db.norm());
        // A node exactly at the pulley has no direction towards it; the limit of the path is
        // the direction to the spring's other end (a light cable can drive a node there).
        let toward = |d: SVector<f64, D>, l: f64, other: SVector<f64, D>| {
            if l > 0.0 { d / l } else { other.normalize() }
        };
        let (ua, ub) = (toward(da, la, b - a), toward(db, lb, a - b));
        (la + lb, -ua.dot(&va) - ub.dot(&vb), ua, ub)
    } else {
        let d = b - a;
        let l = d.norm();
        let u = d / l;
        (l, u.dot(&(vb - va)), u, -u)
    }
}
