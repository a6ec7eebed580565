//! Linearisation of the closed loop about its rest state at an effector position: the
//! fourth-order finite-difference Jacobian of model + controller + tension limits
//! (`cdpr_numerics::differences::jacobian_within`), the coordinates a constraint holds fixed
//! dropped ([`cdpr_numerics::eigen::reduce`]), and every eigenpair classified
//! ([`crate::modes::classify`]).
//!
//! The elastic model's Jacobian has a closed form (the geometric stiffness Σ T_i/l_i (I − e_i
//! e_iᵀ), MODELS.md §3); it is the test oracle for this path (`verify/tests/modes.rs`) rather
//! than a second code path. Constrained coordinates (the lumped model's stored nodes, z = ż = 0,
//! MODELS.md §4) have zero rows and columns that act on perturbations the constraint forbids, so
//! they are dropped before the eigen-analysis; the eigenvectors are mapped back with zeros there.
//! Open loop (tensions fixed at the equilibrium's), the PID states are dropped too: they integrate
//! the error but do not act.

use crate::AnalysisError;
use crate::modes::{Analysis, ClassifiedMode, Loop, classify};
use cdpr_core::closed_loop::{Actuation, ClosedLoop};
use cdpr_core::controller::Controller;
use cdpr_core::modal_layout::ModalLayout;
use cdpr_core::model::{CableModel, Equilibrium};
use cdpr_core::robot::height;
use cdpr_core::scenario::Scenario;
use cdpr_core::shaper::Impulses;
use cdpr_core::trajectory::Step5;
use cdpr_numerics::differences::{jacobian, jacobian_within};
use cdpr_numerics::eigen::{Mode, ModeShape, mode_shapes, modes, nearest_mode, reduce};
use faer::Mat;

/// Jacobian ∂y'/∂y of the closed loop (model and PID states; the audit states are left out) at
/// (t, y) by central differences ([`jacobian`] for the step rule).
pub fn closed_loop_jacobian<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    t: f64,
    y: &[f64],
) -> Mat<f64> {
    let n = sys.dynamic_len();
    jacobian(sys, t, y, n)
}

/// A linearisation with the raw eigenvectors kept (for perturbing a nonlinear run along a mode).
pub struct Linearised {
    pub analysis: Analysis,
    /// Closed-loop state of the equilibrium (model | controller | W | D).
    pub state: Vec<f64>,
    /// For each mode of `analysis.modes` (same order), its eigenvector mapped back to the model and
    /// PID states of `state` (zeros on frozen coordinates and, open loop, on the PID states).
    pub vectors: Vec<Vec<(f64, f64)>>,
}

/// Modal analysis of `model` in the scenario's closed loop at effector position `x` [m]: the
/// static equilibrium of MODELS.md §2 there, with the reference held at x.
pub fn linearise<M: CableModel<D>, const D: usize>(
    model: M,
    scenario: &Scenario,
    x: f64,
    feedback: Loop,
) -> Result<Linearised, AnalysisError> {
    let mut sys = ClosedLoop::new(model, scenario)?;
    check_size(sys.dynamic_len())?;
    if sys.controller.kind().acts_on_z() {
        // The held height z0 is the start equilibrium's.
        sys.initial_state()?;
    }
    // Hold the reference at x: the loop is then autonomous and x is its equilibrium.
    sys.trajectory = Step5 {
        x1: x,
        x2: x,
        ..sys.trajectory
    };
    sys.shaper = Some(Impulses::none());
    let (y, eq) = sys.rest_state(x)?;
    let tensions = sys.rest_tensions();
    if feedback == Loop::Open {
        sys.actuation = Actuation::Prescribed(Box::new(move |_| tensions));
    }
    let n = sys.model_len();
    let np = n / 2;
    let layout = sys.model.modal_layout(&eq.state);
    let free: Vec<usize> = (0..np).filter(|i| !layout.frozen.contains(i)).collect();
    let mut keep: Vec<usize> = free
        .iter()
        .copied()
        .chain(free.iter().map(|i| np + i))
        .collect();
    let m = sys.dynamic_len();
    if feedback == Loop::Closed {
        keep.extend(n..m);
    }
    // The stencil stays where the forces are smooth, as the models' own iteration matrices do:
    // on fine meshes the springs' stretch falls below the default reach (lumped N = 200 at
    // x = 0.5: ≈ 2.8e-6 m against 3e-6·|x|) and the slack side under-reads the axial stiffness.
    let mut reach = vec![f64::INFINITY; m];
    if let Some(form) = sys.model.second_order() {
        form.smooth_reach(&y[..n], &mut reach[..np]);
    }
    // Velocities at rest: a step scale of 1 m/s (the step5 peak speed is 0.94 m/s), see
    // `cdpr_numerics::differences::jacobian_within`.
    let mut scale = vec![1e-3; m];
    scale[np..n].fill(1.0);
    let jac = jacobian_within(&mut sys, 0.0, &y, m, &reach, &scale);
    let shapes = mode_shapes(&reduce(&jac, &keep))?;
    let (modes, vectors) = classified(&shapes, &keep, (m, np), &layout);
    let p = sys.model.effector(&eq.state).position;
    Ok(Linearised {
        analysis: Analysis {
            model: sys.model.name(),
            x: p[0],
            z: height(&p),
            feedback,
            tensions,
            modes,
        },
        state: y,
        vectors,
    })
}

/// Each mode shape of the reduced loop mapped back to its `m` states (zeros on the dropped
/// coordinates), classified by its `np` positions on the model's layout and numbered within its
/// kind.
fn classified(
    shapes: &[ModeShape],
    keep: &[usize],
    (m, np): (usize, usize),
    layout: &ModalLayout,
) -> (Vec<ClassifiedMode>, Vec<Vec<(f64, f64)>>) {
    let mut modes = Vec::with_capacity(shapes.len());
    let mut vectors = Vec::with_capacity(shapes.len());
    for shape in shapes {
        let mut full = vec![(0.0, 0.0); m];
        for (k, &i) in keep.iter().enumerate() {
            full[i] = shape.vector[k];
        }
        let (kind, purity) = classify(layout, &full[..np]);
        modes.push(ClassifiedMode {
            mode: shape.mode,
            kind,
            order: 0,
            purity,
        });
        vectors.push(full);
    }
    let mut counts = std::collections::HashMap::new();
    for m in &mut modes {
        let c = counts.entry(m.kind).or_insert(0);
        *c += 1;
        m.order = *c;
    }
    (modes, vectors)
}

/// Largest linearised loop (model states + the two controller states) whose modes are computed:
/// the dense finite-difference Jacobian and eigen-decomposition cost O(n) right-hand sides, O(n²)
/// memory and O(n³) time (about 4 s and 0.1 GB at the limit on this 2-core machine; a lumped
/// N = 1000 loop, 8 004 states, would take minutes and 1.5 GB, N = 10 000 51 GB).
pub const DENSE_MAX_STATES: usize = 2000;

/// Refuses a loop of `states` states above [`DENSE_MAX_STATES`].
fn check_size(states: usize) -> Result<(), AnalysisError> {
    if states > DENSE_MAX_STATES {
        return Err(AnalysisError::TooLarge {
            states,
            limit: DENSE_MAX_STATES,
        });
    }
    Ok(())
}

/// The settled end of the move: the static equilibrium at x2 and the closed-loop mode there.
#[derive(Debug, Clone)]
pub struct EndState {
    /// Closed-loop mode nearest the guess (eq. 15 for the vertical mode).
    pub mode: Mode,
    /// Static equilibrium at x2 (MODELS.md §2 rule).
    pub equilibrium: Equilibrium,
    /// Effector position there [m], per axis, the vertical last.
    pub effector: Vec<f64>,
}

impl EndState {
    /// The effector's height there [m].
    pub fn effector_height(&self) -> f64 {
        self.effector.last().copied().unwrap_or(f64::NAN)
    }
}

/// [`EndState`] of `sys` at the trajectory's x2: the closed-loop mode nearest `omega_guess`
/// [rad/s], from the finite-difference Jacobian of model + controller.
pub fn end_state<M: CableModel<D>, const D: usize>(
    mut sys: ClosedLoop<M, D>,
    omega_guess: f64,
) -> Result<EndState, AnalysisError> {
    check_size(sys.dynamic_len())?;
    // At rest at x2: the reference there, unshaped.
    sys.shaper = Some(Impulses::none());
    let (y, eq) = sys.rest_state(sys.trajectory.x2)?;
    // After t2 the reference is constant: the loop is autonomous there.
    let t = sys.trajectory.t2 + 1.0;
    let jac = closed_loop_jacobian(&mut sys, t, &y);
    let modes = modes(&jac).map_err(AnalysisError::Eigen)?;
    let mode = nearest_mode(&modes, omega_guess).ok_or(AnalysisError::NoMode)?;
    let effector = sys.model.effector(&eq.state).position.as_slice().to_vec();
    Ok(EndState {
        mode,
        equilibrium: eq,
        effector,
    })
}
