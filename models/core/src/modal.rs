//! Linearisation of the closed loop about a state and its eigenvalues and eigenvectors (faer): the
//! closed-loop vertical eigenfrequency that MODELS.md §8 compares with the spectral peak, and the
//! full modal analysis of issue 7 (every mode's frequency, damping and growth).
//!
//! This module knows no cable model: it differentiates any [`OdeSystem`], drops the coordinates a
//! caller says are constrained ([`reduce`]), and returns eigenpairs. Which coordinate is an effector,
//! a cable node or a stored (frozen) node is model knowledge and lives with the models' dispatcher
//! (`cdpr-verify`), which classifies the modes from the eigenvectors returned here.

use crate::closed_loop::ClosedLoop;
use crate::integrate::OdeSystem;
use crate::model::CableModel;
use crate::second_order::CBRT_EPSILON;
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

/// Jacobian ∂y'/∂y of the closed loop (model and PID states; the audit states are left out) at
/// (t, y) by central differences ([`jacobian`] for the step rule).
pub fn closed_loop_jacobian<M: CableModel>(sys: &mut ClosedLoop<M>, t: f64, y: &[f64]) -> Mat<f64> {
    let n = sys.model_len() + 2;
    jacobian(sys, t, y, n)
}

/// Jacobian ∂y'_i/∂y_j, i, j < `n`, of any [`OdeSystem`] at (t, y) by fourth-order central
/// differences (five-point stencil; the components ≥ n, e.g. audit states, are neither perturbed
/// nor returned).
///
/// Step rule h_j = ¼ ε^(1/3)·max(|y_j|, 1e-3) ≈ 1.5e-6·max(|y_j|, 1e-3) (ε the f64 machine
/// epsilon), and the step actually used is (y_j + h_j) − y_j, exact in floating point. Why
/// fourth order and this step: the soft modes are small differences of stiff terms. The lumped
/// model's straddling spring can have a free part d ≈ 3e-4 m long (at x = 0.5), with transverse
/// stiffness T/d ≈ 3e5 N/m, while the open-loop horizontal mode's stiffness is ≈ 1 N/m. Second-
/// order differences at ε^(1/3)·|y| (6e-6 m at x ≈ 1) err by (h/d)²·T/d ≈ 20 N/m there and turned
/// that 0.98 rad/s oscillation into a spurious real pair ±1.29 1/s (a nonlinear run shows the
/// oscillation). Fourth order errs by (h/d)⁴·T/d ≈ 2e-4 N/m, round-off (k0·ulp(1) ≈ 7e-10 N)/h
/// by ≈ 5e-4 N/m. Checked: h/4 → h/30 changes that mode by 6e-5 relative, the others less. For
/// the oscillatory modes an entry error δK moves λ = ±iω by about δK/(2ω·m).
///
/// The stencil reaches 2h_j ≈ 3e-6·|y_j|: a tension-only spring stretched by less than that (low
/// tension on a fine mesh, T < EA·3e-6·|y|/l0) is probed on its slack side; see
/// [`jacobian_within`].
pub fn jacobian<S: OdeSystem>(sys: &mut S, t: f64, y: &[f64], n: usize) -> Mat<f64> {
    jacobian_within(sys, t, y, n, &[], &[])
}

/// [`jacobian`] with the stencil of column j kept within `reach[j]` (2h_j ≤ reach[j]; missing or
/// ∞: no limit): the largest distance over which the right-hand side is smooth in y_j, e.g. a
/// quarter of the stretch of the springs y_j moves. A stencil across a tension-only kink sees the
/// slack side and under-reads the stiffness (a 21-element chain at 10 N: 3.6e-5 in its lowest
/// axial mode). The round-off of a shorter step stays small: the axial forces' round-off
/// k·ulp(y) against k·h is ulp(y)/h ≈ 7e-10 at h = 1e-7 m.
///
/// `scale[j]` replaces the floor 1e-3 of the step rule (missing: 1e-3): the size of y_j below
/// which its step does not shrink. Velocities at rest need it. The forces are at most quadratic
/// in them (damping, convective and gyroscopic terms), which the five-point stencil
/// differentiates exactly at any step, so only round-off matters; at the floor 1e-3 the step is
/// 1.5e-9 m/s and a Kelvin–Voigt force C·Δε' ≈ 1e-10 N sits on 100 N sums (ulp 1.4e-14 N):
/// 1e-4 relative error, which scattered the damped FE string modes' σ by up to 2e-3 1/s.
pub fn jacobian_within<S: OdeSystem>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    n: usize,
    reach: &[f64],
    scale: &[f64],
) -> Mat<f64> {
    let full = sys.dimension();
    let mut yp = y.to_vec();
    let mut f = [
        vec![0.0; full],
        vec![0.0; full],
        vec![0.0; full],
        vec![0.0; full],
    ];
    let mut jac = Mat::<f64>::zeros(n, n);
    for j in 0..n {
        let limit = reach.get(j).map_or(f64::INFINITY, |r| 0.5 * r);
        let floor = scale.get(j).copied().unwrap_or(1e-3);
        let h0 = (0.25 * CBRT_EPSILON * y[j].abs().max(floor)).min(limit);
        // The step actually taken (y + h is rounded).
        let h = (y[j] + h0) - y[j];
        for (k, o) in [2.0, 1.0, -1.0, -2.0].into_iter().enumerate() {
            yp[j] = y[j] + o * h;
            sys.rhs(t, &yp, &mut f[k]);
        }
        yp[j] = y[j];
        for i in 0..n {
            jac[(i, j)] = (-f[0][i] + 8.0 * f[1][i] - 8.0 * f[2][i] + f[3][i]) / (12.0 * h);
        }
    }
    jac
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// y' = A y with A block-diagonal: damped oscillators [[0, 1], [−ω0², −2ζω0]] and one real
    /// pole −a, each block coupled to the next by a strictly upper term (A stays block upper
    /// triangular, so the eigenvalues are the blocks' closed-form ones but the matrix is not normal).
    struct Linear {
        a: Mat<f64>,
    }

    impl OdeSystem for Linear {
        fn dimension(&self) -> usize {
            self.a.nrows()
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
            for (i, d) in dy.iter_mut().enumerate() {
                *d = (0..y.len()).map(|j| self.a[(i, j)] * y[j]).sum();
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Frequencies ω0√(1 − ζ²), growth −ζω0 and damping ratio ζ of each block, through the FD
        /// Jacobian (exact for a linear system up to round-off ~ε·|A|/h) and faer's eigen solver.
        /// Tolerance 1e-8 relative to ω0: the FD round-off is ε·|y|/h ~ 1e-11 relative, the
        /// non-normal coupling (0.3) amplifies eigenvalue round-off by at most a few orders.
        #[test]
        fn damped_oscillators_match_closed_form(
            blocks in prop::collection::vec((1.0f64..1e4, 0.0f64..0.9), 1..5),
            pole in 0.1f64..100.0,
        ) {
            let n = 2 * blocks.len() + 1;
            let mut a = Mat::<f64>::zeros(n, n);
            for (b, &(w0, zeta)) in blocks.iter().enumerate() {
                let i = 2 * b;
                a[(i, i + 1)] = 1.0;
                a[(i + 1, i)] = -w0 * w0;
                a[(i + 1, i + 1)] = -2.0 * zeta * w0;
                a[(i, i + 2)] = 0.3;
            }
            a[(n - 1, n - 1)] = -pole;
            let mut sys = Linear { a: a.clone() };
            let y = vec![0.0; n];
            let jac = jacobian(&mut sys, 0.0, &y, n);
            let shapes = mode_shapes(&jac).unwrap();
            for &(w0, zeta) in &blocks {
                let wd = w0 * (1.0 - zeta * zeta).sqrt();
                let m = nearest_mode(&shapes.iter().map(|s| s.mode).collect::<Vec<_>>(), wd).unwrap();
                prop_assert!((m.omega - wd).abs() < 1e-8 * w0, "ω {} vs {}", m.omega, wd);
                prop_assert!((m.growth + zeta * w0).abs() < 1e-8 * w0, "σ {} vs {}", m.growth, -zeta * w0);
                prop_assert!((m.damping_ratio() - zeta).abs() < 1e-8, "ζ {} vs {}", m.damping_ratio(), zeta);
            }
            let real = shapes.iter().filter(|s| s.mode.omega == 0.0).map(|s| s.mode.growth);
            prop_assert!(real.clone().any(|g| (g + pole).abs() < 1e-8 * pole.max(1.0)));
            // Each returned vector is an eigenvector: |A v − λ v| ≤ 1e-8 |A| (unit v).
            let scale = blocks.iter().map(|b| b.0 * b.0).fold(pole, f64::max);
            for s in &shapes {
                let lam = c64::new(s.mode.growth, s.mode.omega);
                for i in 0..n {
                    let mut av = c64::new(0.0, 0.0);
                    for j in 0..n {
                        av += c64::new(s.vector[j].0, s.vector[j].1) * a[(i, j)];
                    }
                    let r = av - lam * c64::new(s.vector[i].0, s.vector[i].1);
                    prop_assert!(r.norm() < 1e-8 * scale, "residual {} at row {}", r.norm(), i);
                }
            }
        }
    }

    /// Reducing to the unconstrained coordinates removes exactly the zero rows' eigenvalues.
    #[test]
    fn reduce_drops_constrained_coordinates() {
        let mut a = Mat::<f64>::zeros(4, 4);
        a[(0, 2)] = 1.0;
        a[(2, 0)] = -4.0;
        a[(0, 1)] = 0.5; // column of a frozen coordinate: never excited once frozen
        let r = reduce(&a, &[0, 2]);
        let m = modes(&r).unwrap();
        assert_eq!(m.len(), 1);
        assert!((m[0].omega - 2.0).abs() < 1e-12 && m[0].growth.abs() < 1e-12);
    }
}
