//! The effector directions of modes that share an eigenvalue, chosen from the eigenspace rather
//! than from the eigen-solver's round-off.
//!
//! A controller with equal gains on every axis has its closed-loop modes in triples (one per
//! axis), and a robot symmetric about its vertical axis has its horizontal modes in pairs. Any
//! basis of such an eigenspace is a set of eigenvectors, and the solver returns whichever its
//! round-off gives: the directions read off them, and the names given by their dominant axis,
//! would be arbitrary mixtures. For a group of modes sharing λ this takes the span of their
//! effector motions (complex 3-vectors), and as its basis the projections onto it of the axes
//! x, y, z, the axis the span holds most of first (ties within 1e-6 in the order x, y, z), each
//! made orthogonal to the ones before. A group whose span is all of space thus gets exactly x,
//! y and z; members beyond the span's dimension have no effector motion of their own (the
//! controller's states alone). The choice depends on the eigenspace only, so not on the basis
//! the solver returned.

/// One complex number (re, im).
pub type Complex = (f64, f64);

/// Whether two eigenvalues λ = σ + iω, given as (σ, ω), are one: to 1e-6 of |λ|, far above a
/// dense eigen-solver's spread within a repeated eigenvalue (~1e-12 relative) and far below the
/// gap between distinct modes of a loop (percent).
pub fn same_eigenvalue((growth_a, omega_a): (f64, f64), (growth_b, omega_b): (f64, f64)) -> bool {
    let scale = 1e-6 * omega_a.hypot(growth_a);
    (omega_a - omega_b).abs() <= scale && (growth_a - growth_b).abs() <= scale
}

/// The groups of indices into `eigenvalues` ((σ, ω) each) that share their eigenvalue, each in
/// the list's order; every index is in exactly one group.
pub fn groups(eigenvalues: &[(f64, f64)]) -> Vec<Vec<usize>> {
    let mut grouped = vec![false; eigenvalues.len()];
    let mut out = Vec::new();
    for i in 0..eigenvalues.len() {
        if grouped[i] {
            continue;
        }
        let members: Vec<usize> = (i..eigenvalues.len())
            .filter(|&j| !grouped[j] && same_eigenvalue(eigenvalues[i], eigenvalues[j]))
            .collect();
        members.iter().for_each(|&j| grouped[j] = true);
        out.push(members);
    }
    out
}

/// A motion of the effector smaller than this [m, of a unit eigenvector] is none: the
/// directions' threshold for a mode of the controller's states alone.
const NO_MOTION: f64 = 1e-6;

/// The basis of the span of `motions` (the effector parts of one eigenspace's vectors) made of
/// the axes' projections, in the order above: unit complex 3-vectors, as many as the span has
/// dimensions.
pub fn axis_basis(motions: &[[Complex; 3]]) -> Vec<[Complex; 3]> {
    let span = orthonormal(motions.iter().copied());
    let mut basis: Vec<[Complex; 3]> = Vec::new();
    let mut left = [true; 3];
    while basis.len() < span.len() {
        // Each remaining axis's projection onto the span, less what the basis so far holds.
        let candidates: Vec<(usize, [Complex; 3], f64)> = (0..3)
            .filter(|&k| left[k])
            .map(|k| {
                let mut p = project_axis(&span, k);
                for q in &basis {
                    subtract_along(&mut p, q);
                }
                (k, p, norm(&p))
            })
            .collect();
        let longest = candidates.iter().map(|c| c.2).fold(0.0, f64::max);
        let Some((k, p, length)) = candidates.into_iter().find(|c| c.2 >= longest - 1e-6) else {
            break;
        };
        if length <= NO_MOTION {
            break;
        }
        left[k] = false;
        basis.push(p.map(|c| (c.0 / length, c.1 / length)));
    }
    basis
}

/// How much of each axis x, y, z the span of `motions` holds: the length of the unit axis
/// vector's projection onto it (1: the span contains the axis; 0: orthogonal to it).
pub fn axes_held(motions: &[[Complex; 3]]) -> [f64; 3] {
    let span = orthonormal(motions.iter().copied());
    std::array::from_fn(|k| norm(&project_axis(&span, k)))
}

/// An orthonormal basis of the span of `vectors` (Gram–Schmidt; a vector within 1e-6 of its
/// own length of the span so far, or one below [`NO_MOTION`], adds nothing).
fn orthonormal(vectors: impl Iterator<Item = [Complex; 3]>) -> Vec<[Complex; 3]> {
    let mut basis: Vec<[Complex; 3]> = Vec::new();
    for v in vectors {
        let length = norm(&v);
        let mut r = v;
        for q in &basis {
            subtract_along(&mut r, q);
        }
        let left = norm(&r);
        if length > NO_MOTION && left > 1e-6 * length {
            basis.push(r.map(|c| (c.0 / left, c.1 / left)));
        }
    }
    basis
}

/// The projection of the unit vector along axis `k` onto the span of the orthonormal `span`:
/// Σ_q q conj(q_k).
fn project_axis(span: &[[Complex; 3]], k: usize) -> [Complex; 3] {
    let mut p = [(0.0, 0.0); 3];
    for q in span {
        let (a, b) = (q[k].0, -q[k].1);
        for (pj, qj) in p.iter_mut().zip(q) {
            pj.0 += qj.0 * a - qj.1 * b;
            pj.1 += qj.0 * b + qj.1 * a;
        }
    }
    p
}

/// v ← v − q (q^H v) for a unit `q`.
fn subtract_along(v: &mut [Complex; 3], q: &[Complex; 3]) {
    // q^H v = Σ conj(q_j) v_j.
    let (mut re, mut im) = (0.0, 0.0);
    for (qj, vj) in q.iter().zip(v.iter()) {
        re += qj.0 * vj.0 + qj.1 * vj.1;
        im += qj.0 * vj.1 - qj.1 * vj.0;
    }
    for (vj, qj) in v.iter_mut().zip(q) {
        vj.0 -= qj.0 * re - qj.1 * im;
        vj.1 -= qj.0 * im + qj.1 * re;
    }
}

/// ‖v‖ of a complex 3-vector.
fn norm(v: &[Complex; 3]) -> f64 {
    v.iter().map(|c| c.0 * c.0 + c.1 * c.1).sum::<f64>().sqrt()
}
