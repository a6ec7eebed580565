//! Static equilibrium of the lumped model (MODELS.md §2, §4): effector x held at x_ref(0), the PID
//! force F0 an unknown, by the core's Newton service.
//!
//! Unknowns: x of each stored node, (x, z) of each free node, the effector's z, and F0. The split
//! r_i between stored and free nodes is guessed from the chord (unstrained free length ≈
//! chord/(1 + T/EA), N − r = ⌊that/l0⌋), then checked against the side rule at the solution and
//! shifted by one node until it holds, so any start position inside the workspace finds its own
//! straddling spring.
//!
//! The kink of the straddling spring's length at the pulley (eq. 4) is kept out of Newton's way:
//! an exact Jacobian (no difference step across it), steps that keep the boundary nodes on their
//! side, and a node that stalls at the pulley is moved across. Sweeps of x ∈ [0.15, 0.85] m,
//! ΣT ∈ [120, 400] N found 2 failing starts in 2 000 without any of these; 0 in 500 000 with
//! all of them (the docs of each say what removing it alone brings back).

use crate::pulley::beyond;
use crate::{Lumped, TOWARD_REEL};
use cdpr_core::model::{CableModel, Equilibrium, ModelError, RestRule};
use cdpr_core::robot::Tensions;
use cdpr_core::second_order::SecondOrderForm;
use cdpr_core::statics;
use cdpr_numerics::newton::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector2;

/// The unknowns ↔ state map and the force residual for a fixed split r.
struct Problem<'a> {
    model: Lumped,
    effector_x: f64,
    rule: &'a dyn RestRule<2>,
    /// State vector being assembled (velocities stay zero).
    y: Vec<f64>,
    forces: Vec<f64>,
    /// State indices of the length unknowns, in order (F0 is the last unknown).
    map: Vec<usize>,
    /// Inverse of `map`: the unknown of each position coordinate, if it is one.
    unknown: Vec<Option<usize>>,
    /// The Jacobian's pattern, from the model's iteration pattern (over the positions q).
    pattern: statics::StaticPattern,
    /// [`Lumped::tangent_matrix`]'s values at c_q = 1, and diag(m) in the same order (which no
    /// state changes).
    tangent: Vec<f64>,
    masses: Vec<f64>,
}

impl<'a> Problem<'a> {
    fn new(model: Lumped, effector_x: f64, rule: &'a dyn RestRule<2>) -> Self {
        let mut map = Vec::new();
        for cable in 0..2 {
            for j in 0..model.elements {
                map.push(model.x_index(cable, j));
                if j >= model.stored()[cable] {
                    map.push(model.z_index(cable, j));
                }
            }
        }
        map.push(model.z_index(0, model.elements));
        let mut unknown = vec![None; model.positions_len()];
        for (k, &i) in map.iter().enumerate() {
            unknown[i] = Some(k);
        }
        let dynamic = model.iteration_pattern();
        let mut masses = vec![0.0; dynamic.len()];
        model.mass_matrix_into(&mut masses);
        let mut problem = Self {
            y: vec![0.0; model.state_len()],
            forces: vec![0.0; model.positions_len()],
            tangent: vec![0.0; dynamic.len()],
            masses,
            pattern: statics::StaticPattern::default(),
            unknown,
            model,
            effector_x,
            rule,
            map,
        };
        problem.pattern = statics::pattern_from_dynamics(
            &dynamic,
            |i| problem.row_of(i),
            |j| problem.unknown[j],
            &problem.model.tension_rows(),
            problem.map.len(),
        );
        problem
    }

    /// The equation of position row `i`: its force balance, or F0's for the effector's x.
    fn row_of(&self, i: usize) -> Option<usize> {
        if i == self.model.effector_x() {
            Some(self.map.len())
        } else {
            self.unknown[i]
        }
    }

    fn tensions(&self, force: f64) -> Tensions {
        self.rule.tensions(&[force])
    }

    fn load(&mut self, u: &[f64]) {
        for (k, &i) in self.map.iter().enumerate() {
            self.y[i] = u[k];
        }
        self.y[self.model.effector_x()] = self.effector_x;
    }
}

impl StaticProblem for Problem<'_> {
    fn dimension(&self) -> usize {
        self.map.len() + 1
    }
    fn length_unknowns(&self) -> usize {
        self.map.len()
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.load(u);
        let tensions = self.tensions(u[self.map.len()]);
        self.model.forces(&self.y, &tensions, &mut self.forces);
        for (k, &i) in self.map.iter().enumerate() {
            r[k] = self.forces[i];
        }
        // The effector's horizontal balance closes the system for F0.
        r[self.map.len()] = self.forces[self.model.effector_x()];
    }
    /// The chain's pattern (`SecondOrderForm::iteration_pattern`) over the unknowns; the
    /// effector's x row is F0's equation.
    fn pattern(&self) -> Option<Vec<(usize, usize)>> {
        Some(self.pattern.entries.clone())
    }
    /// Exact, from the springs' tangent stiffness ([`Lumped::tangent_matrix`] gives
    /// S = diag(m) − c_q ∂F/∂q, so diag(m) − S(1) = ∂F/∂q; the residual here is F), the entries
    /// [`Self::pattern`] keeps ([`statics::StaticPattern::kept`]), then F0's column:
    /// T_i = (ΣT ∓ F0)/2 pulls P_0 along e_out (MODELS.md §4). Why not differences: an iterate
    /// whose boundary node comes within their step (6e-10 m) of its pulley has them straddle
    /// the kink of eq. 4's |P − A|, and Newton stalled there (6 of 500 000 starts over the
    /// proptest's ranges, with the other mends in place; 1 with this Jacobian, mended by
    /// [`Self::step_limit`]). The tangent stiffness itself is checked against differences over
    /// shaken equilibria, straddling spring included, in `implicit.rs`. False
    /// (differences instead) exactly at a pulley. Exact for damped cables too: at rest every
    /// λ' = 0, so the Kelvin–Voigt term and its position derivative vanish.
    fn jacobian(&mut self, u: &[f64], values: &mut [f64]) -> bool {
        self.load(u);
        if !self
            .model
            .tangent_matrix(&self.y, (0.0, 1.0), 0.0, &mut self.tangent)
        {
            return false;
        }
        let kept = &self.pattern.kept;
        for (value, &p) in values.iter_mut().zip(kept) {
            *value = self.masses[p] - self.tangent[p];
        }
        let mut at = kept.len();
        let slope = self.rule.slope(0);
        for (cable, row) in self.model.tension_rows().into_iter().enumerate() {
            if self.row_of(row).is_some() {
                values[at] = slope[cable] * TOWARD_REEL[cable];
                at += 1;
            }
        }
        debug_assert_eq!(at, values.len());
        true
    }
    /// Fraction to the kink: the boundary nodes (last stored, first free) keep at least
    /// [`KINK_KEEP`] of their distance from their pulley, so an iterate cannot land on eq. 4's
    /// kink, where |P − A| has no derivative; a node whose equilibrium lies across it approaches
    /// geometrically and Newton stops near it, for [`split_across_kink`] to move the node over.
    /// The free node's bound uses the step's length (|P + λδ − A| ≥ |P − A| − λ|δ|).
    fn step_limit(&mut self, u: &[f64], delta: &[f64]) -> f64 {
        self.load(u);
        let model = &self.model;
        let step = |i: usize| self.unknown[i].map_or(0.0, |k| delta[k]);
        let mut limit = 1.0f64;
        // A node already on its pulley or across it (room ≤ 0: a guess that put it there) has
        // no side to keep; the side rule sorts it out at the solution.
        let mut keep = |room: f64, toward: f64| {
            if room > 0.0 && toward > (1.0 - KINK_KEEP) * room {
                limit = limit.min((1.0 - KINK_KEEP) * room / toward);
            }
        };
        for (cable, r) in model.stored().into_iter().enumerate() {
            if r > 0 {
                let j = r - 1;
                keep(
                    beyond(model, &self.y, cable, j),
                    -step(model.x_index(cable, j)) * TOWARD_REEL[cable],
                );
            }
            if r < model.elements {
                let offset = model.node(&self.y, cable, r) - model.pulley(cable);
                let moved =
                    Vector2::new(step(model.x_index(cable, r)), step(model.z_index(cable, r)));
                keep(offset.norm(), moved.norm());
            }
        }
        limit
    }
    fn residual_round_off(&self) -> f64 {
        self.model.residual_round_off(&self.y)
    }
    /// Finite-difference scales, for where [`Self::jacobian`] declines (a node exactly at its
    /// pulley): 1e-4 m for coordinates, a 6e-10 m step, far inside a spring's
    /// stretch (T/k0 = 8e-6 m at 60 N; a step beyond it slackens the spring and corrupts the
    /// Jacobian) and still moving forces by 4e-3 N against a 2e-9 N round-off. ΣT for F0, on
    /// which the residual depends linearly.
    fn scale(&self, i: usize) -> f64 {
        if i == self.map.len() {
            self.rule.scale(0)
        } else {
            1e-4
        }
    }
}

/// Straight-chord guess: the number of free springs of each cable, and nodes at uniform strain
/// along the chord A_i → P and along the reel line.
fn guess(model: &mut Lumped, effector: Vector2<f64>, tension: f64, ea: f64) -> Vec<f64> {
    let n = model.elements;
    let stretch = 1.0 + tension / ea;
    let mut stored = [0; 2];
    let mut y = vec![0.0; model.state_len()];
    for cable in 0..2 {
        let a = model.pulley(cable);
        let chord = effector - a;
        let free = chord.norm() / stretch;
        let free_springs = ((free / model.segment).floor() as usize).min(n - 1);
        let r = n - free_springs;
        stored[cable] = r;
        let u = chord / chord.norm();
        for j in 0..n {
            // Unstrained distance of node j from the pulley along the cable path (negative: stored).
            let s = free - (n - j) as f64 * model.segment;
            let p = if s >= 0.0 {
                a + u * (s * stretch)
            } else {
                a + Vector2::new(TOWARD_REEL[cable], 0.0) * (-s * stretch)
            };
            y[model.x_index(cable, j)] = p.x;
            y[model.z_index(cable, j)] = if s >= 0.0 { p.y } else { 0.0 };
        }
    }
    y[4 * n] = effector.x;
    y[4 * n + 1] = effector.y;
    model.set_stored(stored);
    y
}

/// Splits tried before giving up (a start needs at most one or two shifts).
const MAX_SPLITS: usize = 6;

/// Least distance from the pulley at which [`reclassify`] starts a node that changes sides, and
/// within which [`split_across_kink`] finds a stalled node [multiples of l0]. 1e-4·l0 = 2.5e-6 m
/// on the paper's cable: below the springs' stretch T/k0 (8e-6 m at 60 N), so moving a node by
/// it slackens no spring. 1e-3·l0 (2.5e-5 m) did slacken them (238 N of residual, no Newton
/// step reducing it) in 7 of 70 000 starts x ∈ [0.15, 0.85] m, ΣT ∈ [120, 400] N.
const PULLEY_GAP: f64 = 1e-4;

/// The least fraction of its distance from its pulley a boundary node keeps over one Newton
/// step ([`StaticProblem::step_limit`]): 1/10, so a node whose solution is 2.85e-8 m from the
/// pulley (x = 0.324825 m, ΣT = 231.44 N) is reached from the 2.5e-6 m start in two steps.
const KINK_KEEP: f64 = 0.1;

/// Switches to the split `stored`: a node changing sides starts just on its new side of the
/// pulley, on its new path (the straddling spring's length has a kink at the pulley that Newton
/// cannot cross).
fn reclassify(model: &mut Lumped, y: &mut [f64], stored: [usize; 2], effector_x: f64) {
    let n = model.elements;
    let effector = Vector2::new(effector_x, y[model.z_index(0, n)]);
    for cable in 0..2 {
        let (old, new) = (model.stored()[cable], stored[cable]);
        if old == new {
            continue;
        }
        let a = model.pulley(cable);
        let j = old.min(new);
        let gap = (model.node(y, cable, j) - a)
            .norm()
            .max(PULLEY_GAP * model.segment);
        let p = if new > old {
            a + Vector2::new(TOWARD_REEL[cable] * gap, 0.0)
        } else {
            a + (effector - a).normalize() * gap
        };
        y[model.x_index(cable, j)] = p.x;
        y[model.z_index(cable, j)] = p.y;
    }
    model.set_stored(stored);
}

/// The split with each cable's boundary moved by one node where `crossed(cable, j, stored)` says
/// its last stored node (`stored`) or else its first free node j belongs on the other side;
/// None if no boundary moves. The one rule behind both checks of [`equilibrium`].
fn shifted_split(
    model: &Lumped,
    crossed: impl Fn(usize, usize, bool) -> bool,
) -> Option<[usize; 2]> {
    let mut stored = model.stored();
    let mut shifted = false;
    for (cable, r) in stored.iter_mut().enumerate() {
        if *r > 0 && crossed(cable, *r - 1, true) {
            *r -= 1;
            shifted = true;
        } else if *r < model.elements && crossed(cable, *r, false) {
            *r += 1;
            shifted = true;
        }
    }
    shifted.then_some(stored)
}

/// The split with a stalled boundary node moved across the pulley, if one stalled there (within
/// [`PULLEY_GAP`], on either side). When a split's solution lies across the pulley for its last
/// stored node (first free node), the straddling spring's length |P_(r−1) − A| + |A − P_r|
/// folds back at A, where it has no derivative, and [`StaticProblem::step_limit`] keeps the
/// node on its side: Newton creeps up to the kink and fails there (before the step limit it
/// stalled on it: x = 0.1745 m, ΣT = 197 N, node 33 of cable 0 1e-10 m beyond the pulley,
/// 0.075 N unbalanced). That node belongs to the other side. Run on failures only; a node of
/// the other cable that merely sits close gets shifted too, and the side rule at the next
/// solution shifts it back (each shift spends one of [`MAX_SPLITS`]).
fn split_across_kink(model: &Lumped, y: &[f64]) -> Option<[usize; 2]> {
    let radius = PULLEY_GAP * model.segment;
    shifted_split(model, |cable, j, _| {
        (model.node(y, cable, j) - model.pulley(cable)).norm() < radius
    })
}

/// The split the side rule asks for at a solution (MODELS.md §4): the last stored node must lie
/// beyond the pulley, the first free node not; None if both do.
fn split_by_side_rule(model: &Lumped, y: &[f64]) -> Option<[usize; 2]> {
    shifted_split(model, |cable, j, stored| {
        (beyond(model, y, cable, j) > 0.0) != stored
    })
}

/// Equilibrium under `rule` (the effector's x pinned, one parameter: the paper's rule) with the
/// split found by the side rule (MODELS.md §2, §4).
pub(crate) fn equilibrium(
    model: &mut Lumped,
    rule: &dyn RestRule<2>,
) -> Result<Equilibrium, ModelError> {
    let (effector_x, tension_sum) =
        cdpr_core::model::planar_rest(rule, model.anchor_distance, "lumped")?;
    let d = model.anchor_distance;
    // Massless-cable sag as the effector's starting depth; the cable weight adds ~1 %.
    let weight = model.effector_mass * model.gravity;
    let sag = -weight * effector_x * (d - effector_x) / (0.5 * tension_sum * d);
    let ea = model.stiffness * model.segment;
    let mut y = guess(model, Vector2::new(effector_x, sag), 0.5 * tension_sum, ea);
    for _attempt in 0..MAX_SPLITS {
        let mut problem = Problem::new(model.clone(), effector_x, rule);
        let mut u: Vec<f64> = problem.map.iter().map(|&i| y[i]).collect();
        u.push(0.0);
        let solved = newton::solve(&mut problem, &mut u, NewtonOptions::default());
        problem.load(&u);
        y.copy_from_slice(&problem.y);
        let report = match solved {
            Ok(report) => report,
            Err(error) => match split_across_kink(model, &y) {
                Some(shifted) => {
                    reclassify(model, &mut y, shifted, effector_x);
                    continue;
                }
                None => return Err(error.into()),
            },
        };
        // Side rule at the solution: shift the split where the last stored node is not beyond
        // the pulley or the first free node is. The step limit keeps both boundary nodes on
        // their side from a start on their side, so this catches starts that were not (the
        // chord guess, a re-split).
        match split_by_side_rule(model, &y) {
            Some(shifted) => reclassify(model, &mut y, shifted, effector_x),
            None => {
                let force = u[problem.map.len()];
                return Ok(Equilibrium {
                    state: y,
                    parameters: vec![force],
                    tensions: rule.tensions(&[force]),
                    iterations: report.iterations,
                    residual: report.residual,
                });
            }
        }
    }
    Err(ModelError::State {
        t: 0.0,
        why: format!(
            "no consistent stored/free split found for the effector at x = {effector_x} m"
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Params;
    use cdpr_core::model::SplitRule;
    use cdpr_core::scenario::Scenario;

    /// The exact static Jacobian against central differences of the residual, entry by entry
    /// and outside the pattern too, at the x = 0.6 m equilibrium (F0 ≠ 0, unequal splits) with
    /// every unknown shaken by up to 3e-6 m (inside the springs' ~1.3e-5 m stretch, so none goes
    /// slack). Per column, against that column's largest entry (F0's column is 0.5, beside
    /// k0 = 7.5e6 N/m): steps 1e-9 m (round-off ~2e-9 N / 1e-9 m ≈ 2 N/m, 3e-7 of k0) and 1e-3 N
    /// for F0 (the residual is affine in it). Measured 3.5e-8; bound 1e-6. A flipped F0 column
    /// fails it.
    #[test]
    fn static_jacobian_matches_central_differences() {
        let s = Scenario::paper();
        let mut model = Lumped::new(&s, Params::default()).unwrap();
        let rule = SplitRule::new(0.6, 200.0);
        let eq = model.equilibrium(&rule).unwrap();
        let mut problem = Problem::new(model, 0.6, &rule);
        let n = problem.dimension();
        let mut u: Vec<f64> = problem.map.iter().map(|&i| eq.state[i]).collect();
        u.push(eq.force());
        for (k, v) in u.iter_mut().enumerate().take(n - 1) {
            *v += 3e-6 * (1.3 * k as f64).sin();
        }
        let pattern = problem.pattern().unwrap();
        let mut values = vec![0.0; pattern.len()];
        assert!(problem.jacobian(&u, &mut values));
        assert!(values.iter().all(|v| v.is_finite()));
        let mut exact = vec![0.0; n * n];
        for (&(r, c), v) in pattern.iter().zip(&values) {
            exact[r * n + c] += v;
        }
        let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
        let mut ratio = 0.0f64;
        for c in 0..n {
            let (mut worst, mut largest) = (0.0f64, 0.0f64);
            let h = if c == n - 1 { 1e-3 } else { 1e-9 };
            let mut moved = u.clone();
            moved[c] += h;
            problem.residual(&moved, &mut plus);
            moved[c] -= 2.0 * h;
            problem.residual(&moved, &mut minus);
            for r in 0..n {
                let differenced = (plus[r] - minus[r]) / (2.0 * h);
                assert!(differenced.is_finite(), "({r}, {c})");
                worst = worst.max((differenced - exact[r * n + c]).abs());
                largest = largest.max(differenced.abs());
            }
            ratio = ratio.max(worst / largest);
        }
        assert!(
            ratio < 1e-6,
            "worst column error {ratio:e} of its largest entry"
        );
    }
}
