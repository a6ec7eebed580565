//! The second-order form of a cable model, R(q, q', q'', T) = M(q) q'' − F(q, q', T) = 0, which the
//! implicit integrator needs (MODELS.md §6, FE.9.3), and the finite-difference iteration matrix over
//! a declared sparsity pattern for models without an analytic one.
//!
//! A model offering this form keeps its state as `[q (n) | q' (n)]`. The residual is in the units of
//! the generalised forces (N for node coordinates), so one Newton tolerance (1e-7 N) serves every
//! model. The tensions enter R linearly; the closed loop adds their dependence on the effector
//! through the controller, so a model never sees the controller.

pub use crate::integrate::MatrixCost;

/// M(q) q'' − F(q, q', T) of a model, with its iteration matrix.
pub trait SecondOrderForm {
    /// Number n of generalised coordinates.
    fn dofs(&self) -> usize;
    /// Index of the effector's x among q.
    fn effector_x(&self) -> usize;
    /// Rows of R in which a commanded tension may appear (the closed loop couples them to the
    /// effector's x through the controller).
    fn tension_rows(&self) -> Vec<usize>;
    /// The (row, col) entries of ∂R/∂q'', ∂R/∂q' and ∂R/∂q that may be non-zero, for every state
    /// the model can reach (so one symbolic factorisation serves the run).
    fn iteration_pattern(&self) -> Vec<(usize, usize)>;
    /// Coordinates that couple distant parts of [`Self::iteration_pattern`] (e.g. a length
    /// that every node of a span depends on) without being dense enough for the sparse LU to
    /// split them off by itself: candidates for its border (see
    /// `cdpr_core::integrate::sparse::IterationMatrix::with_coupled`).
    fn coupled_unknowns(&self) -> Vec<usize> {
        Vec::new()
    }
    /// Round-off level of max |R| [N] at `state` (0 if negligible). A force k·(q_b − q_a) from
    /// coordinates of size |q| carries k·ulp(|q|): with k = EA/l0 = 1.8e8 N/m (lumped N = 1000)
    /// that is above MODELS.md's 1e-7 N Newton tolerance, which the integrator then raises to it.
    fn residual_round_off(&self, _state: &[f64]) -> f64 {
        0.0
    }
    /// Per position coordinate q_i (`out`, n long), the largest finite-difference step [m] over
    /// which the forces stay smooth in q_i at `state` = `[q | q']` (∞: nowhere near a kink), e.g. a quarter of
    /// the stretch of the tension-only springs q_i moves. The models' own iteration matrices use
    /// it, and so must any other differentiation of them (the modal analysis).
    fn smooth_reach(&self, _state: &[f64], out: &mut [f64]) {
        out.fill(f64::INFINITY);
    }

    /// R = M(q) q'' − F(q, q', T) for state `[q | q']` into `r` (n).
    fn residual(&mut self, state: &[f64], qdd: &[f64], tensions: [f64; 2], r: &mut [f64]);
    /// S = ∂R/∂q'' + c_v ∂R/∂q' + c_q ∂R/∂q at fixed tensions, in the order of
    /// [`Self::iteration_pattern`]. Returns the residual evaluations it made and its refresh
    /// price ([`MatrixCost`]).
    #[allow(clippy::too_many_arguments)]
    fn iteration_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: [f64; 2],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost;
}

/// Round-off bound of a spring model's residual [N]: a node's force sums two springs, each
/// k·(|q_b − q_a| − l0) from two rounded coordinates, so up to 4 k ulp(max |q|). Measured Newton
/// stalls at N = 1000: 1.0–1.3e-7 N (lumped, bound 2.4e-7 N) and 1.1–1.6e-7 N (FE, bound
/// 3.2e-7 N); at N ≤ 300 the bound stays below 1e-7 N.
pub fn spring_round_off(stiffness: f64, positions: &[f64]) -> f64 {
    4.0 * stiffness * f64::EPSILON * max_abs(positions)
}

/// max |v_i| (0 for an empty slice; NaN entries are passed over, as by `f64::max`). Four
/// independent lanes: the implicit path asks for its positions' scale at every step, and a
/// sequential max is one chain of dependent instructions (the FE paper run's round-off bound
/// cost 1.4 % of it). A max is exact, so the lanes change no bit.
pub(crate) fn max_abs(v: &[f64]) -> f64 {
    let mut largest = [0.0f64; 4];
    let chunks = v.chunks_exact(4);
    let tail = chunks.remainder();
    for chunk in chunks {
        for (m, &x) in largest.iter_mut().zip(chunk) {
            let a = x.abs();
            *m = if a > *m { a } else { *m };
        }
    }
    let head = tail.iter().fold(largest[0], |m, x| m.max(x.abs()));
    largest[1..].iter().fold(head, |m, &x| m.max(x))
}

/// Finite-difference iteration matrix over a sparsity pattern, with the columns grouped so that no
/// two columns of a group share a row (Curtis, Powell & Reid 1974): one residual evaluation per group
/// and per derivative (q'', q', q) instead of one per column.
///
/// Steps: R is linear in q'', so δq''_j = max(1, |q''_j|) is exact up to round-off; for q and q'
/// central differences with δ_j = ε^(1/3)·max(|u_j|, u_typ) balance truncation (∝ (δ/ℓ)², ℓ the
/// shortest length the force varies on) and round-off (∝ ε/δ). Forward differences were not
/// enough: over the pulley the lumped straddling spring's free part can be ~3e-4 m long, and a
/// forward step of 1.5e-8·|x| erred by 4e-6 of the matrix there. The matrix only steers Newton
/// (it changes the convergence rate, never the converged answer), but it is tested against
/// differences of its own (verify/tests/implicit.rs).
///
/// Kinks: a tension-only spring's force has a kink at zero stretch, and a probe that crosses it
/// sees the slack side: the difference then gives (s + δ)/(2δ) of the stiffness, s the stretch.
/// On fine meshes s is tiny (lumped N = 1000: l0 · T/EA = 5.6e-7 m against a default step of
/// 6e-6 m at x = 1 m), and a matrix at half the stiffness made modified Newton contract by only
/// 0.6–0.8 per iteration at any step size. So the model may state, per coordinate, the largest
/// step over which its forces stay smooth ([`Self::step_limits_mut`]; e.g. a quarter of the
/// stretch, so that no probe reaches the kink), and the step is kept below it
/// ([`central_step`]). Within a smooth region a step that large costs no accuracy: the
/// truncation error is (δ/ℓ)² with ℓ the geometric length (l0), not the stretch.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ColouredDifferences {
    n: usize,
    /// Columns of each group.
    groups: Vec<Vec<usize>>,
    /// Per column: (row, index into the pattern) of its distinct entries.
    column_entries: Vec<Vec<(usize, usize)>>,
    base: Vec<f64>,
    probe: Vec<f64>,
    minus: Vec<f64>,
    state: Vec<f64>,
    qdd: Vec<f64>,
    steps: Vec<f64>,
    /// Per coordinate, the largest step over which its forces are smooth (∞: no limit).
    step_limits: Vec<f64>,
    /// ∂R/∂q'' when it is a constant diagonal (a lumped mass), with each diagonal entry's index
    /// into the pattern: then it is written, not differenced.
    diagonal_mass: Option<Vec<(usize, f64)>>,
}

/// R(state, q'') into the last argument, at fixed tensions.
pub type ResidualFn<'a> = dyn FnMut(&[f64], &[f64], &mut [f64]) + 'a;

/// Typical magnitude of a coordinate [m] and a velocity [m/s] below which the FD step stops
/// shrinking (a node at z = 0 still gets a step of ~1e-10 m).
const TYPICAL_COORDINATE: f64 = 1e-2;

/// ε^(1/3), the relative central-difference step (a constant: `cbrt` is not `const`, and it was
/// 3 % of the lumped implicit run when evaluated per probe).
pub const CBRT_EPSILON: f64 = 6.0554544523933395e-6;

/// Central-difference step for a coordinate or velocity `x` whose forces are smooth over
/// [x − `limit`, x + `limit`] (∞ if nothing limits it): ε^(1/3)·max(|x|, 1e-2), the balance of
/// truncation and round-off, but at most `limit`, and at least 1e3 ulps of max(|x|, 1) (so
/// that the step is resolved in floating point).
pub fn central_step(x: f64, limit: f64) -> f64 {
    let smooth = CBRT_EPSILON * x.abs().max(TYPICAL_COORDINATE);
    let floor = 1e3 * f64::EPSILON * x.abs().max(1.0);
    smooth.min(limit).max(floor)
}

impl ColouredDifferences {
    /// Groups the columns of the n × n `pattern` greedily (first fit, column order).
    pub fn new(n: usize, pattern: &[(usize, usize)]) -> Self {
        let mut column_entries: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
        let mut rows: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (k, &(r, c)) in pattern.iter().enumerate() {
            if r >= n || c >= n || column_entries[c].iter().any(|&(rr, _)| rr == r) {
                continue;
            }
            column_entries[c].push((r, k));
            rows[r].push(c);
        }
        let mut colour = vec![usize::MAX; n];
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut taken = Vec::new();
        for c in 0..n {
            taken.clear();
            for &(r, _) in &column_entries[c] {
                taken.extend(rows[r].iter().map(|&other| colour[other]));
            }
            let g = (0..).find(|g| !taken.contains(g)).unwrap_or(0);
            colour[c] = g;
            if g == groups.len() {
                groups.push(Vec::new());
            }
            groups[g].push(c);
        }
        Self {
            n,
            groups,
            column_entries,
            base: vec![0.0; n],
            probe: vec![0.0; n],
            minus: vec![0.0; n],
            state: vec![0.0; 2 * n],
            qdd: vec![0.0; n],
            steps: vec![0.0; n],
            step_limits: vec![f64::INFINITY; n],
            diagonal_mass: None,
        }
    }

    /// Declares ∂R/∂q'' = diag(`mass`) (n entries, constant: R = diag(m) q'' − F(q, q')), so that
    /// [`Self::fill`] writes it instead of spending a residual per column group on it (R is
    /// linear in q'', so the difference would only reproduce m to round-off). Every (i, i) must
    /// be in the pattern.
    pub fn with_diagonal_mass(mut self, mass: &[f64]) -> Self {
        assert_eq!(mass.len(), self.n, "one mass per coordinate");
        let entries = mass
            .iter()
            .enumerate()
            .map(|(i, &m)| {
                let (_, k) = self.column_entries[i]
                    .iter()
                    .find(|&&(r, _)| r == i)
                    .expect("the pattern holds the diagonal");
                (*k, m)
            })
            .collect();
        self.diagonal_mass = Some(entries);
        self
    }

    /// Per coordinate q_j, the largest step [m] over which the forces are smooth in q_j (a
    /// fraction of the stretch of a tension-only spring it moves, of its distance to a pulley):
    /// the q steps stay below it (see [`central_step`]). ∞ until the model sets it; it keeps its
    /// values between calls, so a model updates it before each [`Self::fill`].
    pub fn step_limits_mut(&mut self) -> &mut [f64] {
        &mut self.step_limits
    }

    /// Number of column groups (residual evaluations per derivative).
    pub fn groups(&self) -> usize {
        self.groups.len()
    }

    /// J = ∂R/∂u of `residual(u, r)` at `u` into `values` (pattern order; duplicate entries get
    /// 0) by central differences with the absolute steps `steps` (one per column): the static
    /// Newton's Jacobian. Returns the residual evaluations used (2 per group).
    pub fn jacobian(
        &mut self,
        residual: &mut dyn FnMut(&[f64], &mut [f64]),
        u: &[f64],
        steps: &[f64],
        values: &mut [f64],
    ) -> u64 {
        values.fill(0.0);
        // A static problem has no q'': its buffer holds the probed unknowns.
        let probe_u = &mut self.qdd;
        probe_u.copy_from_slice(u);
        let mut evals = 0;
        for group in &self.groups {
            for (sign, out) in [(1.0, &mut self.probe), (-1.0, &mut self.minus)] {
                for &c in group {
                    probe_u[c] = u[c] + sign * steps[c];
                }
                residual(probe_u, out);
                evals += 1;
            }
            for &c in group {
                // The step actually taken, after rounding, on both sides.
                let width = (u[c] + steps[c]) - (u[c] - steps[c]);
                for &(r, k) in &self.column_entries[c] {
                    values[k] += (self.probe[r] - self.minus[r]) / width;
                }
                probe_u[c] = u[c];
            }
        }
        evals
    }

    /// S = ∂R/∂q'' + c_v ∂R/∂q' + c_q ∂R/∂q of `residual(state, qdd, r)` at (state, qdd) into
    /// `values` (pattern order; duplicate entries get 0). Returns the residual evaluations used.
    #[allow(clippy::too_many_arguments)]
    pub fn fill(
        &mut self,
        residual: &mut ResidualFn<'_>,
        state: &[f64],
        qdd: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> u64 {
        let n = self.n;
        values.fill(0.0);
        self.state.copy_from_slice(&state[..2 * n]);
        self.qdd.copy_from_slice(qdd);
        let mut evals = 0;
        let q_dd_weight = match &self.diagonal_mass {
            Some(mass) => {
                for &(k, m) in mass {
                    values[k] = m;
                }
                0.0
            }
            None => {
                // The base of the q'' forward difference.
                residual(&self.state, &self.qdd, &mut self.base);
                evals += 1;
                1.0
            }
        };
        // Derivative 0: q'' (weight 1), 1: q' (c_v), 2: q (c_q); a zero weight is skipped.
        for (derivative, weight) in [(0usize, q_dd_weight), (1, c_v), (2, c_q)] {
            if weight == 0.0 {
                continue;
            }
            // q'': R is linear, one forward difference is exact. q', q: central differences.
            let central = derivative != 0;
            for g in 0..self.groups.len() {
                for sign in [1.0, -1.0].into_iter().take(if central { 2 } else { 1 }) {
                    for &c in &self.groups[g] {
                        let (slot, original) = match derivative {
                            0 => (&mut self.qdd[c], qdd[c]),
                            1 => (&mut self.state[n + c], state[n + c]),
                            _ => (&mut self.state[c], state[c]),
                        };
                        let step = if central {
                            // Positions keep within the model's smooth reach; velocities have
                            // no kink.
                            let limit = if derivative == 2 {
                                self.step_limits[c]
                            } else {
                                f64::INFINITY
                            };
                            central_step(original, limit)
                        } else {
                            original.abs().max(1.0)
                        };
                        *slot = original + sign * step;
                        // The step actually taken, after rounding (the minus side adds to it).
                        if sign > 0.0 {
                            self.steps[c] = *slot - original;
                        } else {
                            self.steps[c] += original - *slot;
                        }
                    }
                    let out = if sign > 0.0 {
                        &mut self.probe
                    } else {
                        &mut self.minus
                    };
                    residual(&self.state, &self.qdd, out);
                    evals += 1;
                }
                for &c in &self.groups[g] {
                    let scale = weight / self.steps[c];
                    let lower = if central { &self.minus } else { &self.base };
                    for &(r, k) in &self.column_entries[c] {
                        values[k] += scale * (self.probe[r] - lower[r]);
                    }
                    match derivative {
                        0 => self.qdd[c] = qdd[c],
                        1 => self.state[n + c] = state[n + c],
                        _ => self.state[c] = state[c],
                    }
                }
            }
        }
        evals
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
