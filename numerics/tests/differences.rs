//! Finite differences against analytic derivatives: the coloured iteration matrix of a spring
//! chain, the step rule's limit and floor, and probes kept off a tension-only kink.

use cdpr_numerics::differences::{CBRT_EPSILON, ColouredDifferences, central_step};

/// A chain of tension-only springs stretched by s = 5.6e-7 m (lumped N = 1000 at 100 N),
/// at x ≈ 1 m where the default step would be 6e-6 m: with the step limited to s/4 the
/// differences give the analytic stiffness k to 1e-6 (round-off k·ulp(1 m)/δ ≈ 0.3 N/m,
/// 2e-9 of k = 1.8e8 N/m); without the limit the probes reach the slack side and the matrix is off
/// by (s + δ)/(2δ) − 1 ≈ −45 % (the failure that stalled Newton at N = 1000).
#[test]
fn step_limits_keep_the_probes_off_the_tension_kink() {
    let n = 6;
    let (k, l0, m) = (1.8e8, 1e-3, 1.4e-5);
    let stretch = 5.6e-7;
    let residual = |s: &[f64], a: &[f64], r: &mut [f64]| {
        let q = &s[..n];
        for i in 0..n {
            let tension = |d: f64| k * (d - l0).max(0.0);
            let mut f = 0.0;
            if i > 0 {
                f -= tension(q[i] - q[i - 1]);
            }
            if i + 1 < n {
                f += tension(q[i + 1] - q[i]);
            }
            r[i] = m * a[i] - f;
        }
    };
    let mut pattern = Vec::new();
    for i in 0..n {
        for j in i.saturating_sub(1)..(i + 2).min(n) {
            pattern.push((i, j));
        }
    }
    let mut state = vec![0.0; 2 * n];
    for (i, q) in state[..n].iter_mut().enumerate() {
        *q = 1.0 + i as f64 * (l0 + stretch);
    }
    let qdd = vec![0.0; n];
    let c_q = 2.5e-9;
    let exact = |i: usize, j: usize| {
        let deg = (i > 0) as usize + (i + 1 < n) as usize;
        if i == j {
            m + c_q * k * deg as f64
        } else {
            -c_q * k
        }
    };
    let worst = |fd: &mut ColouredDifferences| {
        let mut values = vec![0.0; pattern.len()];
        let mut f = residual;
        fd.fill(&mut f, &state, &qdd, 0.0, c_q, &mut values);
        pattern
            .iter()
            .zip(&values)
            .map(|(&(i, j), v)| ((v - exact(i, j)) / exact(i, j)).abs())
            .fold(0.0, f64::max)
    };
    let mut limited = ColouredDifferences::new(n, &pattern);
    limited.step_limits_mut().fill(0.25 * stretch);
    let error = worst(&mut limited);
    assert!(error < 1e-6, "limited steps: relative error {error:e}");
    let error = worst(&mut ColouredDifferences::new(n, &pattern));
    assert!(
        error > 0.3,
        "unlimited steps should reach the slack side: {error:e}"
    );
}

/// The step: ε^(1/3) max(|x|, 1e-2) when unlimited, the limit when smaller, never below
/// 1e3 ulps of max(|x|, 1).
#[test]
fn central_step_obeys_its_limit_and_floor() {
    let cbrt = f64::EPSILON.cbrt();
    assert_eq!(CBRT_EPSILON, cbrt);
    assert_eq!(central_step(2.0, f64::INFINITY), cbrt * 2.0);
    assert_eq!(central_step(0.0, f64::INFINITY), cbrt * 1e-2);
    assert_eq!(central_step(2.0, 1e-9), 1e-9);
    assert_eq!(central_step(2.0, 1e-20), 2e3 * f64::EPSILON);
}

/// A chain of unit masses with springs k between neighbours and dampers c, plus a nonlinear
/// cubic term: S from the differences against the hand-derived one.
#[test]
fn coloured_differences_match_the_analytic_chain_matrix() {
    let n = 7;
    let (k, c, m) = (3.0e4, 2.0, 0.5);
    let residual = |s: &[f64], a: &[f64], r: &mut [f64]| {
        let (q, v) = s.split_at(n);
        for i in 0..n {
            let mut f = 0.0;
            if i > 0 {
                f -= k * (q[i] - q[i - 1]) + c * (v[i] - v[i - 1]);
            }
            if i + 1 < n {
                f += k * (q[i + 1] - q[i]) + c * (v[i + 1] - v[i]);
            }
            f -= q[i].powi(3);
            r[i] = m * a[i] - f;
        }
    };
    let mut pattern = Vec::new();
    for i in 0..n {
        for j in i.saturating_sub(1)..(i + 2).min(n) {
            pattern.push((i, j));
        }
    }
    let mut fd = ColouredDifferences::new(n, &pattern);
    assert_eq!(fd.groups(), 3, "a tridiagonal pattern needs three groups");
    let state: Vec<f64> = (0..2 * n).map(|i| 0.1 * i as f64 - 0.3).collect();
    let qdd: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let (c_v, c_q) = (5e-5, 2.5e-9);
    let mut values = vec![0.0; pattern.len()];
    let mut f = residual;
    let evals = fd.fill(&mut f, &state, &qdd, c_v, c_q, &mut values);
    assert_eq!(evals, 1 + 3 + 2 * 3 * 2, "q'' forward, q' and q central");
    for (idx, &(i, j)) in pattern.iter().enumerate() {
        let off = (i as isize - j as isize).abs() == 1;
        let deg = (i > 0) as usize + (i + 1 < n) as usize;
        let exact = if i == j {
            m + c_v * c * deg as f64 + c_q * (k * deg as f64 + 3.0 * state[i].powi(2))
        } else if off {
            -c_v * c - c_q * k
        } else {
            0.0
        };
        // Central differences: relative error ~ε^(2/3) ≈ 4e-11 of the largest term.
        assert!(
            (values[idx] - exact).abs() <= 1e-9 * exact.abs().max(m),
            "({i}, {j}): {} vs {exact}",
            values[idx]
        );
    }
    // The same with the mass declared: no q'' probes, and the same matrix to the q''
    // difference's round-off (ε·max(1, |q''|)·|R| / step ≈ 1e-12 here).
    let mut declared = ColouredDifferences::new(n, &pattern).with_diagonal_mass(&vec![m; n]);
    let mut exact_mass = vec![0.0; pattern.len()];
    let evals = declared.fill(&mut f, &state, &qdd, c_v, c_q, &mut exact_mass);
    assert_eq!(evals, 2 * 3 * 2, "q' and q central only");
    for (idx, (a, b)) in exact_mass.iter().zip(&values).enumerate() {
        assert!((a - b).abs() <= 1e-9 * m, "entry {idx}: {a} vs {b}");
    }
}
