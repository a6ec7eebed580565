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
    solve: impl FnMut(&[f64], &mut [f64]),
) -> Result<Vec<RitzPair>, LanczosError> {
    nearest_with_mass(n, shift, count, steps, solve, |v, out| {
        out.copy_from_slice(v)
    })
}

/// The generalised problem K x = λ M x (K symmetric, M symmetric positive definite) by the same
/// iteration in the M inner product ⟨a, b⟩ = aᵀ M b, in which B = (K − σ M)⁻¹ M is
/// self-adjoint (Ericsson & Ruhe 1980): `solve` writes B y, `mass` writes M v. Each basis
/// vector keeps its M v, so the reorthogonalisation costs O(n k²) as in the standard case. The
/// vectors come M-normalised (xᵀ M x = 1); with M = I this is [`nearest`] to the bit.
pub fn nearest_with_mass(
    n: usize,
    shift: f64,
    count: usize,
    steps: usize,
    mut solve: impl FnMut(&[f64], &mut [f64]),
    mut mass: impl FnMut(&[f64], &mut [f64]),
) -> Result<Vec<RitzPair>, LanczosError> {
    if count == 0 || count > n {
        return Err(LanczosError::Count { count, n });
    }
    let steps = steps.clamp(count, n);
    let mut mw = vec![0.0; n];
    let (basis, alpha, beta) = krylov(n, steps, &mut solve, &mut mass, &mut mw);
    let k = alpha.len();
    let evd = tridiagonal(&alpha, &beta)
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
            mass(&vector, &mut mw);
            let norm = dot(&vector, &mw).sqrt();
            vector.iter_mut().for_each(|x| *x /= norm);
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

/// The fixed pseudo-random start vector, M-normalised, and its M v (same inputs, same pairs).
fn start_vector(n: usize, mass: &mut impl FnMut(&[f64], &mut [f64])) -> (Vec<f64>, Vec<f64>) {
    let mut start: Vec<f64> = (0..n)
        .map(|i| ((i as f64 + 1.0) * 0.618_033_988_749_894_9).fract() - 0.5)
        .collect();
    let mut product = vec![0.0; n];
    mass(&start, &mut product);
    let norm = dot(&start, &product).sqrt();
    start.iter_mut().for_each(|x| *x /= norm);
    product.iter_mut().for_each(|x| *x /= norm);
    (start, product)
}

/// The Lanczos steps in the M inner product: the M-orthonormal basis and the tridiagonal's α, β.
fn krylov(
    n: usize,
    steps: usize,
    solve: &mut impl FnMut(&[f64], &mut [f64]),
    mass: &mut impl FnMut(&[f64], &mut [f64]),
    mw: &mut [f64],
) -> (Vec<Vec<f64>>, Vec<f64>, Vec<f64>) {
    let (mut basis, mut products): (Vec<Vec<f64>>, Vec<Vec<f64>>) =
        (Vec::with_capacity(steps + 1), Vec::with_capacity(steps + 1));
    let (start, product) = start_vector(n, mass);
    basis.push(start);
    products.push(product);
    let (mut alpha, mut beta) = (Vec::with_capacity(steps), Vec::with_capacity(steps));
    let mut w = vec![0.0; n];
    for k in 0..steps {
        solve(&basis[k], &mut w);
        let a = dot(&w, &products[k]);
        alpha.push(a);
        // Full reorthogonalisation, twice (Kahan's "twice is enough").
        for _ in 0..2 {
            for (v, mv) in basis.iter().zip(&products) {
                let c = dot(&w, mv);
                w.iter_mut().zip(v).for_each(|(w, v)| *w -= c * v);
            }
        }
        mass(&w, mw);
        let b = dot(&w, mw).sqrt();
        beta.push(b);
        if b <= 1e-14 * a.abs().max(f64::MIN_POSITIVE) || k + 1 == steps {
            break;
        }
        basis.push(w.iter().map(|v| v / b).collect());
        products.push(mw.iter().map(|v| v / b).collect());
    }
    (basis, alpha, beta)
}

/// The Lanczos tridiagonal T: α on the diagonal, β beside it (B's projection on the basis).
fn tridiagonal(alpha: &[f64], beta: &[f64]) -> Mat<f64> {
    let k = alpha.len();
    Mat::from_fn(k, k, |i, j| {
        if i == j {
            alpha[i]
        } else if i + 1 == j {
            beta[i]
        } else if j + 1 == i {
            beta[j]
        } else {
            0.0
        }
    })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The four of the string's eigenvalues λ(cos θ_j), θ_j = jπ/(n + 1), nearest `shift`,
    /// ascending.
    fn nearest_of(n: usize, shift: f64, value: impl Fn(f64) -> f64) -> Vec<f64> {
        let mut exact: Vec<f64> = (1..=n)
            .map(|j| value((j as f64 * std::f64::consts::PI / (n as f64 + 1.0)).cos()))
            .collect();
        exact.sort_by(|a, b| (a - shift).abs().total_cmp(&(b - shift).abs()));
        exact.truncate(4);
        exact.sort_by(f64::total_cmp);
        exact
    }

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
        let nearest4 = nearest_of(n, shift, |c| 2.0 - 2.0 * c);
        for (p, e) in pairs.iter().zip(&nearest4) {
            assert!((p.value - e).abs() <= 1e-10, "{} against {e}", p.value);
        }
    }

    /// The consistent-mass string, K = tridiag(−1, 2, −1), M = tridiag(1, 4, 1)/6, has
    /// λ_j = 6 (1 − cos θ_j)/(2 + cos θ_j), θ_j = jπ/(n + 1): the four nearest 1.0 of n = 400 in
    /// the M inner product, by solves with the dense LU of K − σM, each vector M-normalised.
    #[test]
    fn the_consistent_strings_eigenvalues_nearest_a_shift() {
        let n = 400;
        let shift = 1.0;
        let tridiagonal = |d: f64, o: f64| {
            Mat::from_fn(n, n, |i, j| {
                if i == j {
                    d
                } else if i.abs_diff(j) == 1 {
                    o
                } else {
                    0.0
                }
            })
        };
        let (k, m) = (tridiagonal(2.0, -1.0), tridiagonal(4.0 / 6.0, 1.0 / 6.0));
        let lu = (&k - &m * shift).partial_piv_lu();
        let product = |v: &[f64], out: &mut [f64]| {
            for i in 0..n {
                out[i] = (0..n).map(|j| m[(i, j)] * v[j]).sum();
            }
        };
        let solve = |y: &[f64], out: &mut [f64]| {
            let mut my = vec![0.0; n];
            product(y, &mut my);
            let rhs = Mat::from_fn(n, 1, |i, _| my[i]);
            let x = faer::linalg::solvers::Solve::solve(&lu, &rhs);
            for i in 0..n {
                out[i] = x[(i, 0)];
            }
        };
        let pairs = nearest_with_mass(n, shift, 4, 80, solve, product).unwrap();
        let nearest4 = nearest_of(n, shift, |c| 6.0 * (1.0 - c) / (2.0 + c));
        for (p, e) in pairs.iter().zip(&nearest4) {
            assert!((p.value - e).abs() <= 1e-10, "{} against {e}", p.value);
            let mut mx = vec![0.0; n];
            product(&p.vector, &mut mx);
            let norm: f64 = p.vector.iter().zip(&mx).map(|(a, b)| a * b).sum();
            assert!((norm - 1.0).abs() <= 1e-12, "xᵀ M x = {norm}");
        }
    }
}
