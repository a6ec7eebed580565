//! Eigenvalues and eigenvectors of a real square matrix (faer), as continuous-time modes: the
//! growth rate σ and angular frequency ω of each λ = σ + iω, with the balancing that keeps a
//! badly scaled Jacobian's eigenvalues accurate, and [`reduce`] to drop coordinates a constraint
//! holds fixed.

use faer::{Mat, c64};

pub use faer::linalg::evd::EvdError;

/// A continuous-time eigenvalue λ = σ + iω [1/s].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Mode {
    /// Growth rate σ [1/s] (> 0: growing).
    pub growth: f64,
    /// Angular frequency ω ≥ 0 [rad/s].
    pub omega: f64,
}

impl Mode {
    /// Damping ratio ζ = −σ/|λ|.
    pub fn damping_ratio(&self) -> f64 {
        -self.growth / self.growth.hypot(self.omega)
    }
}

/// The square submatrix of `jac` on the coordinates `keep` (in that order): the Jacobian of a
/// system whose other coordinates are held fixed by constraints (e.g. the lumped stored nodes'
/// z = ż = 0 of MODELS.md §4 eq. 6). Their rows are identically zero and would only add spurious
/// zero eigenvalues; their columns multiply perturbations the constraint forbids.
pub fn reduce(jac: &Mat<f64>, keep: &[usize]) -> Mat<f64> {
    Mat::from_fn(keep.len(), keep.len(), |i, j| jac[(keep[i], keep[j])])
}

/// A mode with its right eigenvector (in the coordinates of the Jacobian it came from, unit
/// Euclidean norm, phase such that the largest component is real and positive).
#[derive(Debug, Clone, PartialEq)]
pub struct ModeShape {
    pub mode: Mode,
    /// Eigenvector components (re, im).
    pub vector: Vec<(f64, f64)>,
}

/// Why the eigen-analysis failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModalError {
    #[error("eigen-decomposition failed: {0:?}")]
    Evd(EvdError),
    #[error("the Jacobian is not finite (the right-hand side returned NaN or ∞ near the state)")]
    NotFinite,
}

/// Eigenpairs of `jac` with ω ≥ 0 (one of each conjugate pair), sorted by frequency then growth.
pub fn mode_shapes(jac: &Mat<f64>) -> Result<Vec<ModeShape>, ModalError> {
    let n = jac.nrows();
    if (0..n).any(|i| (0..jac.ncols()).any(|j| !jac[(i, j)].is_finite())) {
        return Err(ModalError::NotFinite);
    }
    let (balanced, d) = balance(jac);
    let evd = balanced.eigen().map_err(ModalError::Evd)?;
    let (u, s) = (evd.U(), evd.S());
    let mut shapes: Vec<ModeShape> = (0..n)
        .filter(|&k| s[k].im >= 0.0)
        .map(|k| {
            // Eigenvector of jac = D · eigenvector of D⁻¹ jac D.
            let col: Vec<c64> = (0..n).map(|i| u[(i, k)] * d[i]).collect();
            let norm = col
                .iter()
                .map(|c| c.re * c.re + c.im * c.im)
                .sum::<f64>()
                .sqrt();
            let big = col
                .iter()
                .copied()
                .max_by(|a, b| a.norm().total_cmp(&b.norm()))
                .unwrap_or(c64::new(1.0, 0.0));
            // Multiply by conj(big)/|big|/norm: the largest component becomes real and positive.
            let scale =
                c64::new(big.re, -big.im) * (1.0 / (big.norm() * norm).max(f64::MIN_POSITIVE));
            ModeShape {
                mode: Mode {
                    growth: s[k].re,
                    omega: s[k].im,
                },
                vector: col
                    .iter()
                    .map(|&c| {
                        let v = c * scale;
                        (v.re, v.im)
                    })
                    .collect(),
            }
        })
        .collect();
    shapes.sort_by(|a, b| {
        a.mode
            .omega
            .total_cmp(&b.mode.omega)
            .then(a.mode.growth.total_cmp(&b.mode.growth))
    });
    Ok(shapes)
}

/// Diagonal similarity balancing (Parlett & Reinsch 1969, LAPACK's `dgebal` without
/// permutations): B = D⁻¹ A D with D a diagonal of powers of 2 (exact in floating point) so that
/// each row and column of B have comparable norms. Returns (B, diag D).
///
/// Why: a cable Jacobian mixes entries of 1 (q' = v) with k0/m ≈ 2e10 1/s² (v' = −K q/m); faer's
/// unbalanced Hessenberg QR was observed not to terminate on such a matrix (the damped lumped loop
/// at C ≈ 6.26e-3 N s), and balancing also reduces the eigenvalue error ~ε‖A‖ to ~ε‖B‖.
pub fn balance(a: &Mat<f64>) -> (Mat<f64>, Vec<f64>) {
    let n = a.nrows();
    let mut b = a.clone();
    let mut d = vec![1.0; n];
    for _sweep in 0..100 {
        let mut changed = false;
        for i in 0..n {
            let (mut c, mut r) = (0.0f64, 0.0f64);
            for j in 0..n {
                if j != i {
                    c += b[(j, i)].abs();
                    r += b[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let mut f = 1.0;
            let s = c + r;
            while c < r / 4.0 {
                c *= 2.0;
                r /= 2.0;
                f *= 2.0;
            }
            while c >= r * 4.0 {
                c /= 2.0;
                r *= 2.0;
                f /= 2.0;
            }
            if c + r < 0.95 * s {
                changed = true;
                d[i] *= f;
                for j in 0..n {
                    b[(i, j)] /= f;
                    b[(j, i)] *= f;
                }
            }
        }
        if !changed {
            break;
        }
    }
    (b, d)
}

/// Eigenvalues of `jac` with ω ≥ 0 (one of each conjugate pair), sorted by frequency.
pub fn modes(jac: &Mat<f64>) -> Result<Vec<Mode>, EvdError> {
    let mut modes: Vec<Mode> = balance(jac)
        .0
        .eigenvalues()?
        .into_iter()
        .filter(|l| l.im >= 0.0)
        .map(|l| Mode {
            growth: l.re,
            omega: l.im,
        })
        .collect();
    modes.sort_by(|a, b| {
        a.omega
            .total_cmp(&b.omega)
            .then(a.growth.total_cmp(&b.growth))
    });
    Ok(modes)
}

/// The oscillatory mode whose frequency is closest to `omega_guess` [rad/s].
pub fn nearest_mode(modes: &[Mode], omega_guess: f64) -> Option<Mode> {
    modes
        .iter()
        .filter(|m| m.omega > 0.0)
        .min_by(|a, b| {
            (a.omega - omega_guess)
                .abs()
                .total_cmp(&(b.omega - omega_guess).abs())
        })
        .copied()
}
