//! Statics of the spatial FE robot (MODELS.md FE.8.1 at a pose, §11): F(q, 0, T) = 0 with the
//! effector pinned at the rule's pose and the cables' weight carried by a tension correction
//! T = T0 + W⁺ δw (the least in the tensions' norm, as the lumped lines'), by the core's Newton
//! service from the sagging guess: nodes on each chord A_i → P lowered by the parabola of the
//! span's weight, l_i its arc over (1 + T_i/EA), ρ_i = (L0 − l_i)(1 + T_i/EA).
//!
//! Unknowns: every coordinate of q but the effector's three, then δw (3); equations: every row
//! of F. The Jacobian is sparse — the element blocks' ∂F/∂q (as the implicit path's, at rest)
//! over the model's pattern, and the exact δw columns in the ρ rows (F is affine in the
//! tensions) — and is solved by the sparse LU: O(N m) per iteration at any N.

use super::FeSpatial;
use cdpr_core::model::{CableModel, Equilibrium, ModelError, RestRule};
use cdpr_core::robot::{Matrix, PerCable, StructureMatrix, Tensions, Vector};
use cdpr_core::second_order::SecondOrderForm;
use cdpr_core::statics::{self, StaticPattern};
use cdpr_numerics::newton::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector3;

struct Problem<'a> {
    model: &'a mut FeSpatial,
    pose: Vector3<f64>,
    base: Tensions,
    w: StructureMatrix<3>,
    gram_inv: Matrix<3>,
    /// The state being assembled (velocities stay zero) and the forces' scratch.
    y: Vec<f64>,
    forces: Vec<f64>,
    /// Indices in q of the unknown coordinates, in order (δw follows).
    map: Vec<usize>,
    /// The Jacobian's pattern (the model's over the unknowns, then δw's columns axis by axis
    /// in the ρ rows), ∂R/∂q's scratch and q'' = 0.
    pattern: StaticPattern,
    rho_rows: Vec<usize>,
    stiffness: Vec<f64>,
    at_rest: Vec<f64>,
}

impl Problem<'_> {
    fn tensions(&self, dw: &[f64]) -> Tensions {
        let lambda = self.gram_inv * Vector::<3>::new(dw[0], dw[1], dw[2]);
        PerCable::from_fn(self.base.len(), |i| {
            self.base[i] + self.w.column(i).dot(&lambda)
        })
    }

    fn load(&mut self, u: &[f64]) {
        for (k, &i) in self.map.iter().enumerate() {
            self.y[i] = u[k];
        }
        for a in 0..3 {
            let p = self.model.effector_index(a);
            self.y[p] = self.pose[a];
        }
    }
}

impl StaticProblem for Problem<'_> {
    fn dimension(&self) -> usize {
        self.map.len() + 3
    }
    fn length_unknowns(&self) -> usize {
        self.map.len()
    }
    /// A tension-only element's stretch T/k is ~1e-5 of its length: steps well inside it.
    fn scale(&self, i: usize) -> f64 {
        if i < self.map.len() { 1e-4 } else { 1.0 }
    }
    /// The n rows of F(q, 0, T0 + W⁺ δw) [N].
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.load(u);
        let t = self.tensions(&u[self.map.len()..]);
        let mut forces = std::mem::take(&mut self.forces);
        self.model.rest_forces(&self.y, &t, &mut forces);
        r.copy_from_slice(&forces);
        self.forces = forces;
    }
    fn pattern(&self) -> Option<Vec<(usize, usize)>> {
        Some(self.pattern.entries.clone())
    }
    fn residual_round_off(&self) -> f64 {
        self.model.residual_round_off(&self.y)
    }
    /// The hub: the effector's rows (whose unknowns are δw's), the l_i and ρ_i rows and
    /// unknowns. Left in the interior with the l_i in the border (dense at N ≳ 11), the ρ rows
    /// alone would have to carry δw's columns and their own.
    fn coupled(&self) -> Vec<usize> {
        (self.model.effector_index(0)..self.map.len() + 3).collect()
    }
    /// Element by element (the blocks' ∂R/∂q at rest, sign changed: the residual is F), then
    /// δw's columns: ∂T_i/∂δw = (W⁺)ᵀ's row i, (WᵀW)⁻¹ w_i, in the ρ_i rows.
    fn jacobian(&mut self, u: &[f64], values: &mut [f64]) -> bool {
        self.load(u);
        let mut stiffness = std::mem::take(&mut self.stiffness);
        self.model
            .block_matrix(&self.y, &self.at_rest, [1.0, 0.0, 0.0], &mut stiffness);
        let (kept, columns) = values.split_at_mut(self.pattern.kept.len());
        for (value, &p) in kept.iter_mut().zip(&self.pattern.kept) {
            *value = -stiffness[p];
        }
        self.stiffness = stiffness;
        let m = self.rho_rows.len();
        for (a, column) in columns.chunks_mut(m).enumerate() {
            for (i, value) in column.iter_mut().enumerate() {
                *value = (self.gram_inv * self.w.column(i))[a];
            }
        }
        true
    }
}

/// The robot at rest at the rule's pose (every coordinate pinned), the tensions corrected by
/// W⁺ δw to carry the cables' weight.
pub(super) fn equilibrium(
    model: &mut FeSpatial,
    rule: &dyn RestRule<3>,
) -> Result<Equilibrium, ModelError> {
    if rule.pinned().len() != 3 {
        return Err(ModelError::State {
            t: 0.0,
            why: "the spatial FE model rests at a pose: all three coordinates pinned".into(),
        });
    }
    let mut pose = Vector3::zeros();
    for &(axis, value) in rule.pinned() {
        pose[axis] = value;
    }
    let base = rule.tensions(&[]);
    let w = model.robot().structure_matrix(&pose);
    let gram_inv = w.gram_inverse().ok_or_else(|| ModelError::State {
        t: 0.0,
        why: format!("the cables do not span space at {:?} m", pose.as_slice()),
    })?;
    let y = sagging_guess(model, &pose, &base)?;
    let np = model.positions_len();
    let effector: Vec<usize> = (0..3).map(|a| model.effector_index(a)).collect();
    let map: Vec<usize> = (0..np).filter(|i| !effector.contains(i)).collect();
    let mut u: Vec<f64> = map.iter().map(|&i| y[i]).collect();
    u.extend([0.0; 3]);
    let first = model.effector_index(0);
    let force = map.len();
    let rho_rows = model.tension_rows();
    let dynamic = model.iteration_pattern();
    let mut pattern = statics::pattern_from_dynamics(
        &dynamic,
        Some,
        |j| match j {
            _ if j < first => Some(j),
            _ if j < first + 3 => None,
            _ => Some(j - 3),
        },
        &rho_rows,
        force,
    );
    for axis in 1..3 {
        pattern
            .entries
            .extend(rho_rows.iter().map(|&row| (row, force + axis)));
    }
    let mut problem = Problem {
        stiffness: vec![0.0; dynamic.len()],
        at_rest: vec![0.0; np],
        model,
        pose,
        base,
        w,
        gram_inv,
        y,
        forces: vec![0.0; np],
        map,
        pattern,
        rho_rows,
    };
    let report = newton::solve(&mut problem, &mut u, NewtonOptions::default())?;
    problem.load(&u);
    let tensions = problem.tensions(&u[problem.map.len()..]);
    Ok(Equilibrium {
        state: problem.y,
        parameters: Vec::new(),
        tensions,
        iterations: report.iterations,
        residual: report.residual,
    })
}

/// Nodes on the chords lowered by the parabolic sag of the span's weight μ g under the
/// horizontal pull H = T_i d_h/d (d the chord, d_h its horizontal part): at ξ along it,
/// μ g d_h²/(2H) ξ(1 − ξ) = μ g d_h d/(2T_i) ξ(1 − ξ) — nought for a plumb line, at most a
/// quarter of the chord — and l_i N times the shortest element's length over the strain of its
/// tension, so that no element starts slack. Heavy lines (CoGiRo's 15 m of steel) do not converge from the
/// straight chords.
fn sagging_guess(
    model: &FeSpatial,
    pose: &Vector3<f64>,
    tensions: &Tensions,
) -> Result<Vec<f64>, ModelError> {
    let (n, np) = (model.elements, model.positions_len());
    let mut y = vec![0.0; 2 * np];
    for a in 0..3 {
        y[model.effector_index(a)] = pose[a];
    }
    let weight = model.material.mu * model.material.gravity;
    for cable in 0..model.robot().cables() {
        let a = model.pulley(cable);
        let chord = pose - a;
        let d = chord.norm();
        let pull = tensions[cable].max(f64::MIN_POSITIVE);
        let mid = (weight * chord.xy().norm() * d / (8.0 * pull)).min(0.0625 * d);
        let node = |k: usize| {
            let xi = k as f64 / n as f64;
            let mut p = a + chord * xi;
            p.z -= 4.0 * mid * xi * (1.0 - xi);
            p
        };
        let mut shortest = f64::INFINITY;
        for k in 1..=n {
            let p = node(k);
            shortest = shortest.min((p - node(k - 1)).norm());
            if k < n {
                for axis in 0..3 {
                    y[model.node_index(cable, k, axis)] = p[axis];
                }
            }
        }
        let stretch = 1.0 + tensions[cable].max(0.0) / model.material.ea;
        let l = n as f64 * shortest / stretch;
        if l >= model.modelled_length {
            return Err(ModelError::Parameter {
                name: "cable.modelled_length",
                value: model.modelled_length,
                allowed: format!(
                    "> {l} m, cable {}'s free unstrained length at {:?} m",
                    cable + 1,
                    pose.as_slice()
                ),
            });
        }
        let li = model.l_index(cable);
        y[li] = l;
        y[li + 1] = (model.modelled_length - l) * stretch;
    }
    Ok(y)
}
