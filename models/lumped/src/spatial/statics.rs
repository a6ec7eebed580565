//! Statics of the spatial lumped model (MODELS.md §11): each cable at rest hangs in the vertical
//! plane through its pulley and the effector, and is found by shooting along the chain; the
//! reel tensions then carry the effector and the cables' weight.
//!
//! One cable, reel tension T (MODELS.md §4's chain at rest): along the reel line each stored
//! spring carries T less the line-wise weight of the nodes before it, so the straddling spring
//! carries T_s = T − r m g (r_i·ẑ). Leaving the pulley at angle θ in the cable's plane, its free
//! share φ λ_s puts P_r at A + φ λ_s e(θ); each free node's balance, f_j = f_{j−1} − m g ẑ, gives
//! the next spring's force and (taut) length l0 + |f_j|/k0, and the chain is marched to P_N.
//! Newton on (θ, φ) puts P_N on the effector; φ outside (0, 1] moves the split r by one node.
//!
//! The effector: the pose is pinned and the controller's tensions T0 given; the cables' weight
//! needs a correction, taken as the least one in the tensions' norm, T = T0 + W⁺ δw (the
//! distribution's own slope when no bound is active), with δw found by Newton on the effector's
//! balance Σ f_i + M g⃗ = 0.

use super::LumpedSpatial;
use crate::PULLEY_OFFSET;
use cdpr_core::model::{CableModel, Equilibrium, ModelError, RestRule};
use cdpr_core::robot::{PerCable, Tensions};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// One cable at rest from its reel to the effector.
#[derive(Debug, Clone, PartialEq)]
pub struct Hang {
    /// Stored nodes r.
    pub stored: usize,
    /// Nodes P_0 … P_{N−1} [m].
    pub nodes: Vec<Vector3<f64>>,
    /// The force the cable exerts on the effector [N] (from the effector toward the cable).
    pub pull: Vector3<f64>,
    /// Tension of the straddling spring T_s [N].
    pub straddle_tension: f64,
    /// Unstrained length from the pulley to the effector [m].
    pub free_length: f64,
}

/// One march: the end P_N, the last spring's force on it, and the straddling spring.
struct March {
    end: Vector3<f64>,
    pull: Vector3<f64>,
    straddle_tension: f64,
    straddle_length: f64,
}

/// Marches cable `cable` from its pulley for split `r`, angle `theta` [rad] in the plane of the
/// horizontal unit `h` and z, and free share `phi` of the straddling spring, handing each free
/// node P_r … P_{N−1} to `node` (the shooting's own marches keep none).
fn march(
    model: &LumpedSpatial,
    cable: usize,
    (r, theta, phi): (usize, f64, f64),
    tension: f64,
    h: Vector3<f64>,
    mut node: impl FnMut(usize, Vector3<f64>),
) -> March {
    let (n, l0, k0) = (model.elements, model.segment, model.stiffness);
    let weight = model.node_mass * model.robot().gravity;
    let straddle_tension = tension - r as f64 * weight * model.reel(cable).z;
    let straddle_length = l0 + straddle_tension / k0;
    let e = h * theta.cos() + Vector3::z() * theta.sin();
    let mut p = model.pulley(cable) + e * (phi * straddle_length);
    let mut f = -e * straddle_tension;
    for j in r..n {
        node(j, p);
        f.z -= weight;
        let t = f.norm();
        p -= f * ((l0 + t / k0) / t);
    }
    March {
        end: p,
        pull: f,
        straddle_tension,
        straddle_length,
    }
}

/// Horizontal unit vector from the pulley toward `p` (x for a cable hanging plumb).
fn plane_of(pulley: Vector3<f64>, p: &Vector3<f64>) -> Vector3<f64> {
    let h = Vector3::new(p.x - pulley.x, p.y - pulley.y, 0.0);
    if h.norm() > 1e-12 {
        h.normalize()
    } else {
        Vector3::x()
    }
}

/// Newton on (θ, φ) for a fixed split r: P_N on `p` to 1e-12 m.
fn shoot(
    model: &LumpedSpatial,
    cable: usize,
    r: usize,
    start: (f64, f64),
    tension: f64,
    p: &Vector3<f64>,
) -> Result<(f64, f64), ModelError> {
    let h = plane_of(model.pulley(cable), p);
    let miss = |theta: f64, phi: f64| {
        let d = march(model, cable, (r, theta, phi), tension, h, |_, _| {}).end - p;
        Vector2::new(d.dot(&h), d.z)
    };
    let (mut theta, mut phi) = start;
    for _ in 0..60 {
        let residual = miss(theta, phi);
        if residual.norm() <= 1e-12 {
            return Ok((theta, phi));
        }
        let step = 1e-7;
        let d_theta = (miss(theta + step, phi) - miss(theta - step, phi)) / (2.0 * step);
        let d_phi = (miss(theta, phi + step) - miss(theta, phi - step)) / (2.0 * step);
        let jacobian = Matrix2::from_columns(&[d_theta, d_phi]);
        let Some(delta) = jacobian.try_inverse().map(|inv| -(inv * residual)) else {
            break;
        };
        theta += delta.x.clamp(-0.3, 0.3);
        phi += delta.y;
    }
    Err(ModelError::State {
        t: 0.0,
        why: format!(
            "cable {}: no lumped chain of {r} stored nodes hangs from its pulley to the effector \
             at {:?} m under {tension} N (shooting did not converge)",
            cable + 1,
            p.as_slice()
        ),
    })
}

/// One cable's rest without its nodes: the split and the march that hangs it, and what it puts
/// on the effector (the statics' Newton iterations need no more; [`hang`] adds the nodes).
#[derive(Debug, Clone, Copy)]
struct Settled {
    stored: usize,
    theta: f64,
    phi: f64,
    h: Vector3<f64>,
    tension: f64,
    /// The force the cable exerts on the effector [N].
    pull: Vector3<f64>,
}

impl Settled {
    /// Unstrained length from the pulley to the effector [m].
    fn free_length(&self, model: &LumpedSpatial) -> f64 {
        ((model.elements - self.stored) as f64 + self.phi) * model.segment
    }
}

/// The split r, angle and share that hang cable `cable` from its reel under `tension` [N] to
/// the effector at `p` [m]: shooting for a split guessed from the chord, moved by one node while
/// the share falls outside (0, 1].
fn settle(
    model: &LumpedSpatial,
    cable: usize,
    p: &Vector3<f64>,
    tension: f64,
) -> Result<Settled, ModelError> {
    if tension <= 0.0 || tension.is_nan() {
        return Err(ModelError::State {
            t: 0.0,
            why: format!(
                "cable {}: a reel tension of {tension} N cannot hang a line (it must be > 0 N)",
                cable + 1
            ),
        });
    }
    let (n, l0) = (model.elements, model.segment);
    let pulley = model.pulley(cable);
    let chord = p - pulley;
    let h = plane_of(pulley, p);
    let free = chord.norm() / (1.0 + tension / (model.stiffness * l0));
    let mut r = (n + 1)
        .saturating_sub((free / l0).ceil() as usize)
        .clamp(1, n);
    let mut guess = (chord.z.atan2(chord.dot(&h)), free / l0 - (n - r) as f64);
    // The split moves one way; a move back is a node that sits on the pulley.
    let mut came_from = None;
    loop {
        let (theta, phi) = shoot(model, cable, r, guess, tension, p)?;
        let next = if phi > 1.0 {
            (r > 1).then(|| (r - 1, phi - 1.0))
        } else if phi <= 0.0 {
            (r < n).then(|| (r + 1, phi + 1.0))
        } else {
            let m = march(model, cable, (r, theta, phi), tension, h, |_, _| {});
            return Ok(Settled {
                stored: r,
                theta,
                phi,
                h,
                tension,
                pull: m.pull,
            });
        };
        let Some((next_r, next_phi)) = next.filter(|(k, _)| Some(*k) != came_from) else {
            return Err(ModelError::State {
                t: 0.0,
                why: format!(
                    "cable {}: no split of its {n} nodes puts the pulley inside the straddling \
                     spring at {:?} m under {tension} N (free share {phi} with {r} stored: the \
                     modelled cable is too short, or a node sits on the pulley)",
                    cable + 1,
                    p.as_slice()
                ),
            });
        };
        came_from = Some(r);
        (r, guess) = (next_r, (theta, next_phi));
    }
}

/// Cable `cable` at rest from its reel, pulled by `tension` [N], to the effector at `p` [m].
pub fn hang(
    model: &LumpedSpatial,
    cable: usize,
    p: &Vector3<f64>,
    tension: f64,
) -> Result<Hang, ModelError> {
    Ok(assemble(model, cable, &settle(model, cable, p, tension)?))
}

/// The whole chain of a settled cable: its free nodes marched again, its stored nodes back
/// along the reel line.
fn assemble(model: &LumpedSpatial, cable: usize, s: &Settled) -> Hang {
    let (l0, k0) = (model.segment, model.stiffness);
    let reel = model.reel(cable);
    let weight_along = model.node_mass * model.robot().gravity * reel.z;
    let mut nodes = vec![Vector3::zeros(); model.elements];
    let split = (s.stored, s.theta, s.phi);
    let m = march(model, cable, split, s.tension, s.h, |j, p| nodes[j] = p);
    let r = s.stored;
    let behind = ((1.0 - s.phi) * m.straddle_length).max(PULLEY_OFFSET);
    nodes[r - 1] = model.pulley(cable) + reel * behind;
    for j in (0..r - 1).rev() {
        let t = s.tension - (j + 1) as f64 * weight_along;
        nodes[j] = nodes[j + 1] + reel * (l0 + t / k0);
    }
    Hang {
        stored: r,
        nodes,
        pull: m.pull,
        straddle_tension: m.straddle_tension,
        free_length: s.free_length(model),
    }
}

/// A root of [`newton_3`]: where, its residual, and the iterations it took.
struct Root {
    x: Vector3<f64>,
    residual: Vector3<f64>,
    iterations: usize,
}

/// Newton on a map x ∈ R³ → R³ from `x` by central differences of `step`, until |R(x)| ≤
/// `tolerance`; where it stalls (30 iterations, or a singular Jacobian) the error `stalled`
/// makes of the residual there.
fn newton_3(
    mut residual: impl FnMut(&Vector3<f64>) -> Result<Vector3<f64>, ModelError>,
    mut x: Vector3<f64>,
    (step, tolerance): (f64, f64),
    stalled: impl FnOnce(Vector3<f64>) -> ModelError,
) -> Result<Root, ModelError> {
    let mut r = residual(&x)?;
    for iterations in 0..=30 {
        if r.norm() <= tolerance {
            return Ok(Root {
                x,
                residual: r,
                iterations,
            });
        }
        if iterations == 30 {
            break;
        }
        let mut jacobian = Matrix3::zeros();
        for k in 0..3 {
            let e = Vector3::ith(k, step);
            let column = (residual(&(x + e))? - residual(&(x - e))?) / (2.0 * step);
            jacobian.set_column(k, &column);
        }
        let Some(inv) = jacobian.try_inverse() else {
            break;
        };
        x -= inv * r;
        r = residual(&x)?;
    }
    Err(stalled(r))
}

/// The robot at rest at the rule's pose (every coordinate pinned), the tensions corrected by
/// W⁺ δw to carry the cables' weight (see the module documentation).
pub(super) fn equilibrium(
    model: &mut LumpedSpatial,
    rule: &dyn RestRule<3>,
) -> Result<Equilibrium, ModelError> {
    let mut p = Vector3::zeros();
    if rule.pinned().len() != 3 {
        return Err(ModelError::State {
            t: 0.0,
            why: "the spatial lumped model rests at a pose: all three coordinates pinned".into(),
        });
    }
    for &(axis, value) in rule.pinned() {
        p[axis] = value;
    }
    let base = rule.tensions(&[]);
    let m = model.robot().cables();
    let w = model.robot().structure_matrix(&p);
    let gram_inv = w.gram_inverse().ok_or_else(|| ModelError::State {
        t: 0.0,
        why: format!("the cables do not span space at {:?} m", p.as_slice()),
    })?;
    let tensions_for = |dw: &Vector3<f64>| {
        let lambda = gram_inv * dw;
        PerCable::from_fn(m, |i| base[i] + w.column(i).dot(&lambda))
    };
    let lift = model.robot().effector_mass * model.robot().gravity;
    let residual = |dw: &Vector3<f64>| -> Result<Vector3<f64>, ModelError> {
        let t = tensions_for(dw);
        let mut sum = Vector3::new(0.0, 0.0, -lift);
        for i in 0..m {
            sum += settle(model, i, &p, t[i])?.pull;
        }
        Ok(sum)
    };
    let scale = lift + base.iter().map(|t| t.abs()).sum::<f64>();
    let root = newton_3(
        residual,
        Vector3::zeros(),
        (1e-6 * scale, 1e-11 * scale),
        |r| ModelError::State {
            t: 0.0,
            why: format!(
                "the lumped cables' weight cannot be carried at {:?} m: the effector's \
                 balance stalled at {:e} N",
                p.as_slice(),
                r.norm()
            ),
        },
    )?;
    let (dw, r, iterations) = (root.x, root.residual, root.iterations);
    let tensions = tensions_for(&dw);
    let state = rest_state(model, &p, &tensions)?;
    Ok(Equilibrium {
        state,
        parameters: Vec::new(),
        tensions,
        iterations,
        residual: r.norm(),
    })
}

/// The state at rest with every cable hanging under `tensions` (velocities zero), and the
/// model's split set.
fn rest_state(
    model: &mut LumpedSpatial,
    p: &Vector3<f64>,
    tensions: &Tensions,
) -> Result<Vec<f64>, ModelError> {
    let m = model.robot().cables();
    let n = model.elements;
    let mut state = vec![0.0; model.state_len()];
    let mut stored = vec![0; m];
    for (i, split) in stored.iter_mut().enumerate() {
        let hang = hang(model, i, p, tensions[i])?;
        *split = hang.stored;
        for (j, node) in hang.nodes.iter().enumerate() {
            for axis in 0..3 {
                state[model.index(i, j, axis)] = node[axis];
            }
        }
    }
    for axis in 0..3 {
        state[model.index(0, n, axis)] = p[axis];
    }
    model.set_stored(&stored);
    Ok(state)
}

/// Cable `cable` at rest from its pulley to the effector at `p` [m] holding `free` [m] of
/// unstrained cable between them (a reel locked at that length): the reel tension T for which
/// the hanging chain needs exactly `free`, to 1e-12 m. The length needed falls as T rises (a
/// tauter line sags less and stretches more), so T is bracketed from the straight elastic
/// line's tension and found by the Illinois secant; a tension too low for the modelled cable
/// to hang at all lies below the root, and bisection steps over it.
pub fn hang_with_length(
    model: &LumpedSpatial,
    cable: usize,
    p: &Vector3<f64>,
    free: f64,
) -> Result<Hang, ModelError> {
    Ok(assemble(
        model,
        cable,
        &settle_with_length(model, cable, p, free)?,
    ))
}

/// [`hang_with_length`] without the nodes.
fn settle_with_length(
    model: &LumpedSpatial,
    cable: usize,
    p: &Vector3<f64>,
    free: f64,
) -> Result<Settled, ModelError> {
    let excess = |t: f64| settle(model, cable, p, t).map(|s| (s.free_length(model) - free, s));
    let ea = model.stiffness * model.segment;
    let chord = (p - model.pulley(cable)).norm();
    let weight = model.node_mass / model.segment * model.robot().gravity * free;
    // Up from the straight line's tension (or the line's weight) until the line needs less
    // than `free`; a tension too low to hang the line at all needs more.
    let mut bracket = Bracket::up(&excess, (ea * (chord / free - 1.0)).max(weight).max(1e-6));
    bracket.down(&excess);
    if !(bracket.f_lo > 0.0 && bracket.f_hi < 0.0) {
        return Err(ModelError::State {
            t: 0.0,
            why: format!(
                "cable {}: no tension hangs {free} m of unstrained line from its pulley to {:?} m",
                cable + 1,
                p.as_slice()
            ),
        });
    }
    bracket.illinois(&excess, cable)
}

/// A locked line's excess length (needed − held) [m] at a reel tension [N], and the line there.
type Excess<'a> = dyn Fn(f64) -> Result<(f64, Settled), ModelError> + 'a;

/// Reel tensions around a locked line's root: at `lo` it needs more than it holds, at `hi` less.
struct Bracket {
    lo: f64,
    f_lo: f64,
    hi: f64,
    f_hi: f64,
    /// The last line that hung (the answer if the secant does not converge).
    last: Option<Settled>,
}

impl Bracket {
    /// Doubles the tension from `hi` until the line needs less than it holds (or 200 doublings).
    fn up(excess: &Excess, mut hi: f64) -> Self {
        let mut f_hi = f64::INFINITY;
        let mut last = None;
        for _ in 0..200 {
            if let Ok((f, h)) = excess(hi) {
                (f_hi, last) = (f, Some(h));
                if f < 0.0 {
                    break;
                }
            }
            hi *= 2.0;
        }
        Self {
            lo: hi,
            f_lo: f_hi,
            hi,
            f_hi,
            last,
        }
    }

    /// Halves the tension until the line needs more than it holds, or halves a can't-hang gap.
    fn down(&mut self, excess: &Excess) {
        let mut floor = 0.0;
        for _ in 0..400 {
            if self.f_lo > 0.0 {
                break;
            }
            let t = if floor > 0.0 {
                0.5 * (floor + self.lo)
            } else {
                0.5 * self.lo
            };
            match excess(t) {
                Ok((f, h)) if f > 0.0 => (self.lo, self.f_lo, self.last) = (t, f, Some(h)),
                Ok((f, _)) => (self.hi, self.f_hi, self.lo, self.f_lo) = (t, f, t, f),
                Err(_) => floor = t,
            }
        }
    }

    /// The tension that hangs exactly the held length, to 1e-12 m, by the Illinois secant.
    fn illinois(mut self, excess: &Excess, cable: usize) -> Result<Settled, ModelError> {
        let mut side = 0;
        for _ in 0..200 {
            let t = self.hi - self.f_hi * (self.hi - self.lo) / (self.f_hi - self.f_lo);
            let (f, h) = excess(t)?;
            if f.abs() <= 1e-12 || self.hi - self.lo <= 1e-14 * self.hi {
                return Ok(h);
            }
            self.last = Some(h);
            if f > 0.0 {
                (self.lo, self.f_lo) = (t, f);
                if side == 1 {
                    self.f_hi *= 0.5;
                }
                side = 1;
            } else {
                (self.hi, self.f_hi) = (t, f);
                if side == -1 {
                    self.f_lo *= 0.5;
                }
                side = -1;
            }
        }
        self.last.ok_or_else(|| ModelError::State {
            t: 0.0,
            why: format!(
                "cable {}: the locked length's tension did not converge",
                cable + 1
            ),
        })
    }
}

/// The robot at rest with every reel locked at the unstrained free lengths `lengths` [m]: the
/// effector's pose (Newton on the effector's balance Σ f_i + M g⃗ = 0 from `guess`, central
/// differences of 1e-7 m), each line hanging with its length, and the tensions at the reels.
pub fn rest_with_lengths(
    model: &LumpedSpatial,
    guess: &Vector3<f64>,
    lengths: &[f64],
) -> Result<(Vector3<f64>, Vec<Hang>), ModelError> {
    let m = model.robot().cables();
    let lift = model.robot().effector_mass * model.robot().gravity;
    let residual = |p: &Vector3<f64>| -> Result<Vector3<f64>, ModelError> {
        let mut sum = Vector3::new(0.0, 0.0, -lift);
        for (i, &free) in lengths.iter().enumerate().take(m) {
            sum += settle_with_length(model, i, p, free)?.pull;
        }
        Ok(sum)
    };
    // Balanced to 1e-10 of the weight and the lines' pulls at the guess.
    let pulls: f64 = (0..m)
        .map(|i| settle_with_length(model, i, guess, lengths[i]).map(|s| s.pull.norm()))
        .sum::<Result<f64, _>>()?;
    let p = newton_3(residual, *guess, (1e-7, 1e-10 * (lift + pulls)), |r| {
        ModelError::State {
            t: 0.0,
            why: format!(
                "locked reels at lengths {lengths:?} m: the effector's balance stalled at {:e} \
                 N near {:?} m",
                r.norm(),
                guess.as_slice()
            ),
        }
    })?
    .x;
    let hangs = (0..m)
        .map(|i| hang_with_length(model, i, &p, lengths[i]))
        .collect::<Result<_, _>>()?;
    Ok((p, hangs))
}
