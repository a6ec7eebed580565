//! Cross-code test of the spatial lumped cables against MoorDyn 2 (Hall & Goupee 2015; its Python
//! wheel, run live through `verify/moordyn/run_system.py`): a Hangprinter-like robot — three
//! anchors low around the effector, one above it, 1.1 mm UHMWPE lines of 20 masses, a 1 kg
//! effector — with locked reels is a MoorDyn mooring system of four lines from fixed anchors to
//! one free point mass. Every MoorDyn number is computed by the test; none is stored.
//!
//! The same lumping, exactly. With one stored node per cable (its reel end P_0, locked a_i behind
//! the pulley), spring 0 straddles the pulley and pulls P_1 with k0 (a_i + |A_i P_1| − l0): in
//! MoorDyn a one-segment line A_i → C_i of unstrained length l0 − a_i and axial stiffness
//! EA (l0 − a_i)/l0 (the same k0). The other N − 1 springs are one MoorDyn line C_i → effector
//! of N − 1 segments. MoorDyn lumps half of each segment's mass on its end nodes: the connector
//! C_i (our P_1, mass μ l0) gets μ (l0 − a_i)/2 + μ l0/2 from the lines and μ a_i/2 as its own
//! point mass; the effector gets μ l0/2 from each line, so its point mass is M − 4 μ l0/2.
//!
//! The same locked robot's effector modes are checked against the massless elastic lines'
//! (MODELS.md §11) as the lines' mass vanishes, one sagging line's out-of-plane string mode
//! against MoorDyn's (the effector held), and a weightless robot's taut lines' transverse modes
//! against the discrete string's closed form.

use crate::common;

use cdpr_bench::core::model::{CableModel, PoseRule};
use cdpr_bench::core::robot::distribution::{DistributionMethod, TensionBox, distribute};
use cdpr_bench::core::robot::{Robot, Vector};
use cdpr_bench::lumped::spatial::{CableProperties, LumpedSpatial, default_reel_directions};
use cdpr_bench::numerics::{Dopri5, Dopri5Options, OdeSystem};
use nalgebra::Vector3;
use serde_json::{Value, json};

/// Springs per line.
const N: usize = 20;
/// The example's line: EA [N], μ [kg/m] (examples/robots/hangprinter.toml).
const EA: f64 = 2.105e10 * 9.503e-7;
const MU: f64 = 970.0 * 9.503e-7;
const G: f64 = 9.81;
/// The effector's offset from rest [m].
const OFFSET: f64 = 2e-4;

/// Runs `case` in MoorDyn (see `run_system.py`) and returns its answer.
fn moordyn(case: &Value) -> Value {
    common::moordyn("run_system.py", case)
}

/// Anchors [m]: three low at 120° on a 1.5 m circle at z = 0 and one 2.3 m above the centre,
/// and the effector's rest pose on the axis where all four chords are equal (1.639 m).
fn geometry() -> ([Vector3<f64>; 4], Vector3<f64>) {
    let (radius, top) = (1.5, 2.3);
    let low = |deg: f64| {
        let a = deg.to_radians();
        Vector3::new(radius * a.cos(), radius * a.sin(), 0.0)
    };
    let anchors = [
        low(-90.0),
        low(30.0),
        low(150.0),
        Vector3::new(0.0, 0.0, top),
    ];
    let z = (top * top - radius * radius) / (2.0 * top);
    (anchors, Vector3::new(0.0, 0.0, z))
}

/// The robot on lumped lines of unstrained length `length` each, at rest at its pose under the
/// QP's tensions in [10, 70] N.
fn at_rest(length: f64) -> (LumpedSpatial, Vec<f64>) {
    at_rest_with(length, MU)
}

/// [`at_rest`] with lines of mass per length `mu` [kg/m].
fn at_rest_with(length: f64, mu: f64) -> (LumpedSpatial, Vec<f64>) {
    let (anchors, p) = geometry();
    let robot = Robot::new(&anchors, 1.0, G).unwrap();
    let cable = CableProperties {
        elements: N,
        modelled_length: length,
        mass_per_length: mu,
        axial_stiffness: EA,
        axial_damping: 0.0,
    };
    let mut model = LumpedSpatial::new(robot, cable, &default_reel_directions(&anchors)).unwrap();
    let w = robot.structure_matrix(&p);
    let limits = TensionBox {
        t_min: 10.0,
        t_max: 70.0,
    };
    let hold = distribute(
        DistributionMethod::Qp,
        &w,
        &Vector::<3>::new(0.0, 0.0, G),
        limits,
    )
    .unwrap()
    .tensions;
    let eq = model.equilibrium(&PoseRule::new(&p, hold)).unwrap();
    (model, eq.state)
}

/// The locked robot as an ODE.
struct Locked(LumpedSpatial);

impl OdeSystem for Locked {
    fn dimension(&self) -> usize {
        self.0.state_len()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        // Locked reels: the tensions act on the held reel ends only.
        self.0.rhs(t, y, &[0.0; 4], dy);
    }
}

/// The effector's path from `y0` at `times`, by DOPRI5 at `rtol` (atol 1e-3 rtol [m, m/s]), and
/// the largest change of the mechanical energy [J]; every node stays on its side of its pulley
/// (no event is due).
fn ours(model: &LumpedSpatial, y0: &[f64], times: &[f64], rtol: f64) -> (Vec<Vector3<f64>>, f64) {
    let mut sys = Locked(model.clone());
    let opts = Dopri5Options {
        rtol,
        atol: 1e-3 * rtol,
        ..Dopri5Options::default()
    };
    let mut d = Dopri5::new(y0.len(), opts);
    d.start(&mut sys, 0.0, y0, *times.last().unwrap()).unwrap();
    let mut g = vec![0.0; model.event_count()];
    let energy = model.energy(y0).total();
    let mut drift = 0.0f64;
    let path = times
        .iter()
        .map(|&t| {
            while d.time() < t {
                d.step(&mut sys, t).unwrap();
            }
            model.event_functions(d.state(), &mut g);
            assert!(
                g.iter().all(|v| *v > 0.0),
                "a node reached a pulley at {t} s"
            );
            drift = drift.max((model.energy(d.state()).total() - energy).abs());
            model.effector(d.state()).position
        })
        .collect();
    (path, drift)
}

/// The MoorDyn system of the locked robot in state `y0` (see the module documentation).
fn system(model: &LumpedSpatial, y0: &[f64], dt: f64, t_end: f64, sample: f64) -> Value {
    let l0 = model.segment;
    let n = model.elements;
    let row = |p: Vector3<f64>| json!([p.x, p.y, p.z, 0.0, 0.0, 0.0]);
    let mut types = vec![json!({"ea": EA, "mu": MU})];
    let mut points = Vec::new();
    let mut lines = Vec::new();
    let (mut point_states, mut line_states) = (Vec::new(), Vec::new());
    let effector = 8;
    for cable in 0..4 {
        let anchor = model.pulley(cable);
        let behind = (model.node(y0, cable, 0) - anchor).norm();
        let first = l0 - behind;
        types.push(json!({"ea": EA * first / l0, "mu": MU}));
        points.push(json!({"fixed": true, "position": anchor.as_slice(), "mass": 0.0}));
        point_states.push(row(anchor));
        lines.push(
            json!({"type": cable + 1, "a": cable, "b": 4 + cable, "length": first, "segments": 1}),
        );
        line_states.push(json!([]));
        lines.push(json!({"type": 0, "a": 4 + cable, "b": effector, "length": (n - 1) as f64 * l0, "segments": n - 1}));
        line_states.push(Value::Array(
            (2..n).map(|j| row(model.node(y0, cable, j))).collect(),
        ));
    }
    for cable in 0..4 {
        let behind = (model.node(y0, cable, 0) - model.pulley(cable)).norm();
        let connector = model.node(y0, cable, 1);
        points.push(
            json!({"fixed": false, "position": connector.as_slice(), "mass": MU * behind / 2.0}),
        );
        point_states.push(row(connector));
    }
    let p = model.effector(y0).position;
    let mass = model.robot().effector_mass - 4.0 * MU * l0 / 2.0;
    points.push(json!({"fixed": false, "position": p.as_slice(), "mass": mass}));
    point_states.push(row(p));
    json!({
        "types": types, "points": points, "lines": lines,
        "initial": {"points": point_states, "lines": line_states},
        "gravity": G, "dt": dt, "t_end": t_end, "sample": sample, "watch": effector,
    })
}

/// The effector's positions in a MoorDyn answer.
fn watched(answer: &Value) -> Vec<Vector3<f64>> {
    answer["watch"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            Vector3::new(
                p[0].as_f64().unwrap(),
                p[1].as_f64().unwrap(),
                p[2].as_f64().unwrap(),
            )
        })
        .collect()
}

/// Largest distance between two paths [m].
fn gap(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max)
}

/// Free vibration from a 0.2 mm offset: the effector and each line's free nodes shifted in
/// proportion to their distance from the pulley (each line's quasi-static shape to first
/// order, so that the axial modes start nearly at rest), released with locked reels for 0.1 s
/// (two periods of the effector's lowest mode). MoorDyn's path (RK4, dtM = 2 µs and 1 µs)
/// against ours (DOPRI5 at rtol 1e-9 and 1e-10). Both integrate the same ODE, so the bound is
/// the two integrators' error, estimated from their orders: RK4's at 1 µs is |x(2 µs) −
/// x(1 µs)|/15 (Richardson, order 4), DOPRI5's at 1e-10 is |x(1e-9) − x(1e-10)|/9 (its error
/// proportional to the tolerance); the paths must agree within twice their sum (measured:
/// 1.8e-13 m apart against a bound of 3.6e-13 m, on a 0.23 mm swing). The offset keeps every
/// spring taut: three lines hold 10 N, a stretch of T l0/EA = 4.2e-5 m per 84 mm spring, and
/// the shift shortens a line's springs by up to ~1.2e-5 m each. From 2 mm (~1.2e-4 m each) the
/// 10 N lines go slack, the vibration turns non-smooth, and both codes' own refinements part
/// by µm within 0.1 s (DOPRI5 at 1e-9 against 1e-10: up to 10 µm; a 1e-14 relative change of
/// the holding tensions moved the comparison between 1.3 and 6.2 µm), so no bound derived from
/// the integrators' orders holds there. With the reels locked the robot is conservative: the
/// energy stays within 1e-8 J of its start (measured 5e-13 J of the vibration's 4.1e-4 J).
#[test]
fn locked_reels_free_vibration_matches_moordyn() {
    let (probe, probe_state) = at_rest(3.0);
    let longest = (0..4)
        .map(|c| probe.free_length(&probe_state, c))
        .fold(0.0, f64::max);
    // Each line one stored node (its reel end) with half a segment behind the pulley at most.
    let (mut model, rest) = at_rest(N as f64 * longest / (N as f64 - 0.5));
    assert_eq!(model.stored(), &[1, 1, 1, 1]);
    model.lock_reels(true);
    let mut y0 = rest.clone();
    let shift = Vector3::new(OFFSET, 0.5 * OFFSET, -0.3 * OFFSET);
    let p = model.effector(&rest).position;
    for cable in 0..4 {
        let a = model.pulley(cable);
        for j in 1..=N {
            let node = model.node(&rest, cable, j);
            let moved = node + shift * ((node - a).norm() / (p - a).norm());
            for axis in 0..3 {
                y0[model.index(cable, j, axis)] = moved[axis];
            }
        }
    }
    let (t_end, sample) = (0.1, 1e-4);
    let times: Vec<f64> = (1..=1000).map(|k| k as f64 * sample).collect();
    let coarse = watched(&moordyn(&system(&model, &y0, 2e-6, t_end, sample)));
    let fine = watched(&moordyn(&system(&model, &y0, 1e-6, t_end, sample)));
    let ((loose, _), (tight, drift)) = (
        ours(&model, &y0, &times, 1e-9),
        ours(&model, &y0, &times, 1e-10),
    );
    let rk4 = gap(&coarse, &fine) / 15.0;
    let dopri = gap(&loose, &tight) / 9.0;
    let bound = 2.0 * (rk4 + dopri);
    let error = gap(&tight, &fine);
    let swing = gap(&tight, &vec![p; tight.len()]);
    assert!(swing > 0.5 * OFFSET, "the effector barely moved: {swing} m");
    assert!(
        drift <= 1e-8,
        "locked reels: the energy changed by {drift:e} J"
    );
    assert!(
        error <= bound,
        "MoorDyn {error:e} m from ours; bound {bound:e} m"
    );
}

/// The lines' length for one stored node per line (the reel end, half a segment behind its
/// pulley at most), from the free lengths of a rest on long lines.
fn one_stored_node_length(mu: f64) -> f64 {
    let (probe, state) = at_rest_with(3.0, mu);
    let longest = (0..4)
        .map(|c| probe.free_length(&state, c))
        .fold(0.0, f64::max);
    N as f64 * longest / (N as f64 - 0.5)
}

/// The modes of `model` at `rest` with the coordinates `held` fixed: K = −∂F/∂q from the model's
/// own second-order form (S(c_q = 1) − S(0)), M its diagonal, and the eigenpairs of
/// M^(−1/2) K M^(−1/2) over the other coordinates (`keep`, the eigenvectors' row order). K must
/// be symmetric (conservative springs, no stored node but the held ones) to 1e-9.
fn modes_holding(
    model: &LumpedSpatial,
    rest: &[f64],
    held: &[usize],
) -> (nalgebra::SymmetricEigen<f64, nalgebra::Dyn>, Vec<usize>) {
    use cdpr_bench::core::second_order::SecondOrderForm;
    use nalgebra::{DMatrix, SymmetricEigen};
    let mut form = model.clone();
    let n = form.dofs();
    let (k, m) = cdpr_bench::analysis::rest_modes::stiffness_and_mass(&mut form, rest, &[0.0; 4]);
    let keep: Vec<usize> = (0..n).filter(|i| !held.contains(i)).collect();
    let scaled = DMatrix::from_fn(keep.len(), keep.len(), |r, c| {
        let (i, j) = (keep[r], keep[c]);
        k[(i, j)] / (m[i] * m[j]).sqrt()
    });
    let asymmetry = (&scaled - scaled.transpose()).amax();
    assert!(
        asymmetry <= 1e-9 * scaled.amax(),
        "K not symmetric: {asymmetry:e}"
    );
    (
        SymmetricEigen::new((&scaled + scaled.transpose()) * 0.5),
        keep,
    )
}

/// The reel ends' coordinates (locked reels hold them).
fn reel_ends(model: &LumpedSpatial) -> Vec<usize> {
    (0..4)
        .flat_map(|c| (0..3).map(move |a| (c, a)))
        .map(|(c, a)| model.index(c, 0, a))
        .collect()
}

/// The effector's three mode frequencies [rad/s] of the locked robot at `rest` (lumped: the
/// modes of [`modes_holding`] the reel ends, the effector's being those whose kinetic energy the
/// effector holds most of), and the massless elastic lines' with the same reels locked at the
/// same pose (MODELS.md §11: K = Σ (EA/L_i) u_i u_iᵀ + (T_i/l_i)(I − u_i u_iᵀ), L_i the locked
/// line's whole unstrained length from its reel end, T_i the lumped line's tension at the
/// effector).
fn effector_modes(model: &LumpedSpatial, rest: &[f64]) -> ([f64; 3], [f64; 3]) {
    use nalgebra::Matrix3;
    let (eigen, keep) = modes_holding(model, rest, &reel_ends(model));
    let effector: Vec<usize> = (0..3)
        .map(|a| {
            keep.iter()
                .position(|&i| i == model.index(0, N, a))
                .unwrap()
        })
        .collect();
    let mut ranked: Vec<(f64, f64)> = (0..keep.len())
        .map(|k| {
            let v = eigen.eigenvectors.column(k);
            let share: f64 = effector.iter().map(|&i| v[i] * v[i]).sum();
            (share, eigen.eigenvalues[k].max(0.0).sqrt())
        })
        .collect();
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut lumped = [ranked[0].1, ranked[1].1, ranked[2].1];
    lumped.sort_by(f64::total_cmp);
    let p = model.effector(rest).position;
    let mut k_elastic = Matrix3::<f64>::zeros();
    for cable in 0..4 {
        let d = model.pulley(cable) - p;
        let (l, u) = (d.norm(), d.normalize());
        let t = model.spring_force(rest, cable, N - 1);
        let whole = N as f64 * model.segment;
        k_elastic +=
            u * u.transpose() * (EA / whole) + (Matrix3::identity() - u * u.transpose()) * (t / l);
    }
    let mass_effector = model.robot().effector_mass;
    let mut elastic: Vec<f64> = k_elastic
        .symmetric_eigenvalues()
        .iter()
        .map(|v| (v / mass_effector).sqrt())
        .collect();
    elastic.sort_by(f64::total_cmp);
    (lumped, [elastic[0], elastic[1], elastic[2]])
}

/// The effector's modes on lumped lines with locked reels tend to the massless elastic lines'
/// as the lines' mass goes to zero (MODELS.md §11's locked-reel stiffness), at first order: from
/// μ/8 to μ/16 of the example's line the relative gap of each of the three modes halves (ratio
/// within 0.45–0.55; measured 0.49 for all three, the ratios from μ down being 0.43, 0.47, 0.49,
/// 0.49, 0.50 for the horizontal pair and 0.36, 0.44, 0.47, 0.49, 0.49 for the vertical mode, as
/// a μ² part — Irvine's sag softening, (w l)² EA/(12 T³) ≈ 4e-4 here — fades), and on the
/// example's line it is below 0.2 % (measured 0.12 % and 0.17 % at 122 and 133 rad/s).
#[test]
fn the_effector_modes_tend_to_the_elastic_lines_as_the_mass_vanishes() {
    let gaps = |mu: f64| {
        let length = one_stored_node_length(mu);
        let (model, rest) = at_rest_with(length, mu);
        assert_eq!(model.stored(), &[1, 1, 1, 1]);
        let (lumped, elastic) = effector_modes(&model, &rest);
        [0, 1, 2].map(|k| (lumped[k] - elastic[k]).abs() / elastic[k])
    };
    let example = gaps(MU);
    let (coarse, fine) = (gaps(MU / 8.0), gaps(MU / 16.0));
    for k in 0..3 {
        assert!(example[k] < 2e-3, "mode {k}: {} relative", example[k]);
        let ratio = fine[k] / coarse[k];
        assert!(
            (0.45..=0.55).contains(&ratio),
            "mode {k}: gaps {} and {}",
            coarse[k],
            fine[k]
        );
    }
}

/// A taut line's transverse modes are the discrete string's closed form: a weightless robot
/// (g = 0) with anchors on a regular tetrahedron (circumradius 1.5 m) around its effector, every
/// line straight under the QP's 10 N, locked with its reel end at the pulley (a line as long as
/// its free span, to 1e-9) and the effector held: each line is then N springs of stretched
/// length d = l/N joining N − 1 masses m = μ l0 between fixed ends, whose transverse modes are
/// ω_k = 2 √(T/(m d)) sin(kπ/(2N)), k = 1 … N − 1, each in two directions on each of the four
/// lines (8 copies), all below the axial ones. The 8(N − 1) lowest frequencies of the model
/// match them to 1e-9 (the eigen-solver's round-off; the geometric term T/λ is all that
/// resists a transverse motion).
#[test]
fn a_taut_lines_transverse_modes_are_the_discrete_strings() {
    let r = 1.5;
    let (a, b) = ((8.0f64 / 9.0).sqrt(), (2.0f64 / 9.0).sqrt());
    let c = (2.0f64 / 3.0).sqrt();
    let anchors = [
        Vector3::new(r * a, 0.0, -r / 3.0),
        Vector3::new(-r * b, r * c, -r / 3.0),
        Vector3::new(-r * b, -r * c, -r / 3.0),
        Vector3::new(0.0, 0.0, r),
    ];
    let robot = Robot::new(&anchors, 1.0, 0.0).unwrap();
    let tension = 10.0;
    let free = r / (1.0 + tension / EA);
    let cable = CableProperties {
        elements: N,
        modelled_length: free * (1.0 + 1e-9),
        mass_per_length: MU,
        axial_stiffness: EA,
        axial_damping: 0.0,
    };
    let mut model = LumpedSpatial::new(robot, cable, &default_reel_directions(&anchors)).unwrap();
    let p = Vector3::zeros();
    let hold = cdpr_bench::core::robot::Tensions::from_fn(4, |_| tension);
    let rest = model.equilibrium(&PoseRule::new(&p, hold)).unwrap().state;
    assert_eq!(model.stored(), &[1, 1, 1, 1]);
    let mut held = reel_ends(&model);
    held.extend((0..3).map(|axis| model.index(0, N, axis)));
    let (eigen, _) = modes_holding(&model, &rest, &held);
    let mut omega: Vec<f64> = eigen
        .eigenvalues
        .iter()
        .map(|v| v.max(0.0).sqrt())
        .collect();
    omega.sort_by(f64::total_cmp);
    let (m, d) = (model.node_mass, r / N as f64);
    for k in 1..N {
        let expected = 2.0
            * (tension / (m * d)).sqrt()
            * (k as f64 * std::f64::consts::PI / (2.0 * N as f64)).sin();
        for copy in 0..8 {
            let got = omega[8 * (k - 1) + copy];
            assert!(
                (got - expected).abs() <= 1e-9 * expected,
                "mode {k}, copy {copy}: {got} rad/s against {expected} rad/s"
            );
        }
    }
}

/// The locked robot with its effector held as an ODE.
struct HeldEffector(LumpedSpatial);

impl OdeSystem for HeldEffector {
    fn dimension(&self) -> usize {
        self.0.state_len()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.0.rhs(t, y, &[0.0; 4], dy);
        let np = self.0.positions_len();
        for axis in 0..3 {
            let i = self.0.index(0, N, axis);
            (dy[i], dy[np + i]) = (0.0, 0.0);
        }
    }
}

/// Node `j` of line 1 at `times` from `y0` with the reels locked and the effector held, by
/// DOPRI5 at rtol 1e-10.
fn held_line_node(model: &LumpedSpatial, y0: &[f64], times: &[f64], j: usize) -> Vec<Vector3<f64>> {
    let mut locked = model.clone();
    locked.lock_reels(true);
    let mut sys = HeldEffector(locked);
    let opts = Dopri5Options {
        rtol: 1e-10,
        atol: 1e-13,
        ..Dopri5Options::default()
    };
    let mut d = Dopri5::new(y0.len(), opts);
    d.start(&mut sys, 0.0, y0, *times.last().unwrap()).unwrap();
    let mut out = vec![0.0; y0.len()];
    times
        .iter()
        .map(|&t| {
            while d.time() < t {
                d.step(&mut sys, *times.last().unwrap()).unwrap();
            }
            d.dense_output(t, &mut out);
            model.node(&out, 0, j)
        })
        .collect()
}

/// The times [s] at which the samples `q` (at `times`) cross zero, by linear interpolation.
fn zero_crossings(times: &[f64], q: &[f64]) -> Vec<f64> {
    (1..q.len())
        .filter(|&k| q[k - 1] * q[k] < 0.0)
        .map(|k| times[k - 1] + (times[k] - times[k - 1]) * q[k - 1] / (q[k - 1] - q[k]))
        .collect()
}

/// A single line's out-of-plane string mode against MoorDyn's: the locked robot at rest with
/// its effector held, line 1's lowest mode across its vertical plane (the model's own
/// eigenpair: the lowest mode whose motion lies ≥ 90 % across that plane on line 1, 199.38
/// rad/s) given as the initial shape with 0.1 mm at its largest, released for 0.2 s in MoorDyn
/// (RK4, dtM = 5 µs, the effector a fixed point) and in ours (DOPRI5 at rtol 1e-10). The
/// frequency the line's middle node swings at, from its zero crossings (linearly interpolated
/// at 10 µs samples), is the same in both to 1e-8: the same discrete line, so what may differ
/// is the integrators' phase error, RK4's (ω h)⁴/120 ≈ 1e-14 and DOPRI5's below 1e-9 (measured:
/// 1.2e-14). Both lie within 2e-5 of the eigenvalue (measured 6.7e-6: the estimate's bias
/// from the finite swing, which the two codes share).
#[test]
fn a_single_lines_out_of_plane_mode_matches_moordyn() {
    let (model, rest) = at_rest(one_stored_node_length(MU));
    assert_eq!(model.stored(), &[1, 1, 1, 1]);
    let p = model.effector(&rest).position;
    let a = model.pulley(0);
    let across = (p - a).cross(&Vector3::z()).normalize();
    let mut held = reel_ends(&model);
    held.extend((0..3).map(|axis| model.index(0, N, axis)));
    let (eigen, keep) = modes_holding(&model, &rest, &held);
    let line: Vec<(usize, usize, usize)> = (1..N)
        .flat_map(|j| (0..3).map(move |axis| (j, axis)))
        .map(|(j, axis)| {
            let at = keep
                .iter()
                .position(|&i| i == model.index(0, j, axis))
                .unwrap();
            (j, axis, at)
        })
        .collect();
    let mut order: Vec<usize> = (0..keep.len()).collect();
    order.sort_by(|&i, &k| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[k]));
    let mode = order
        .into_iter()
        .find(|&k| {
            let v = eigen.eigenvectors.column(k);
            let out: f64 = (1..N)
                .map(|j| {
                    let d: f64 = line
                        .iter()
                        .filter(|e| e.0 == j)
                        .map(|e| v[e.2] * across[e.1])
                        .sum();
                    d * d
                })
                .sum();
            out >= 0.9 * v.norm_squared()
        })
        .unwrap();
    let omega = eigen.eigenvalues[mode].sqrt();
    let v = eigen.eigenvectors.column(mode);
    let scale = 1e-4 / v.amax();
    let mut y0 = rest.clone();
    for (i, &coordinate) in keep.iter().enumerate() {
        y0[coordinate] += scale * v[i];
    }
    let middle = N / 2;
    let mut case = system(&model, &y0, 5e-6, 0.2, 1e-5);
    case["points"][8]["fixed"] = json!(true);
    // Line 1 (index 1) runs from the connector, our P_1, to the effector: its node k is P_(k+1).
    case["watch_node"] = json!([1, middle - 1]);
    let answer = moordyn(&case);
    let times: Vec<f64> = answer["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    let at_rest = model.node(&rest, 0, middle);
    let swing: Vec<f64> = answer["node"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| {
            let x = Vector3::new(
                x[0].as_f64().unwrap(),
                x[1].as_f64().unwrap(),
                x[2].as_f64().unwrap(),
            );
            (x - at_rest).dot(&across)
        })
        .collect();
    let frequency = |swing: &[f64]| {
        let crossings = zero_crossings(&times, swing);
        assert!(crossings.len() >= 8, "{} crossings", crossings.len());
        std::f64::consts::PI * (crossings.len() - 1) as f64
            / (crossings.last().unwrap() - crossings[0])
    };
    let measured = frequency(&swing);
    let simulated: Vec<f64> = held_line_node(&model, &y0, &times, middle)
        .iter()
        .map(|x| (x - at_rest).dot(&across))
        .collect();
    let simulated = frequency(&simulated);
    eprintln!(
        "out-of-plane mode: eigenvalue {omega}, ours simulated {simulated}, MoorDyn {measured} \
         rad/s"
    );
    assert!(
        (measured - simulated).abs() <= 1e-8 * omega,
        "MoorDyn {measured} rad/s against ours {simulated} rad/s"
    );
    assert!(
        (simulated - omega).abs() <= 2e-5 * omega,
        "ours {simulated} rad/s against the eigenvalue's {omega} rad/s"
    );
}
