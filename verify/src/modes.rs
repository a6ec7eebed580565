//! Closed-loop and open-loop modal analysis of every model (issue 7): linearise model + PID +
//! tension distribution about the static equilibrium at any effector position, compute every
//! eigenpair, and classify each mode from its eigenvector as effector vertical, effector
//! horizontal / controller, transverse string mode of cable 1 or 2, or axial mode of cable 1 or 2.
//!
//! Where the model knowledge lives. `cdpr-core` differentiates and decomposes without knowing what
//! a coordinate is ([`cdpr_core::modal`]); which coordinate is the effector, a free cable node (and
//! along which tangent the cable runs there), a coordinate along the cable (lumped stored nodes, FE
//! lengths l_i and ρ_i) or a constrained one (lumped stored nodes' z, MODELS.md §4 eq. 6) is said
//! here, by [`ModalLayout`], implemented for the three concrete models. This crate already is the one
//! place that knows every model; a `CableModel` trait method would have put a classification
//! vocabulary into the core interface for the sake of one analysis, and the core is being reworked
//! in parallel (the issue allows either; this keeps the core trait unchanged).
//!
//! Linearisation: central finite differences for all three models ([`cdpr_core::modal::jacobian`],
//! step rule and error bound there). The elastic model's Jacobian has a closed form (the geometric
//! stiffness Σ T_i/l_i (I − e_i e_iᵀ), MODELS.md §3); it is the test oracle for the FD path
//! (`verify/tests/modes.rs`) rather than a second code path. The massive models have no analytic
//! Jacobian here.
//!
//! Constrained coordinates: the lumped model's stored nodes have z = ż = 0 (MODELS.md §4): their
//! rows are zero and their columns act on perturbations the constraint forbids, so they are dropped
//! ([`cdpr_core::modal::reduce`]) before the eigen-analysis; the eigenvectors are mapped back with
//! zeros there. Open loop (PID off, tensions fixed at the equilibrium's), the PID states are
//! dropped too: they integrate the error but do not act.

use crate::SimulateError;
use cdpr_core::Vector2;
use cdpr_core::closed_loop::{Actuation, ClosedLoop};
use cdpr_core::modal::{self, Mode};
use cdpr_core::model::CableModel;
use cdpr_core::scenario::{ModelKind, Scenario};
use cdpr_core::trajectory::Step5;
use cdpr_elastic::Elastic;
use cdpr_fe::Fe;
use cdpr_lumped::Lumped;

/// What a group of position coordinates is, for the classification (indices into the model's
/// position coordinates, i.e. the first half of its state).
#[derive(Debug, Clone, PartialEq)]
pub enum Dof {
    /// The effector's x and z, mass M [kg].
    Effector { x: usize, z: usize, mass: f64 },
    /// A free cable node: its displacement along `tangent` is axial, across it transverse.
    Node {
        cable: usize,
        x: usize,
        z: usize,
        tangent: Vector2<f64>,
        mass: f64,
    },
    /// A coordinate that moves material along the cable (lumped stored node's x, FE l_i and ρ_i),
    /// with the mass that moves with it [kg].
    Axial {
        cable: usize,
        index: usize,
        mass: f64,
    },
}

/// The model's coordinates, as the classifier needs them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Layout {
    pub dofs: Vec<Dof>,
    /// Position coordinates held fixed by a constraint at this state (their velocities are
    /// frozen too).
    pub frozen: Vec<usize>,
}

/// Model knowledge for the modal classification.
pub trait ModalLayout {
    /// The coordinate groups and constrained coordinates at the model state `state`.
    fn layout(&self, state: &[f64]) -> Layout;
}

impl ModalLayout for Elastic {
    fn layout(&self, _state: &[f64]) -> Layout {
        Layout {
            dofs: vec![Dof::Effector {
                x: 0,
                z: 1,
                mass: self.effector_mass,
            }],
            frozen: Vec::new(),
        }
    }
}

impl ModalLayout for Lumped {
    fn layout(&self, y: &[f64]) -> Layout {
        let n = self.elements;
        let mut layout = Layout {
            dofs: vec![Dof::Effector {
                x: self.xi(0, n),
                z: self.zi(0, n),
                mass: self.effector_mass,
            }],
            frozen: Vec::new(),
        };
        for cable in 0..2 {
            let r = self.stored()[cable];
            for j in 0..n {
                let (x, z) = (self.xi(cable, j), self.zi(cable, j));
                if j < r {
                    layout.frozen.push(z);
                    layout.dofs.push(Dof::Axial {
                        cable,
                        index: x,
                        mass: self.node_mass,
                    });
                } else {
                    let prev = if j == r {
                        self.pulley(cable)
                    } else {
                        self.node(y, cable, j - 1)
                    };
                    let next = self.node(y, cable, j + 1);
                    layout.dofs.push(Dof::Node {
                        cable,
                        x,
                        z,
                        tangent: (next - prev).normalize(),
                        mass: self.node_mass,
                    });
                }
            }
        }
        layout
    }
}

impl ModalLayout for Fe {
    fn layout(&self, y: &[f64]) -> Layout {
        let n = self.elements;
        let nn = self.chain_nodes();
        let p = self.effector_index();
        let mut layout = Layout {
            dofs: vec![Dof::Effector {
                x: self.node_coordinate(p, 0),
                z: self.node_coordinate(p, 1),
                mass: self.effector_mass,
            }],
            frozen: Vec::new(),
        };
        let mu = self.material.mu;
        for cable in 0..2 {
            let l = self.free_length(y, cable);
            for k in 1..n {
                let j = self.chain_index(cable, k).expect("k ≥ 1 is a chain node");
                let (prev, _) = self.node(y, cable, k - 1);
                let (next, _) = self.node(y, cable, k + 1);
                layout.dofs.push(Dof::Node {
                    cable,
                    x: j,
                    z: nn + j,
                    tangent: (next - prev).normalize(),
                    mass: mu * l / n as f64,
                });
            }
            // l_i moves material through every node of the span (weight ≈ the kinetic-energy
            // coefficient γ ≈ 1/3 of the span's mass); ρ_i moves the stored cable (c1 = 1/3).
            layout.dofs.push(Dof::Axial {
                cable,
                index: self.l_index(cable),
                mass: mu * l / 3.0,
            });
            if let Some(r) = self.rho_index(cable) {
                layout.dofs.push(Dof::Axial {
                    cable,
                    index: r,
                    mass: mu * (self.modelled_length - l) / 3.0,
                });
            }
        }
        layout
    }
}

/// What a mode is, by the largest share of its mass-weighted displacement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum ModeKind {
    /// The effector bouncing on the cables (eq. 15's mode).
    Vertical,
    /// The effector sliding along the workspace; in closed loop these are the PID's x poles.
    Horizontal,
    /// Transverse string mode of cable 1 or 2.
    Transverse(usize),
    /// Axial (stretch) mode of cable 1 or 2.
    Axial(usize),
}

impl std::fmt::Display for ModeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModeKind::Vertical => write!(f, "effector vertical"),
            ModeKind::Horizontal => write!(f, "effector horizontal / controller"),
            ModeKind::Transverse(c) => write!(f, "transverse cable {}", c + 1),
            ModeKind::Axial(c) => write!(f, "axial cable {}", c + 1),
        }
    }
}

/// One mode of one model, classified.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClassifiedMode {
    pub mode: Mode,
    pub kind: ModeKind,
    /// 1-based rank among the modes of the same kind, by frequency (the k of ω_k).
    pub order: usize,
    /// Share of the mass-weighted |displacement|² that `kind` holds (1: pure).
    pub purity: f64,
}

/// Whether the PID acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Loop {
    /// The paper's PID and tension distribution.
    Closed,
    /// Tensions fixed at the equilibrium's, PID states dropped.
    Open,
}

/// Every mode of a model at one effector position.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Analysis {
    pub model: &'static str,
    /// Effector x [m] of the static equilibrium.
    pub x: f64,
    /// Effector z [m] there.
    pub z: f64,
    pub feedback: Loop,
    /// Commanded tensions at the equilibrium [N].
    pub tensions: [f64; 2],
    /// Modes sorted by frequency (one of each conjugate pair; real modes have ω = 0).
    pub modes: Vec<ClassifiedMode>,
}

impl Analysis {
    /// The fastest-growing mode (largest σ).
    pub fn least_stable(&self) -> Option<&ClassifiedMode> {
        self.modes
            .iter()
            .max_by(|a, b| a.mode.growth.total_cmp(&b.mode.growth))
    }

    /// The `order`-th mode (1-based) of `kind`.
    pub fn find(&self, kind: ModeKind, order: usize) -> Option<&ClassifiedMode> {
        self.modes
            .iter()
            .find(|m| m.kind == kind && m.order == order)
    }

    /// The oscillatory vertical mode (the lowest of that kind).
    pub fn vertical(&self) -> Option<&ClassifiedMode> {
        self.modes
            .iter()
            .find(|m| m.kind == ModeKind::Vertical && m.mode.omega > 0.0)
    }
}

/// A linearisation with the raw eigenvectors kept (for perturbing a nonlinear run along a mode).
pub struct Linearised {
    pub analysis: Analysis,
    /// Closed-loop state of the equilibrium (model | w | f | W | D).
    pub state: Vec<f64>,
    /// For each mode of `analysis.modes` (same order), its eigenvector mapped back to the model and
    /// PID states of `state` (zeros on frozen coordinates and, open loop, on the PID states).
    pub vectors: Vec<Vec<(f64, f64)>>,
}

/// Modal analysis of the scenario's model at effector position `x` [m] (the static equilibrium of
/// MODELS.md §2 there, with the reference held at x).
pub fn analyse(scenario: &Scenario, x: f64, feedback: Loop) -> Result<Analysis, SimulateError> {
    Ok(linearise(scenario, x, feedback)?.analysis)
}

/// As [`analyse`], keeping the equilibrium state and the eigenvectors.
pub fn linearise(scenario: &Scenario, x: f64, feedback: Loop) -> Result<Linearised, SimulateError> {
    match scenario.model.kind {
        ModelKind::Elastic => linearise_model(Elastic::new(scenario), scenario, x, feedback),
        ModelKind::Lumped => linearise_model(Lumped::new(scenario)?, scenario, x, feedback),
        ModelKind::Fe => linearise_model(Fe::new(scenario)?, scenario, x, feedback),
    }
}

/// As [`linearise`] for a given model (e.g. a hand-built one in tests).
pub fn linearise_model<M: CableModel + ModalLayout>(
    model: M,
    scenario: &Scenario,
    x: f64,
    feedback: Loop,
) -> Result<Linearised, SimulateError> {
    let mut sys = ClosedLoop::new(model, scenario);
    // Hold the reference at x: the loop is then autonomous and x is its equilibrium.
    sys.trajectory = Step5 {
        x1: x,
        x2: x,
        ..sys.trajectory
    };
    let (y, eq) = sys.rest_state(x)?;
    let tensions = sys.distribution.tensions(eq.force);
    if feedback == Loop::Open {
        sys.actuation = Actuation::Prescribed(Box::new(move |_| tensions));
    }
    let n = sys.model_len();
    let np = n / 2;
    let layout = sys.model.layout(&eq.state);
    let free: Vec<usize> = (0..np).filter(|i| !layout.frozen.contains(i)).collect();
    let mut keep: Vec<usize> = free
        .iter()
        .copied()
        .chain(free.iter().map(|i| np + i))
        .collect();
    if feedback == Loop::Closed {
        keep.extend([n, n + 1]);
    }
    // The stencil stays where the forces are smooth, as the models' own iteration matrices do:
    // on fine meshes the springs' stretch falls below the default reach (lumped N = 200 at
    // x = 0.5: ≈ 2.8e-6 m against 3e-6·|x|) and the slack side under-reads the axial stiffness.
    let mut reach = vec![f64::INFINITY; n + 2];
    if let Some(form) = sys.model.second_order() {
        form.smooth_reach(&y[..n], &mut reach[..np]);
    }
    // Velocities at rest: a step scale of 1 m/s (the step5 peak speed is 0.94 m/s), see
    // `modal::jacobian_within`.
    let mut scale = vec![1e-3; n + 2];
    scale[np..n].fill(1.0);
    let jac = modal::jacobian_within(&mut sys, 0.0, &y, n + 2, &reach, &scale);
    let shapes = modal::mode_shapes(&modal::reduce(&jac, &keep))?;
    let mut modes = Vec::with_capacity(shapes.len());
    let mut vectors = Vec::with_capacity(shapes.len());
    for shape in &shapes {
        let mut full = vec![(0.0, 0.0); n + 2];
        for (k, &i) in keep.iter().enumerate() {
            full[i] = shape.vector[k];
        }
        let (kind, purity) = classify(&layout, &full[..np]);
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
    let p = sys.model.effector(&eq.state).position;
    Ok(Linearised {
        analysis: Analysis {
            model: sys.model.name(),
            x: p.x,
            z: p.y,
            feedback,
            tensions,
            modes,
        },
        state: y,
        vectors,
    })
}

/// The kind holding the largest share of Σ m |u|² over the position part `u` of an eigenvector,
/// and that share. Effector: x → horizontal, z → vertical; a free node: its component along the
/// cable tangent → axial, across → transverse; an axial coordinate → axial.
pub fn classify(layout: &Layout, u: &[(f64, f64)]) -> (ModeKind, f64) {
    let abs2 = |(re, im): (f64, f64)| re * re + im * im;
    // [vertical, horizontal, transverse 1, transverse 2, axial 1, axial 2]
    let mut share = [0.0f64; 6];
    for dof in &layout.dofs {
        match *dof {
            Dof::Effector { x, z, mass } => {
                share[1] += mass * abs2(u[x]);
                share[0] += mass * abs2(u[z]);
            }
            Dof::Node {
                cable,
                x,
                z,
                tangent: t,
                mass,
            } => {
                let along = (t.x * u[x].0 + t.y * u[z].0, t.x * u[x].1 + t.y * u[z].1);
                let across = (-t.y * u[x].0 + t.x * u[z].0, -t.y * u[x].1 + t.x * u[z].1);
                share[4 + cable] += mass * abs2(along);
                share[2 + cable] += mass * abs2(across);
            }
            Dof::Axial { cable, index, mass } => share[4 + cable] += mass * abs2(u[index]),
        }
    }
    let total: f64 = share.iter().sum();
    let (best, &value) = share
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .expect("six shares");
    let kind = match best {
        0 => ModeKind::Vertical,
        1 => ModeKind::Horizontal,
        2 | 3 => ModeKind::Transverse(best - 2),
        _ => ModeKind::Axial(best - 4),
    };
    // No displacement at all (a pure controller-state mode): the controller's x loop.
    if total == 0.0 {
        return (ModeKind::Horizontal, 1.0);
    }
    (kind, value / total)
}

/// Taut-string transverse frequency ω_k = (kπ/l)√(T/μ_s) [rad/s] of a span of chord `length` l
/// [m] under tension `tension` T [N], μ_s = μ/(1 + T/EA) the mass per stretched length.
pub fn taut_string(k: usize, length: f64, tension: f64, mu: f64, ea: f64) -> f64 {
    let mu_s = mu / (1.0 + tension / ea);
    k as f64 * std::f64::consts::PI / length * (tension / mu_s).sqrt()
}

/// Modes below this frequency [rad/s] are the physically relevant band (MODELS.md FE.9.1: the
/// effector, string and lowest axial modes); above it lie the discretisation's axial modes.
pub const RELEVANT_BAND: f64 = 1e4;

/// The linearisation's resolution in growth rate [1/s]: the largest |σ| of an oscillatory mode
/// below [`RELEVANT_BAND`] of the undamped open loop, which is conservative (MODELS.md §4 energy,
/// FE.7), so every such σ is exactly 0 and what the analysis shows is finite-difference and
/// eigen-solver error. Real (ω = 0) modes are excluded: a conservative system may have real pairs
/// ±σ (a divergence). Above the band the lumped model's nearly degenerate axial modes of the two
/// stored chains split into ±σ pairs of up to ~0.4 1/s at 2e5 rad/s (|σ|/ω ~ 2e-6, the FD error
/// acting on a near-double eigenvalue); they are not physical and any damping removes them.
pub fn growth_resolution(scenario: &Scenario, x: f64) -> Result<f64, SimulateError> {
    let mut undamped = scenario.clone();
    undamped.cable.axial_damping = 0.0;
    let open = analyse(&undamped, x, Loop::Open)?;
    Ok(open
        .modes
        .iter()
        .filter(|m| m.mode.omega > 0.0 && m.mode.omega < RELEVANT_BAND)
        .fold(0.0, |a, m| a.max(m.mode.growth.abs())))
}

/// One point of the damping sweep.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SweepPoint {
    /// Axial damping C [N s] (MODELS.md §4, FE.5.7).
    pub damping: f64,
    /// The least stable closed-loop mode at that damping.
    pub least_stable: ClassifiedMode,
}

/// Result of [`damping_sweep`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Sweep {
    pub model: &'static str,
    pub x: f64,
    /// Growth rates at or below this count as decaying [1/s] (the caller's choice, see
    /// [`damping_sweep`]).
    pub threshold: f64,
    /// The linearisation's resolution at x ([`growth_resolution`]) [1/s].
    pub resolution: f64,
    /// Every point evaluated, in damping order.
    pub points: Vec<SweepPoint>,
    /// The smallest damping [N s] found (to the bisection's relative width) for which every
    /// closed-loop mode has growth ≤ threshold; None if even the largest tried does not.
    pub smallest: Option<f64>,
}

/// Smallest Kelvin–Voigt coefficient C in [`low`, `high`] N s for which every closed-loop mode at
/// x has growth ≤ `threshold` [1/s]: a log-spaced scan (`scan` points, to see the curve) then
/// bisection on log C to a relative width of 1e-3 from the last unstable scan point.
///
/// Why a threshold and not σ < 0: axial (Kelvin–Voigt) damping barely touches the transverse
/// string modes (they hardly stretch), so they stay neutral to within the linearisation's error
/// (above the answer at x = 0.6: |σ| ≤ 1.8e-6 1/s, lumped and FE), and "< 0" would be decided by
/// that error. The caller's threshold should sit well above it and below the undamped axial
/// growth (0.16–0.57 1/s, MODELS.md §4, FE.9.1): the xtask uses 1e-2 1/s (≤ 5 % growth over the
/// 5 s run). The growing axial mode's σ falls about linearly in C (slope ≈ −97 (1/s)/(N s) for
/// FE, −90 lumped), so the threshold moves the answer by ≈ 1e-4 N s from the σ = 0 crossing.
/// (Before the velocity columns were differentiated with a step of their own scale, see
/// `modal::jacobian_within`, the string modes' σ scattered non-monotonically up to 2e-3 1/s and
/// the FE answer moved by 0.1 % with the last bits of the equilibrium.)
pub fn damping_sweep(
    scenario: &Scenario,
    x: f64,
    (low, high): (f64, f64),
    scan: usize,
    threshold: f64,
) -> Result<Sweep, SimulateError> {
    let resolution = growth_resolution(scenario, x)?;
    let mut points = Vec::new();
    let eval = |c: f64, points: &mut Vec<SweepPoint>| -> Result<bool, SimulateError> {
        let mut s = scenario.clone();
        s.cable.axial_damping = c;
        let a = analyse(&s, x, Loop::Closed)?;
        let worst = a.least_stable().cloned().ok_or(SimulateError::NoMode)?;
        let stable = worst.mode.growth <= threshold;
        points.push(SweepPoint {
            damping: c,
            least_stable: worst,
        });
        Ok(stable)
    };
    let scan = scan.max(2);
    let ratio = (high / low).ln() / (scan - 1) as f64;
    let mut last_unstable = None;
    let mut first_stable = None;
    for k in 0..scan {
        let c = low * (ratio * k as f64).exp();
        if eval(c, &mut points)? {
            first_stable.get_or_insert(c);
        } else {
            last_unstable = Some(c);
            first_stable = None;
        }
    }
    let smallest = match (last_unstable, first_stable) {
        (_, None) => None,
        (None, Some(c)) => Some(c),
        (Some(mut lo), Some(mut hi)) => {
            while hi / lo > 1.0 + 1e-3 {
                let mid = (lo * hi).sqrt();
                if eval(mid, &mut points)? {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            Some(hi)
        }
    };
    points.sort_by(|a, b| a.damping.total_cmp(&b.damping));
    Ok(Sweep {
        model: scenario.model.kind.name(),
        x,
        threshold,
        resolution,
        points,
        smallest,
    })
}
