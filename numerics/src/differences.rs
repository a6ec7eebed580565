//! Finite differences: the coloured (Curtis–Powell–Reid) iteration matrix over a declared sparsity
//! pattern for systems without an analytic one, the central-difference step rule that keeps
//! probes off a kink, and the fourth-order Jacobian of an ODE right-hand side that the modal
//! analysis linearises with.

use crate::ode::OdeSystem;
use faer::Mat;

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
            for g in 0..self.groups.len() {
                evals += self.perturb_group(residual, derivative, g, state, qdd);
                self.accumulate_group(derivative, g, weight, state, qdd, values);
            }
        }
        evals
    }
}

impl ColouredDifferences {
    /// The residual at group `g`'s columns of `derivative` (0: q'', 1: q', 2: q) stepped up
    /// into `probe` and, for a central difference, stepped down into `minus`; the steps taken
    /// (after rounding) into `steps`. Returns the residual evaluations used.
    fn perturb_group(
        &mut self,
        residual: &mut ResidualFn<'_>,
        derivative: usize,
        g: usize,
        state: &[f64],
        qdd: &[f64],
    ) -> u64 {
        let n = self.n;
        // q'': R is linear, one forward difference is exact. q', q: central differences.
        let central = derivative != 0;
        let mut evals = 0;
        for sign in [1.0, -1.0].into_iter().take(if central { 2 } else { 1 }) {
            for &c in &self.groups[g] {
                let (slot, original) = match derivative {
                    0 => (&mut self.qdd[c], qdd[c]),
                    1 => (&mut self.state[n + c], state[n + c]),
                    _ => (&mut self.state[c], state[c]),
                };
                let step = if central {
                    // Positions keep within the model's smooth reach; velocities have no kink.
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
        evals
    }

    /// Group `g`'s differences, times `weight`, added into `values`; its columns restored.
    fn accumulate_group(
        &mut self,
        derivative: usize,
        g: usize,
        weight: f64,
        state: &[f64],
        qdd: &[f64],
        values: &mut [f64],
    ) {
        let n = self.n;
        let lower = if derivative != 0 {
            &self.minus
        } else {
            &self.base
        };
        for &c in &self.groups[g] {
            let scale = weight / self.steps[c];
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
