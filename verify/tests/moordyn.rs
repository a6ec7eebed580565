//! Cross-code tests against MoorDyn 2 (Hall & Goupee 2015; its Python wheel, run live through
//! `verify/moordyn/run_case.py`), the lumped-mass mooring code whose lumping is ours: N springs
//! EA/l0, interior nodes of mass μ l0, half a segment at each end. The paper's cable
//! (EA = 179 520 N, μ = 0.013816 kg/m) is set up in MoorDyn in air (ρ_w = 0: no buoyancy, no drag,
//! no added mass), undamped, integrated by its RK4. Every MoorDyn number is computed by the test;
//! none is stored.
//!
//! - statics: MoorDyn's catenary start against Irvine's closed form; the lumped and FE equilibria
//!   held by MoorDyn's dynamics (the same discrete statics);
//! - a taut cable's lowest transverse and axial modes: MoorDyn, the lumped chain integrated here,
//!   and the discrete-string closed forms;
//! - a pendulum: a 1 kg mass on the cable released from 0.3 rad, MoorDyn against the lumped chain.

use crate::common;

use cdpr_bench::core::Vector2;
use cdpr_bench::fe::element::Material;
use cdpr_bench::fe::fixed_cable::FixedCable;
use cdpr_bench::lumped::fixed_cable::FixedCable as LumpedCable;
use cdpr_bench::lumped::spring_tension;
use cdpr_bench::numerics::{Dopri5, Dopri5Options, OdeSystem};
use cdpr_verify::irvine::Catenary;
use serde_json::{Value, json};

const EA: f64 = 179_520.0;
const MU: f64 = 0.013816;
const G: f64 = 9.81;

/// Runs `case` in MoorDyn (see `run_case.py` for its keys) and returns its answer.
fn moordyn(case: Value) -> Value {
    common::moordyn("run_case.py", &case)
}

fn points(v: &Value) -> Vec<Vector2<f64>> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| Vector2::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

/// The times MoorDyn sampled at [s].
fn sample_times(answer: &Value) -> Vec<f64> {
    answer["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect()
}

/// Interior rows [x, z, vx, vz] for MoorDyn's state file.
fn rows(nodes: &[Vector2<f64>], velocities: &[Vector2<f64>]) -> Value {
    json!(
        nodes
            .iter()
            .zip(velocities)
            .map(|(p, v)| [p.x, p.y, v.x, v.y])
            .collect::<Vec<_>>()
    )
}

/// The lumped chain's dynamics: interior nodes of mass μ l0 under [`LumpedCable::forces`], and end B
/// either fixed or a free point of mass M + μ l0/2 carrying its weight and the last spring.
/// State: interior positions (x, z interleaved), then end B, then the same velocities.
struct ChainDynamics {
    chain: LumpedCable,
    /// M + μ l0 / 2 of a free end B [kg]; `None`: B fixed.
    end_mass: Option<f64>,
    forces: Vec<f64>,
}

impl ChainDynamics {
    fn new(chain: LumpedCable, end_mass: Option<f64>) -> Self {
        let n = chain.elements;
        let end_mass = end_mass.map(|m| m + 0.5 * chain.node_mass);
        Self {
            chain,
            end_mass,
            forces: vec![0.0; 2 * (n - 1)],
        }
    }
    /// Position coordinates: interior nodes and end B.
    fn positions(&self) -> usize {
        2 * self.chain.elements
    }
}

impl OdeSystem for ChainDynamics {
    fn dimension(&self) -> usize {
        2 * self.positions()
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let np = self.positions();
        let ni = np - 2;
        if self.end_mass.is_some() {
            self.chain.ends[1] = Vector2::new(y[ni], y[ni + 1]);
        }
        self.chain.forces(&y[..ni], &mut self.forces);
        dy[..np].copy_from_slice(&y[np..]);
        for (a, f) in dy[np..np + ni].iter_mut().zip(&self.forces) {
            *a = f / self.chain.node_mass;
        }
        dy[np + ni] = 0.0;
        dy[np + ni + 1] = 0.0;
        if let Some(mass) = self.end_mass {
            let last = Vector2::new(y[ni - 2], y[ni - 1]);
            let d = last - self.chain.ends[1];
            let length = d.norm();
            let c = &self.chain;
            let tension = spring_tension(c.stiffness, c.segment, 0.0, length, 0.0);
            let pull = d * (tension / length);
            dy[np + ni] = pull.x / mass;
            dy[np + ni + 1] = pull.y / mass - c.gravity;
        }
    }
}

/// Integrates the chain from `y0` and returns the state at each of `samples` (DOPRI5 at
/// rtol 1e-11: its global error is far below MoorDyn's).
fn integrate(sys: &mut ChainDynamics, y0: &[f64], samples: &[f64]) -> Vec<Vec<f64>> {
    let opts = Dopri5Options {
        rtol: 1e-11,
        atol: 1e-14,
        ..Dopri5Options::default()
    };
    let t_end = *samples.last().unwrap();
    let mut d = Dopri5::new(y0.len(), opts);
    d.start(sys, 0.0, y0, t_end).unwrap();
    samples
        .iter()
        .map(|&t| {
            while d.time() < t {
                d.step(sys, t).unwrap();
            }
            d.state().to_vec()
        })
        .collect()
}

/// Angular frequency from the zero crossings of `signal` (linear interpolation between
/// samples) [rad/s].
fn crossing_frequency(times: &[f64], signal: &[f64]) -> f64 {
    let crossings: Vec<f64> = (1..signal.len())
        .filter(|&k| signal[k - 1] * signal[k] < 0.0)
        .map(|k| {
            let (a, b) = (signal[k - 1], signal[k]);
            times[k - 1] + (times[k] - times[k - 1]) * a / (a - b)
        })
        .collect();
    assert!(crossings.len() >= 10, "{} crossings", crossings.len());
    let span = crossings.last().unwrap() - crossings[0];
    std::f64::consts::PI * (crossings.len() - 1) as f64 / span
}

/// MoorDyn starts a line between fixed ends on its catenary (Jonkman's quasi-static routine,
/// iterated to a relative closure of 1e-6 or better): its nodes must be Irvine's at the same
/// unstrained arc lengths, computed by our solver. 1e-8 m: two independent solutions of the
/// same closed form (measured 1.5e-10 m on the slack case).
///
/// The lumped chain and the FE cable with l' = 0 share their statics (springs EA/l0 and the
/// weight μ g l0 per interior node; FE.11.4): they agree to the Newton stop, 2e-8 N over the
/// softest transverse stiffness (T/l0 ≈ 1 N/m for the slack case) ≈ 2e-8 m; 1e-7 m allowed
/// (measured 8e-17 m). MoorDyn, started at rest at the lumped equilibrium, must stay there: a
/// force residual δF moves a node by δF t²/(2m) in t = 0.05 s, so the 2e-8 N Newton stop allows
/// 1e-9 m (measured 2e-15 m). On the taut cable, where the sag is set by w/H, the same run from
/// a chain 1 % heavier (a model's weight error) must move by more than 10× that (measured
/// 8.4e-7 m); the slack steel catenary's shape does not depend on its weight (only its stretch
/// does), so there it guards the geometry and the lumping.
#[test]
fn catenaries_match_irvine_and_moordyn_holds_the_lumped_and_fe_equilibria() {
    let n = 10;
    for (name, end, length, dt) in [
        ("slack steel", [1.0, -0.2], 1.2, 1e-5),
        ("taut", [0.5, -0.0247251205], 0.5003322670, 5e-6),
    ] {
        let ends = [Vector2::new(0.0, 0.0), Vector2::new(end[0], end[1])];
        let case = |initial: Option<Value>| {
            json!({
                "line": {"ea": EA, "mu": MU, "length": length, "segments": n},
                "anchor": [0.0, 0.0], "end": end, "gravity": G, "dt": dt,
                "t_end": if initial.is_some() { 0.05 } else { 0.0 }, "sample": 0.01,
                "initial": initial,
            })
        };
        let start = points(&moordyn(case(None))["start"]);
        let irvine = Catenary::through(end, length, MU * G, EA).unwrap();
        let worst = start
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let q = irvine.position(k as f64 * length / n as f64);
                (p - Vector2::new(q[0], q[1])).norm()
            })
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-8,
            "{name}: MoorDyn's catenary is {worst:e} m from Irvine's"
        );

        let lumped = LumpedCable::new(ends, length, n, EA, MU, G)
            .equilibrium()
            .unwrap();
        let fe = FixedCable {
            ends,
            elements: n,
            length,
            material: Material {
                ea: EA,
                mu: MU,
                gravity: G,
            },
        }
        .equilibrium()
        .unwrap();
        let apart = lumped
            .iter()
            .zip(&fe)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(
            apart < 1e-7,
            "{name}: lumped and FE statics {apart:e} m apart"
        );

        let drift = |mu: f64| {
            let nodes = LumpedCable::new(ends, length, n, EA, mu, G)
                .equilibrium()
                .unwrap();
            let interior = &nodes[1..n];
            let answer = moordyn(case(Some(rows(interior, &vec![Vector2::zeros(); n - 1]))));
            answer["nodes"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|sample| {
                    let at = points(sample);
                    (1..n)
                        .map(|k| (at[k] - nodes[k]).norm())
                        .collect::<Vec<_>>()
                })
                .fold(0.0, f64::max)
        };
        let held = drift(MU);
        assert!(
            held < 1e-9,
            "{name}: MoorDyn moved {held:e} m off the lumped equilibrium"
        );
        if name == "taut" {
            let heavier = drift(1.01 * MU);
            assert!(
                heavier > 1e-8,
                "{name}: a chain 1 % heavier is only {heavier:e} m off MoorDyn's equilibrium"
            );
        }
    }
}

/// A taut cable (g = 0, ends 0.5 m apart, 100 N, N = 20) started in the lowest transverse or
/// axial mode shape sin(π j/N) at 1e-6 m rings at the discrete string's
/// ω = 2 √(T/(m l)) sin(π/2N) or ω = 2 √(k0/m) sin(π/2N) (m = μ l0, l = 0.5/N, k0 = EA/l0), in
/// MoorDyn and in the lumped chain. 1e-6 relative: RK4's phase lag (ωh)⁴/120 = 3.4e-8 for the
/// axial mode at h = 2e-6 s (ωh = 0.045; MoorDyn measured −3.2e-8) and 1e-15 for the transverse
/// one, the amplitude's nonlinear shift (A/l)² ≈ 2e-9, and the crossing interpolation (measured
/// 7e-9 for both codes); a 1 % error in tension or mass shifts ω by 0.5 %.
#[test]
fn taut_cable_modes_match_moordyn_and_the_discrete_string() {
    let n = 20usize;
    let (span, tension) = (0.5, 100.0);
    let length = span / (1.0 + tension / EA);
    let l0 = length / n as f64;
    let m = MU * l0;
    let s = (std::f64::consts::PI / (2.0 * n as f64)).sin();
    let ends = [Vector2::new(0.0, 0.0), Vector2::new(span, 0.0)];
    for (name, axial, expected, t_end, sample) in [
        (
            "transverse",
            false,
            2.0 * (tension / (m * span / n as f64)).sqrt() * s,
            0.12,
            2e-5,
        ),
        ("axial", true, 2.0 * (EA / l0 / m).sqrt() * s, 3e-3, 2e-6),
    ] {
        let amplitude = 1e-6;
        let shape = |j: usize| (std::f64::consts::PI * j as f64 / n as f64).sin() * amplitude;
        let rest = |j: usize| Vector2::new(span * j as f64 / n as f64, 0.0);
        let interior: Vec<Vector2<f64>> = (1..n)
            .map(|j| {
                rest(j)
                    + if axial {
                        Vector2::new(shape(j), 0.0)
                    } else {
                        Vector2::new(0.0, shape(j))
                    }
            })
            .collect();
        let answer = moordyn(json!({
            "line": {"ea": EA, "mu": MU, "length": length, "segments": n},
            "anchor": [0.0, 0.0], "end": [span, 0.0], "gravity": 0.0, "dt": 2e-6,
            "t_end": t_end, "sample": sample,
            "initial": rows(&interior, &vec![Vector2::zeros(); n - 1]),
        }));
        let times = sample_times(&answer);
        let mid = n / 2;
        let displacement = |p: Vector2<f64>| {
            if axial { p.x - rest(mid).x } else { p.y }
        };
        let theirs: Vec<f64> = answer["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|sample| displacement(points(sample)[mid]))
            .collect();
        let mut sys = ChainDynamics::new(LumpedCable::new(ends, length, n, EA, MU, 0.0), None);
        let mut y0 = vec![0.0; sys.dimension()];
        for (k, p) in interior.iter().enumerate() {
            y0[2 * k] = p.x;
            y0[2 * k + 1] = p.y;
        }
        y0[2 * n - 2] = span;
        let ours: Vec<f64> = integrate(&mut sys, &y0, &times)
            .iter()
            .map(|y| displacement(Vector2::new(y[2 * (mid - 1)], y[2 * (mid - 1) + 1])))
            .collect();
        let (w_moordyn, w_lumped) = (
            crossing_frequency(&times, &theirs),
            crossing_frequency(&times, &ours),
        );
        for (who, w) in [("MoorDyn", w_moordyn), ("lumped", w_lumped)] {
            assert!(
                (w / expected - 1.0).abs() < 1e-6,
                "{name}: {who} {w} rad/s, discrete string {expected} rad/s"
            );
        }
    }
}

/// A 1 kg mass on 1 m of the cable (N = 10) hung from a fixed point, released at rest from
/// 0.3 rad, the cable straight and stretched by M g/EA: MoorDyn and the lumped chain integrate
/// the same equations, so the mass's path must agree over 2 s (one swing period). The release
/// excites the mass bouncing on the cable (√(EA/(L M)) = 424 rad/s) by the change of the static
/// stretch, M g (1 − cos 0.3) L/EA ≈ 2.4e-6 m; RK4 at h = 1e-5 s lags it by (ωh)⁴/120 ≈ 3e-12
/// per radian, 2e-9 over the run, and the swing by far less; the cable's own modes carry a share
/// m_cable/M of that energy. 1e-8 m allowed (measured 1.5e-11 m); a cable 1 % heavier moves the
/// path by 1.7e-5 m.
#[test]
fn pendulum_swing_matches_moordyn() {
    let (n, length, mass, angle) = (10usize, 1.0, 1.0, 0.3f64);
    let stretch = 1.0 + mass * G / EA;
    let direction = Vector2::new(angle.sin(), -angle.cos());
    let node = |j: usize| direction * (length * stretch * j as f64 / n as f64);
    let interior: Vec<Vector2<f64>> = (1..n).map(node).collect();
    let mut initial = rows(&interior, &vec![Vector2::zeros(); n - 1]);
    let end = node(n);
    initial
        .as_array_mut()
        .unwrap()
        .push(json!([end.x, end.y, 0.0, 0.0]));
    let answer = moordyn(json!({
        "line": {"ea": EA, "mu": MU, "length": length, "segments": n},
        "anchor": [0.0, 0.0], "end": [end.x, end.y], "end_mass": mass, "gravity": G,
        "dt": 1e-5, "t_end": 2.0, "sample": 0.01, "initial": initial,
    }));
    let times = sample_times(&answer);
    let theirs: Vec<Vector2<f64>> = answer["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|sample| points(sample)[n])
        .collect();
    let path = |mu: f64| -> Vec<Vector2<f64>> {
        let chain = LumpedCable::new([Vector2::zeros(), end], length, n, EA, mu, G);
        let mut sys = ChainDynamics::new(chain, Some(mass));
        let mut y0 = vec![0.0; sys.dimension()];
        for (k, p) in interior.iter().chain([&end]).enumerate() {
            y0[2 * k] = p.x;
            y0[2 * k + 1] = p.y;
        }
        integrate(&mut sys, &y0, &times)
            .iter()
            .map(|y| Vector2::new(y[2 * n - 2], y[2 * n - 1]))
            .collect()
    };
    let apart = |ours: &[Vector2<f64>]| {
        ours.iter()
            .zip(&theirs)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    };
    let swing = theirs.iter().map(|p| p.x).fold(f64::INFINITY, f64::min);
    assert!(swing < -0.25, "the mass swung to x = {swing} m only");
    let same = apart(&path(MU));
    assert!(
        same < 1e-8,
        "MoorDyn and the lumped chain differ by {same:e} m"
    );
    let heavier = apart(&path(1.01 * MU));
    assert!(
        heavier > 1e-6,
        "a 1 % heavier cable differs by only {heavier:e} m"
    );
}
