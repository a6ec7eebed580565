//! Eigenpairs of a large symmetric matrix nearest a shift, by shift-invert Lanczos (Ericsson &
//! Ruhe 1980; Saad, *Numerical Methods for Large Eigenvalue Problems*, 2011, §4.4 and §8.1):
//! the Krylov space of B = (A − σ I)⁻¹, whose largest |θ| are A's eigenvalues λ = σ + 1/θ
//! nearest σ. The operator is given only through its solve y ↦ B y (a sparse factorisation of
//! A − σ I), so the cost is one factorisation and a few tens of solves at any size. Every new
//! Lanczos vector is reorthogonalised against all earlier ones (full reorthogonalisation: the
//! basis stays orthonormal to round-off, no ghost copies of converged pairs), which costs
//! O(n k²) for k steps — negligible next to the solves at the k ≲ 100 used here.

use faer::{Mat, Side};

/// One eigenpair of A.
#[derive(Debug, Clone, PartialEq)]
pub struct RitzPair {
    /// The eigenvalue λ = σ + 1/θ.
    pub value: f64,
    /// The unit eigenvector.
    pub vector: Vec<f64>,
    /// The Lanczos residual |β_k s_k| of the pair in B, ‖B x − θ x‖ (an upper bound on
    /// |θ_true − θ| for the symmetric B).
    pub residual: f64,
}

/// Why the iteration failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LanczosError {
    #[error("the tridiagonal eigen-decomposition failed")]
    Tridiagonal,
    #[error("asked for {count} pairs of an operator of order {n}")]
    Count { count: usize, n: usize },
}

/// The `count` eigenpairs of the symmetric n × n matrix A nearest `shift` σ, from at most
/// `steps` Lanczos steps with B = (A − σ I)⁻¹ applied by `solve` (writes B y into its second
/// argument), sorted by eigenvalue. The start vector is a fixed pseudo-random one, so the same
/// inputs give the same pairs bit for bit.
pub fn nearest(
    n: usize,
    shift: f64,
    count: usize,
    steps: usize,
    mut solve: impl FnMut(&[f64], &mut [f64]),
) -> Result<Vec<RitzPair>, LanczosError> {
    if count == 0 || count > n {
        return Err(LanczosError::Count { count, n });
    }
    let steps = steps.clamp(count, n);
    let mut basis: Vec<Vec<f64>> = Vec::with_capacity(steps + 1);
    let mut start: Vec<f64> = (0..n)
        .map(|i| ((i as f64 + 1.0) * 0.618_033_988_749_894_9).fract() - 0.5)
        .collect();
    normalise(&mut start);
    basis.push(start);
    let (mut alpha, mut beta) = (Vec::with_capacity(steps), Vec::with_capacity(steps));
    let mut w = vec![0.0; n];
    for k in 0..steps {
        solve(&basis[k], &mut w);
        let a = dot(&w, &basis[k]);
        alpha.push(a);
        // Full reorthogonalisation, twice (Kahan's "twice is enough").
        for _ in 0..2 {
            for v in &basis {
                let c = dot(&w, v);
                w.iter_mut().zip(v).for_each(|(w, v)| *w -= c * v);
            }
        }
        let b = dot(&w, &w).sqrt();
        beta.push(b);
        if b <= 1e-14 * a.abs().max(f64::MIN_POSITIVE) || k + 1 == steps {
            break;
        }
        basis.push(w.iter().map(|v| v / b).collect());
    }
    let k = alpha.len();
    let tridiagonal = Mat::from_fn(k, k, |i, j| {
        if i == j {
            alpha[i]
        } else if i + 1 == j {
            beta[i]
        } else if j + 1 == i {
            beta[j]
        } else {
            0.0
        }
    });
    let evd = tridiagonal
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| LanczosError::Tridiagonal)?;
    let (theta, s) = (evd.S().column_vector(), evd.U());
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&i, &j| theta[j].abs().total_cmp(&theta[i].abs()));
    let last = beta[k - 1];
    let mut pairs: Vec<RitzPair> = order
        .into_iter()
        .take(count.min(k))
        .map(|j| {
            let mut vector = vec![0.0; n];
            for (i, v) in basis.iter().take(k).enumerate() {
                let c = s[(i, j)];
                vector.iter_mut().zip(v).for_each(|(x, v)| *x += c * v);
            }
            normalise(&mut vector);
            RitzPair {
                value: shift + 1.0 / theta[j],
                vector,
                residual: (last * s[(k - 1, j)]).abs(),
            }
        })
        .collect();
    pairs.sort_by(|a, b| a.value.total_cmp(&b.value));
    Ok(pairs)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

fn normalise(v: &mut [f64]) {
    let norm = dot(v, v).sqrt();
    v.iter_mut().for_each(|x| *x /= norm);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The path graph's Laplacian (the fixed–fixed string) has λ_j = 2 − 2 cos(jπ/(n+1)):
    /// the four nearest 1.0 of n = 400, by solves with the dense inverse of A − σ I.
    #[test]
    fn the_string_laplacians_eigenvalues_nearest_a_shift() {
        let n = 400;
        let shift = 1.0;
        let a = Mat::from_fn(n, n, |i, j| {
            if i == j {
                2.0 - shift
            } else if i.abs_diff(j) == 1 {
                -1.0
            } else {
                0.0
            }
        });
        let lu = a.partial_piv_lu();
        let solve = |y: &[f64], out: &mut [f64]| {
            let rhs = Mat::from_fn(n, 1, |i, _| y[i]);
            let x = faer::linalg::solvers::Solve::solve(&lu, &rhs);
            for i in 0..n {
                out[i] = x[(i, 0)];
            }
        };
        let pairs = nearest(n, shift, 4, 80, solve).unwrap();
        let mut exact: Vec<f64> = (1..=n)
            .map(|j| 2.0 - 2.0 * (j as f64 * std::f64::consts::PI / (n as f64 + 1.0)).cos())
            .collect();
        exact.sort_by(|a, b| (a - shift).abs().total_cmp(&(b - shift).abs()));
        let mut nearest4 = exact[..4].to_vec();
        nearest4.sort_by(f64::total_cmp);
        for (p, e) in pairs.iter().zip(&nearest4) {
            assert!((p.value - e).abs() <= 1e-10, "{} against {e}", p.value);
        }
    }
}
