//! The continuous-time algebraic Riccati equation (CARE) of LQR design:
//!
//! ```text
//! Aᵀ X + X A − X B R⁻¹ Bᵀ X + Q = 0,   K = R⁻¹ Bᵀ X,   u = −K x
//! ```
//!
//! X is the stabilising solution (A − B K has every eigenvalue in the left half-plane). It is
//! found in two stages: the stable invariant subspace of the Hamiltonian
//! H = [A, −B R⁻¹ Bᵀ; −Q, −Aᵀ] (its n eigenvectors with Re λ < 0, [U₁; U₂], give X = U₂ U₁⁻¹;
//! Laub 1979), then Newton–Kleinman iterations (Kleinman 1968) from that stabilising start,
//! each a Lyapunov equation Aₖᵀ X + X Aₖ = −(Q + Kₖᵀ R Kₖ), solved exactly as an n² × n² linear
//! system (the controllers here have n ≤ 8 states), until the update is at round-off. The
//! eigenvector stage alone loses accuracy when H's eigenvectors are ill-conditioned; Newton's
//! quadratic convergence restores it, and the residual is reported.

use faer::prelude::Solve;
use faer::{Mat, c64};

/// Why no stabilising solution was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RiccatiError {
    #[error("dimensions do not fit: {0}")]
    Dimensions(String),
    #[error("R is not invertible")]
    SingularR,
    #[error(
        "the Hamiltonian has {stable} eigenvalues with Re λ < 0, not {n}: (A, B) is not \
         stabilisable or (A, Q) has an undetectable mode on the imaginary axis"
    )]
    NoStableSubspace { stable: usize, n: usize },
    #[error("eigen-decomposition failed")]
    Eigen,
    /// The candidate does not stabilise A − B K (an unstable mode no input reaches).
    #[error("no stabilising solution: (A, B) is not stabilisable")]
    NotStabilisable,
    #[error(
        "Newton–Kleinman did not converge: residual {residual:e} after {iterations} iterations"
    )]
    NotConverged { residual: f64, iterations: usize },
}

/// The stabilising solution of a CARE and the LQR gain.
#[derive(Debug, Clone)]
pub struct Care {
    /// X, symmetric positive semi-definite.
    pub x: Mat<f64>,
    /// K = R⁻¹ Bᵀ X (m × n): the state feedback u = −K x.
    pub gain: Mat<f64>,
    /// max |Aᵀ X + X A − X B R⁻¹ Bᵀ X + Q| at the returned X.
    pub residual: f64,
    /// Newton–Kleinman iterations taken.
    pub iterations: usize,
}

/// Most Newton–Kleinman iterations (quadratic convergence needs a handful).
const MAX_ITERATIONS: usize = 50;

/// Solves the CARE for A (n × n), B (n × m), Q (n × n, symmetric ≥ 0), R (m × m, symmetric > 0).
///
/// # Examples
///
/// The double integrator ẍ = u weighting the position only (Q = diag(1, 0), R = 1) has
/// K = [1, √2] (with Q = I it is [1, √3]):
///
/// ```
/// use cdpr_numerics::riccati::care;
/// use faer::Mat;
///
/// let a = Mat::from_fn(2, 2, |i, j| if (i, j) == (0, 1) { 1.0 } else { 0.0 });
/// let b = Mat::from_fn(2, 1, |i, _| if i == 1 { 1.0 } else { 0.0 });
/// let q = Mat::from_fn(2, 2, |i, j| if (i, j) == (0, 0) { 1.0 } else { 0.0 });
/// let r = Mat::<f64>::identity(1, 1);
/// let lqr = care(&a, &b, &q, &r).unwrap();
/// assert!((lqr.gain[(0, 0)] - 1.0).abs() < 1e-12);
/// assert!((lqr.gain[(0, 1)] - 2f64.sqrt()).abs() < 1e-12);
/// ```
pub fn care(a: &Mat<f64>, b: &Mat<f64>, q: &Mat<f64>, r: &Mat<f64>) -> Result<Care, RiccatiError> {
    let (n, m) = (a.nrows(), b.ncols());
    let square = |mat: &Mat<f64>, k: usize| mat.nrows() == k && mat.ncols() == k;
    if !square(a, n) || b.nrows() != n || !square(q, n) || !square(r, m) {
        return Err(RiccatiError::Dimensions(format!(
            "A {}×{}, B {}×{}, Q {}×{}, R {}×{}",
            a.nrows(),
            a.ncols(),
            b.nrows(),
            b.ncols(),
            q.nrows(),
            q.ncols(),
            r.nrows(),
            r.ncols()
        )));
    }
    let r_inv = inverse(r).ok_or(RiccatiError::SingularR)?;
    let s = b * &r_inv * b.transpose();
    let mut x = hamiltonian_start(a, &s, q)?;
    if !finite(&x) {
        return Err(RiccatiError::NotStabilisable);
    }
    // The residual's round-off scale: the largest terms of the equation.
    let scale = |x: &Mat<f64>| 1.0 + max_abs(q) + max_abs(x) * (1.0 + max_abs(a));
    let mut iterations = 0;
    loop {
        let residual = residual(a, &s, q, &x);
        let converged = residual <= 1e-13 * scale(&x);
        if converged || iterations == MAX_ITERATIONS {
            if !converged && residual > 1e-8 * scale(&x) {
                return Err(RiccatiError::NotConverged {
                    residual,
                    iterations,
                });
            }
            break;
        }
        // Newton–Kleinman: (A − S X)ᵀ X⁺ + X⁺ (A − S X) = −(Q + X S X).
        let closed = a - &s * &x;
        let rhs = -(q + &x * &s * &x);
        let next = lyapunov(&closed, &rhs).ok_or(RiccatiError::NotConverged {
            residual,
            iterations,
        })?;
        let change = max_abs(&(&next - &x));
        x = symmetrised(&next);
        iterations += 1;
        if change <= 1e-15 * (1.0 + max_abs(&x)) {
            break; // at round-off
        }
    }
    let care = Care {
        gain: &r_inv * b.transpose() * &x,
        residual: residual(a, &s, q, &x),
        x,
        iterations,
    };
    stabilising(a, &s, care)
}

/// `care` if A − S X has every eigenvalue in the open left half-plane.
fn stabilising(a: &Mat<f64>, s: &Mat<f64>, care: Care) -> Result<Care, RiccatiError> {
    let closed = a - s * &care.x;
    let evd = closed.eigen().map_err(|_| RiccatiError::Eigen)?;
    let stable = (0..closed.nrows()).all(|k| evd.S()[k].re < 0.0);
    if finite(&care.x) && stable {
        Ok(care)
    } else {
        Err(RiccatiError::NotStabilisable)
    }
}

/// The LQR gain of a CARE given as row-major slices, for callers that do not use faer: A (n × n),
/// B (n × m), Q (n × n), R (m × m). Returns K (m × n, row-major) with [`Care`]'s residual and
/// iteration count.
pub fn lqr_gain(
    n: usize,
    m: usize,
    a: &[f64],
    b: &[f64],
    q: &[f64],
    r: &[f64],
) -> Result<(Vec<f64>, f64, usize), RiccatiError> {
    if a.len() != n * n || b.len() != n * m || q.len() != n * n || r.len() != m * m {
        return Err(RiccatiError::Dimensions(format!(
            "A {} B {} Q {} R {} values for n = {n}, m = {m}",
            a.len(),
            b.len(),
            q.len(),
            r.len()
        )));
    }
    let mat =
        |v: &[f64], rows: usize, cols: usize| Mat::from_fn(rows, cols, |i, j| v[i * cols + j]);
    let care = care(&mat(a, n, n), &mat(b, n, m), &mat(q, n, n), &mat(r, m, m))?;
    let gain = (0..m)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| care.gain[(i, j)])
        .collect();
    Ok((gain, care.residual, care.iterations))
}

/// max |Aᵀ X + X A − X S X + Q| with S = B R⁻¹ Bᵀ.
pub fn residual(a: &Mat<f64>, s: &Mat<f64>, q: &Mat<f64>, x: &Mat<f64>) -> f64 {
    max_abs(&(a.transpose() * x + x * a - x * s * x + q))
}

/// X = U₂ U₁⁻¹ from the n eigenvectors of the Hamiltonian with Re λ < 0 (real part, symmetrised).
fn hamiltonian_start(a: &Mat<f64>, s: &Mat<f64>, q: &Mat<f64>) -> Result<Mat<f64>, RiccatiError> {
    let n = a.nrows();
    let h = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => a[(i, j)],
        (true, false) => -s[(i, j - n)],
        (false, true) => -q[(i - n, j)],
        (false, false) => -a[(j - n, i - n)],
    });
    // Balanced first (D⁻¹ H D, D a diagonal of powers of 2): printer-scale weights put 1e10
    // next to 1 in H, and the unbalanced eigen-solver's error ε‖H‖ then blurs the two halves
    // of the spectrum. The eigenvectors of H are D times those of the balanced matrix.
    let (balanced, d) = crate::eigen::balance(&h);
    let evd = balanced.eigen().map_err(|_| RiccatiError::Eigen)?;
    let (ub, lambda) = (evd.U(), evd.S());
    let u = Mat::<c64>::from_fn(2 * n, 2 * n, |i, k| ub[(i, k)] * d[i]);
    // H's spectrum is symmetric about the imaginary axis: its stable half is the n eigenvalues
    // of smallest real part. Counting Re λ < 0 instead fails on badly scaled weights (Q ~ 1e10
    // against R ~ 1), where round-off moves an eigenvalue of either half across zero; the start
    // only has to be good enough for Newton–Kleinman, whose result is checked to stabilise.
    let mut order: Vec<usize> = (0..2 * n).collect();
    order.sort_by(|&a, &b| lambda[a].re.total_cmp(&lambda[b].re));
    let stable: Vec<usize> = order[..n].to_vec();
    let strictly = (0..2 * n)
        .filter(|&k| lambda[k].re < -1e-12 * (1.0 + lambda[k].norm()))
        .count();
    if n > 0 && lambda[order[n - 1]].re >= 1e-9 * (1.0 + lambda[order[n - 1]].norm()) {
        return Err(RiccatiError::NoStableSubspace {
            stable: strictly,
            n,
        });
    }
    // X U₁ = U₂  ⇔  U₁ᵀ Xᵀ = U₂ᵀ.
    let u1t = Mat::<c64>::from_fn(n, n, |i, j| u[(j, stable[i])]);
    let u2t = Mat::<c64>::from_fn(n, n, |i, j| u[(n + j, stable[i])]);
    let xt = u1t.partial_piv_lu().solve(&u2t);
    let x = Mat::from_fn(n, n, |i, j| xt[(j, i)].re);
    Ok(symmetrised(&x))
}

/// The solution of Aᵀ X + X A = C (n × n) through the n² × n² system (I ⊗ Aᵀ + Aᵀ ⊗ I) vec X =
/// vec C, or None if it is singular (A has eigenvalues λ_i + λ_j = 0).
fn lyapunov(a: &Mat<f64>, c: &Mat<f64>) -> Option<Mat<f64>> {
    let n = a.nrows();
    let big = Mat::from_fn(n * n, n * n, |row, col| {
        // vec index i + n j ↔ X[(i, j)]; (Aᵀ X)[(i, j)] = Σ_k A[(k, i)] X[(k, j)],
        // (X A)[(i, j)] = Σ_k X[(i, k)] A[(k, j)].
        let (i, j) = (row % n, row / n);
        let (k, l) = (col % n, col / n);
        let mut v = 0.0;
        if l == j {
            v += a[(k, i)];
        }
        if k == i {
            v += a[(l, j)];
        }
        v
    });
    let rhs = Mat::from_fn(n * n, 1, |row, _| c[(row % n, row / n)]);
    let solution = big.partial_piv_lu().solve(&rhs);
    let x = Mat::from_fn(n, n, |i, j| solution[(i + n * j, 0)]);
    finite(&x).then_some(x)
}

/// (X + Xᵀ)/2.
fn symmetrised(x: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(x.nrows(), x.ncols(), |i, j| 0.5 * (x[(i, j)] + x[(j, i)]))
}

/// The inverse of a small square matrix, None if singular.
fn inverse(r: &Mat<f64>) -> Option<Mat<f64>> {
    let k = r.nrows();
    let inv = r.partial_piv_lu().solve(Mat::<f64>::identity(k, k));
    finite(&inv).then_some(inv)
}

fn finite(m: &Mat<f64>) -> bool {
    (0..m.ncols()).all(|j| (0..m.nrows()).all(|i| m[(i, j)].is_finite()))
}

fn max_abs(m: &Mat<f64>) -> f64 {
    let mut largest = 0.0f64;
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            largest = largest.max(m[(i, j)].abs());
        }
    }
    largest
}
