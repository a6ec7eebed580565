//! Test helpers written from MODELS.md FE.2–FE.4 directly, not from the model's kernel: the
//! kinetic energy as the quadrature of the material velocity field of the ansatz, the potential,
//! and the generalised forces of the commanded tensions.

#![allow(dead_code)]
// Cable loops index several per-cable tables (TOWARD_REEL, pulleys, layout helpers) by the cable number.
#![allow(clippy::needless_range_loop)]

use cdpr_core::Vector2;
use cdpr_core::channel::Channel;
use cdpr_core::model::{CableModel, SplitRule};
use cdpr_core::robot::Tensions;
use cdpr_core::scenario::Scenario;
use cdpr_fe::{Fe, FeMass, FeStored, Params, TOWARD_REEL};

/// The FE model's parameters: `n` elements per span and the two variants.
pub fn params(n: usize, mass: FeMass, stored: FeStored) -> Params {
    Params {
        elements: n,
        mass,
        stored,
    }
}

pub fn model(n: usize, mass: FeMass, stored: FeStored) -> Fe {
    Fe::new(&Scenario::paper(), params(n, mass, stored)).unwrap()
}

pub fn tensions(tension_sum: f64, force: f64) -> [f64; 2] {
    [0.5 * (tension_sum - force), 0.5 * (tension_sum + force)]
}

/// Deterministic pseudo-random numbers in [−1, 1) (a 64-bit LCG; the proptest seed picks the
/// stream).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// A random admissible state near the equilibrium at `x`: positions disturbed by up to `dq` m
/// (border included), velocities up to `v` m/s (l', ρ' up to v/2).
pub fn random_state(m: &mut Fe, x: f64, seed: u64, dq: f64, v: f64) -> Vec<f64> {
    let eq = m.equilibrium(&SplitRule::new(x, 200.0)).unwrap();
    let mut y = eq.state;
    let np = m.positions_len();
    let mut rng = Lcg(seed);
    let border = 2 * m.chain_nodes();
    for i in 0..np {
        y[i] += dq * rng.next();
        y[np + i] = if i >= border { 0.5 } else { 1.0 } * v * rng.next();
    }
    y
}

/// Position and velocity of node k of `cable` read straight from the layout [m, m/s].
pub fn node(m: &Fe, y: &[f64], cable: usize, k: usize) -> (Vector2<f64>, Vector2<f64>) {
    let np = m.positions_len();
    let nn = m.chain_nodes();
    match m.chain_index(cable, k) {
        None => (m.pulley(cable), Vector2::zeros()),
        Some(j) => (
            Vector2::new(y[j], y[nn + j]),
            Vector2::new(y[np + j], y[np + nn + j]),
        ),
    }
}

/// Quadrature of ½ μ |v|² over one element of unstrained length h, v(η) = (1 − η) a + η b +
/// l' w(η) Δ/h (FE.3): 2-point Gauss (exact for the consistent mass) or the end points (the
/// lumped mass's nodal quadrature).
fn element_kinetic(
    mass: FeMass,
    mu: f64,
    h: f64,
    ld: f64,
    (ra, rb): (Vector2<f64>, Vector2<f64>),
    (a, b): (Vector2<f64>, Vector2<f64>),
    (wa, wb): (f64, f64),
) -> f64 {
    let delta = rb - ra;
    let v = |eta: f64| a * (1.0 - eta) + b * eta + delta * (ld * ((1.0 - eta) * wa + eta * wb) / h);
    let points: [(f64, f64); 2] = match mass {
        FeMass::Consistent => {
            let g = 0.5 / 3f64.sqrt();
            [(0.5 - g, 0.5), (0.5 + g, 0.5)]
        }
        FeMass::Lumped => [(0.0, 0.5), (1.0, 0.5)],
    };
    points
        .iter()
        .map(|&(eta, w)| 0.5 * mu * h * w * v(eta).norm_squared())
        .sum()
}

/// Kinetic energy T(q, q') of the whole system from the velocity field (FE.3) [J].
pub fn kinetic(m: &Fe, y: &[f64]) -> f64 {
    let np = m.positions_len();
    let (n, mu, l0) = (m.elements, m.material.mu, m.modelled_length);
    let mut t = 0.0;
    for c in 0..2 {
        let li = m.l_index(c);
        let (l, ld) = (y[li], y[np + li]);
        let h = l / n as f64;
        for e in 1..=n {
            let (ra, a) = node(m, y, c, e - 1);
            let (rb, b) = node(m, y, c, e);
            let w = |k: usize| 1.0 - k as f64 / n as f64;
            t += element_kinetic(m.mass, mu, h, ld, (ra, rb), (a, b), (w(e - 1), w(e)));
        }
        match m.rho_index(c) {
            Some(ri) => {
                let e_out = Vector2::new(TOWARD_REEL[c], 0.0);
                let (rho, rhod) = (y[ri], y[np + ri]);
                let r = m.pulley(c) + e_out * rho;
                t += element_kinetic(
                    m.mass,
                    mu,
                    l0 - l,
                    ld,
                    (r, m.pulley(c)),
                    (e_out * rhod, Vector2::zeros()),
                    (0.0, 1.0),
                );
            }
            None => t += 0.5 * mu * (l0 - l) * ld * ld,
        }
    }
    let (_, vp) = node(m, y, 0, n);
    t + 0.5 * m.effector_mass * vp.norm_squared()
}

/// Potential U(q): strain ½ EA h max(ε, 0)², element weights μ g h z̄, effector M g z [J].
pub fn potential(m: &Fe, y: &[f64]) -> f64 {
    let (n, ea, mu, g, l0) = (
        m.elements,
        m.material.ea,
        m.material.mu,
        m.material.gravity,
        m.modelled_length,
    );
    let strain_energy = |len: f64, h: f64| {
        let eps = (len / h - 1.0).max(0.0);
        0.5 * ea * h * eps * eps
    };
    let mut u = 0.0;
    for c in 0..2 {
        let l = y[m.l_index(c)];
        let h = l / n as f64;
        for e in 1..=n {
            let (ra, _) = node(m, y, c, e - 1);
            let (rb, _) = node(m, y, c, e);
            u += strain_energy((rb - ra).norm(), h) + mu * g * h * 0.5 * (ra.y + rb.y);
        }
        if let Some(ri) = m.rho_index(c) {
            u += strain_energy(y[ri].abs(), l0 - l);
        }
    }
    u + m.effector_mass * g * node(m, y, 0, n).0.y
}

/// Generalised forces of the commanded tensions: Q_ρ = T_i (elastic stored), Q_l = −T_i (rigid).
pub fn applied(m: &Fe, tensions: [f64; 2]) -> Vec<f64> {
    let mut q = vec![0.0; m.positions_len()];
    for c in 0..2 {
        match m.rho_index(c) {
            Some(r) => q[r] = tensions[c],
            None => q[m.l_index(c)] = -tensions[c],
        }
    }
    q
}

/// DOPRI5 (β = 0, rtol, atol) from the model state `y` (controller and audit states appended as
/// zeros) under [`wobbling_tensions`], to `t_final` [s] sampled every 1e-4 s, and the largest
/// |E − E0 − W + D| of the run [J]: the energy identity the FE tests audit.
pub fn wobbling_run(
    m: Fe,
    scenario: &Scenario,
    eq: cdpr_core::model::Equilibrium,
    mut y: Vec<f64>,
    t_final: f64,
    (rtol, atol): (f64, f64),
) -> (cdpr_core::runner::Run, f64) {
    use cdpr_core::closed_loop::ClosedLoop;
    use cdpr_core::runner::{RunOptions, simulate_from};
    use cdpr_numerics::Dopri5Options;
    y.extend_from_slice(&[0.0; 4]);
    let mut sys = ClosedLoop::new(m, scenario).unwrap();
    sys.actuation = wobbling_tensions();
    let dopri = Dopri5Options {
        rtol,
        atol,
        beta: 0.0,
        ..Dopri5Options::default()
    };
    let opts = RunOptions::dopri5(t_final, 1e-4, dopri);
    let run = simulate_from(&mut sys, y, eq, &opts, &mut |_| {}).unwrap();
    let worst = column_max_abs(&run, Channel::EResidual);
    (run, worst)
}

/// Largest |value| of a time-series channel.
pub fn column_max_abs(run: &cdpr_core::runner::Run, channel: Channel) -> f64 {
    let values = run.series.column(channel).unwrap();
    values.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// Commanded tensions that wobble around 100 N at 3 and 7 Hz with a phase offset between the
/// cables (energy-balance runs: they pump work through both reels and excite the cable).
pub fn wobbling_tensions() -> cdpr_core::closed_loop::Actuation {
    let pi = std::f64::consts::PI;
    cdpr_core::closed_loop::Actuation::Prescribed(Box::new(move |t| {
        Tensions::pair([
            100.0 + 10.0 * (6.0 * pi * t).sin(),
            100.0 + 10.0 * (6.0 * pi * t + 0.5).sin() + 3.0 * (14.0 * pi * t).sin(),
        ])
    }))
}
