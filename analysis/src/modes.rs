//! Every mode of a model at one effector position, classified from its eigenvector as effector
//! vertical, effector horizontal / controller, transverse string mode of cable 1 or 2, or axial
//! mode of cable 1 or 2, by the share of the mass-weighted displacement each holds. In space the
//! effector's horizontal share splits into x and y, and a cable's transverse share into the
//! string's motion in its vertical plane (through its pulley and the effector) and across it
//! (MODELS.md §11). The model says what its coordinates are
//! ([`cdpr_core::modal_layout::ModalLayout`]); this module knows no model.

use cdpr_core::modal_layout::{Dof, ModalLayout};
use cdpr_core::robot::Tensions;
use cdpr_numerics::eigen::Mode;

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
    /// In space: the effector moving along x (the loop's x poles in closed loop).
    EffectorX,
    /// In space: the effector moving along y.
    EffectorY,
    /// In space: string mode of cable k in its vertical plane.
    InPlane(usize),
    /// In space: string mode of cable k across its vertical plane.
    OutOfPlane(usize),
}

impl std::fmt::Display for ModeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModeKind::Vertical => write!(f, "effector vertical"),
            ModeKind::Horizontal => write!(f, "effector horizontal / controller"),
            ModeKind::Transverse(c) => write!(f, "transverse cable {}", c + 1),
            ModeKind::Axial(c) => write!(f, "axial cable {}", c + 1),
            ModeKind::EffectorX => write!(f, "effector x"),
            ModeKind::EffectorY => write!(f, "effector y"),
            ModeKind::InPlane(c) => write!(f, "in-plane string cable {}", c + 1),
            ModeKind::OutOfPlane(c) => write!(f, "out-of-plane string cable {}", c + 1),
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
    /// Commanded tensions at the equilibrium [N], one per cable.
    pub tensions: Tensions,
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

/// The kind holding the largest share of Σ m |u|² over the position part `u` of an eigenvector,
/// and that share. Effector: x → horizontal, z → vertical; a free node: its component along the
/// cable tangent → axial, across → transverse; an axial coordinate → axial. In space: the
/// effector's x and y apart, and a free node's transverse part split along n = t × ẑ/|t × ẑ|
/// (out of the vertical plane its tangent t lies in) and the rest (in-plane); a node on a
/// vertical tangent, whose plane is any, counts as in-plane.
pub fn classify(layout: &ModalLayout, u: &[(f64, f64)]) -> (ModeKind, f64) {
    let abs2 = |(re, im): (f64, f64)| re * re + im * im;
    let cables = layout
        .dofs
        .iter()
        .filter_map(|dof| match dof {
            Dof::Node { cable, .. } | Dof::Axial { cable, .. } => Some(cable + 1),
            Dof::Effector { .. } => None,
        })
        .max()
        .unwrap_or(0);
    // [vertical, horizontal (x), transverse (in-plane) per cable…, axial per cable…, then in
    // space: y, out-of-plane per cable…]: the plane's shares first, in the plane's order.
    let mut share = vec![0.0f64; 3 + 3 * cables];
    let (transverse, axial, y, out) = (2, 2 + cables, 2 + 2 * cables, 3 + 2 * cables);
    let spatial = layout.dofs.iter().any(|dof| match dof {
        Dof::Effector { coordinates, .. } => coordinates.len() == 3,
        _ => false,
    });
    for dof in &layout.dofs {
        match dof {
            Dof::Effector { coordinates, mass } => {
                let (vertical, horizontal) = coordinates.split_last().expect("one axis at least");
                for (axis, &k) in horizontal.iter().enumerate() {
                    share[if axis == 1 { y } else { 1 }] += mass * abs2(u[k]);
                }
                share[0] += mass * abs2(u[*vertical]);
            }
            Dof::Node {
                cable,
                coordinates,
                tangent,
                mass,
            } => {
                let (along, across) = split_along(coordinates, tangent, u);
                let across_plane = out_of_plane(coordinates, tangent, u).min(across);
                share[axial + cable] += mass * along;
                share[transverse + cable] += mass * (across - across_plane);
                share[out + cable] += mass * across_plane;
            }
            Dof::Axial { cable, index, mass } => share[axial + cable] += mass * abs2(u[*index]),
        }
    }
    let total: f64 = share.iter().sum();
    let (best, &value) = share
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .expect("two shares at least");
    let kind = match best {
        0 => ModeKind::Vertical,
        1 if spatial => ModeKind::EffectorX,
        1 => ModeKind::Horizontal,
        k if k < axial && spatial => ModeKind::InPlane(k - transverse),
        k if k < axial => ModeKind::Transverse(k - transverse),
        k if k < y => ModeKind::Axial(k - axial),
        k if k == y => ModeKind::EffectorY,
        k => ModeKind::OutOfPlane(k - out),
    };
    // No displacement at all (a pure controller-state mode): the controller's x loop.
    if total == 0.0 {
        return (ModeKind::Horizontal, 1.0);
    }
    (kind, value / total)
}

/// |u·t|² and |u − (u·t)t|² of a node's complex displacement `u` against its unit `tangent`.
/// In the plane the transverse part is the rotated projection (−t_z, t_x)·u, as MODELS.md states it.
fn split_along(coordinates: &[usize], tangent: &[f64], u: &[(f64, f64)]) -> (f64, f64) {
    let abs2 = |(re, im): (f64, f64)| re * re + im * im;
    let dot = |w: &[f64]| {
        coordinates
            .iter()
            .zip(w)
            .fold((0.0, 0.0), |(re, im), (&k, &c)| {
                (re + c * u[k].0, im + c * u[k].1)
            })
    };
    if let [tx, tz] = *tangent {
        let (x, z) = (u[coordinates[0]], u[coordinates[1]]);
        let along = (tx * x.0 + tz * z.0, tx * x.1 + tz * z.1);
        let across = (-tz * x.0 + tx * z.0, -tz * x.1 + tx * z.1);
        return (abs2(along), abs2(across));
    }
    let along = dot(tangent);
    let total: f64 = coordinates.iter().map(|&k| abs2(u[k])).sum();
    (abs2(along), (total - abs2(along)).max(0.0))
}

/// |u·n|² of a node's complex displacement `u` across the vertical plane of its unit `tangent`
/// t (n = t × ẑ normalised; 0 in the plane, or on a vertical tangent).
fn out_of_plane(coordinates: &[usize], tangent: &[f64], u: &[(f64, f64)]) -> f64 {
    let [tx, ty, _] = *tangent else {
        return 0.0;
    };
    // t × ẑ = (t_y, −t_x, 0).
    let norm = tx.hypot(ty);
    if norm < 1e-9 {
        return 0.0;
    }
    let n = [ty / norm, -tx / norm];
    let (x, y) = (u[coordinates[0]], u[coordinates[1]]);
    let (re, im) = (n[0] * x.0 + n[1] * y.0, n[0] * x.1 + n[1] * y.1);
    re * re + im * im
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
