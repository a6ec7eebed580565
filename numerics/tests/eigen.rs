//! Eigen-analysis of linear systems with closed-form modes, through the finite-difference Jacobian.

use cdpr_numerics::OdeSystem;
use cdpr_numerics::differences::jacobian;
use cdpr_numerics::eigen::{mode_shapes, modes, nearest_mode, reduce};
use faer::{Mat, c64};
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
