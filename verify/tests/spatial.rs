//! Spatial robots (MODELS.md §11), checked against what the code did not produce: the planar
//! run of the same robot, closed forms of the pendulum frequency and of the locked-reel
//! stiffness, energy conservation with the strain energy computed here, the designed error
//! dynamics of computed-torque integrated here, and named refusals of bad input.

use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::controller::length::LengthControl;
use cdpr_bench::core::controller::{Controller, Reference};
use cdpr_bench::core::model::CableModel;
use cdpr_bench::core::robot::{Effector, Matrix, Robot, Vector};
use cdpr_bench::core::runner::{Observer, RunOptions, simulate_from};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::elastic::Elastic;
use cdpr_bench::{Error, simulate, simulate_spatial};
use proptest::prelude::*;

const HANGPRINTER: &str = "
[robot]
anchors = [[0.0, -1.61098, -0.13153], [1.31422, 1.26814, -0.12128], [-1.41573, 0.70761, -0.12182], [0.0, 0.0, 2.29983]]
effector_mass = 1.0
[cable]
youngs_modulus = 2.105e10
area = 9.503e-7
density = 970.0
[controller]
t_min = 10.0
t_max = 70.0
[trajectory]
start = [0.0, 0.0, 0.0]
end = [0.1, 0.05, 0.02]
t1 = 0.0
t2 = 0.2
[simulation]
t_final = 1.5
sample_period = 1e-3
";

/// The Hangprinter scenario with the keys of `extra` set (each in its section).
fn hangprinter_text(extra: &str) -> String {
    let mut doc: toml::Table = toml::from_str(HANGPRINTER).unwrap();
    let add: toml::Table = toml::from_str(extra).unwrap();
    for (section, values) in add {
        let target = doc
            .entry(section)
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        for (k, v) in values.as_table().unwrap() {
            target.as_table_mut().unwrap().insert(k.clone(), v.clone());
        }
    }
    toml::to_string(&doc).unwrap()
}

fn hangprinter(extra: &str) -> Scenario {
    cdpr_bench::scenario_from_toml_str(&hangprinter_text(extra)).unwrap()
}

fn run_spatial(scenario: &Scenario) -> Result<cdpr_bench::SpatialRun, Error> {
    simulate_spatial(scenario, &mut Observer::progress(&mut |_| {}))
}

/// The paper's robot given with 3-D anchors in the plane y = 0 and the paper's PID: y stays 0
/// exactly (every force lies in the plane) and x, z, T1, T2 equal the planar run's to the
/// integrators' tolerance. Both runs are made at rtol = 1e-10 (atol 1e-12): they take
/// different steps (the spatial state has two more components in DOPRI5's error norm), so each
/// is within its global error of the exact solution, a few hundred times rtol over 2 s of a
/// lightly damped loop — 1e-7 m and 1e-5 N bound both differences with that margin.
#[test]
fn the_paper_robot_in_space_equals_the_planar_run() {
    let mut planar = Scenario::paper();
    planar.simulation.t_final = 2.0;
    planar.simulation.sample_period = 1e-3;
    planar.simulation.rtol = 1e-10;
    planar.simulation.atol = 1e-12;
    let mut spatial = planar.clone();
    spatial.robot.anchors = Some(vec![vec![0.0, 0.0, 0.0], vec![1.0, 0.0, 0.0]]);
    spatial.validate().unwrap();
    let a = simulate(&planar, &mut |_| {}).unwrap();
    let b = run_spatial(&spatial).unwrap().run;
    assert_eq!(a.series.len(), b.series.len());
    let y = b.series.channel(Channel::Y).unwrap();
    assert!(y.iter().all(|&v| v == 0.0), "y leaves the plane");
    for (channel, tol) in [
        (Channel::X, 1e-7),
        (Channel::Z, 1e-7),
        (Channel::T1, 1e-5),
        (Channel::T2, 1e-5),
    ] {
        let (pa, pb) = (
            a.series.channel(channel).unwrap(),
            b.series.channel(channel).unwrap(),
        );
        let worst = pa
            .iter()
            .zip(pb)
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max);
        assert!(worst < tol, "{channel}: differs by {worst:e}");
    }
}

/// Two anchors given as 2-vectors, (0, 0) and (1, 0), are the paper's planar robot: the same
/// run to the bit; other planar spellings are refused by name.
#[test]
fn planar_anchors_as_2_vectors_are_the_paper_robot() {
    let short = "[simulation]\nt_final = 1.0\n[analysis]\nmodes = \"off\"\n";
    let paper = cdpr_bench::scenario_from_toml_str(short).unwrap();
    let spelled = cdpr_bench::scenario_from_toml_str(&format!(
        "[robot]\nanchors = [[0.0, 0.0], [1.0, 0.0]]\n{short}"
    ))
    .unwrap();
    assert_eq!(spelled, paper);
    let (a, b) = (
        simulate(&paper, &mut |_| {}).unwrap(),
        simulate(&spelled, &mut |_| {}).unwrap(),
    );
    for i in 0..a.series.len() {
        assert!(
            a.series
                .row(i)
                .iter()
                .zip(b.series.row(i))
                .all(|(u, v)| u.to_bits() == v.to_bits())
        );
    }
    for bad in [
        "[[0.1, 0.0], [1.0, 0.0]]",
        "[[0.0, 0.0], [1.0, 0.2]]",
        "[[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]]",
    ] {
        let err = cdpr_bench::scenario_from_toml_str(&format!("[robot]\nanchors = {bad}\n"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("robot.anchors") && err.contains("[[0, 0], [d, 0]]"),
            "{bad}: {err}"
        );
    }
}

/// The out-of-plane mode of the paper's robot in space is the pendulum ω_y² = Σ T_i/(M l_i):
/// the y-row of the elastic model's Jacobian at rest (tensions held), by central differences of
/// its right-hand side (exact to ~1e-9 relative for a 1e-6 m step on a smooth field).
#[test]
fn the_out_of_plane_mode_is_the_pendulum() {
    let robot = Robot::<3>::new(
        &[
            Vector::<3>::new(0.0, 0.0, 0.0),
            Vector::<3>::new(1.0, 0.0, 0.0),
        ],
        1.0,
        9.81,
    )
    .unwrap();
    let mut model = Elastic::new(robot, 179_520.0);
    for x in [0.3, 0.5, 0.6, 0.8] {
        let rule = cdpr_bench::core::model::SplitRule::new(x, 200.0);
        let eq = model.equilibrium(&rule).unwrap();
        let p = Vector::<3>::from_column_slice(&eq.state[..3]);
        let t = eq.tensions;
        let h = 1e-6;
        let mut rate = [[0.0; 6]; 2];
        for (k, sign) in [1.0, -1.0].into_iter().enumerate() {
            let mut y = eq.state.clone();
            y[1] += sign * h;
            model.rhs(0.0, &y, &t, &mut rate[k]);
        }
        let stiffness = -(rate[0][4] - rate[1][4]) / (2.0 * h);
        let closed: f64 = (0..2)
            .map(|i| t[i] / robot.chord(i, &p).length)
            .sum::<f64>()
            / robot.effector_mass;
        assert!(
            (stiffness - closed).abs() < 1e-7 * closed,
            "x = {x}: ω_y² = {stiffness} against Σ T/(M l) = {closed}"
        );
    }
}

/// The pull of locked reels, f(p) = Σ T_i(p) u_i(p) with T_i = EA (l_i − l0_i)/l0_i, has the
/// stiffness K = −∂f/∂p = Σ (EA/l_i) u_i u_iᵀ + (T_i/l_i) I (MODELS.md §11); checked by central
/// differences of the `length` controller's tensions (relative error ~h²/l² + round-off, 1e-6).
fn locked_reel_stiffness(anchors: &[Vector<3>], pose: Vector<3>) -> Result<(), TestCaseError> {
    let robot = Robot::<3>::new(anchors, 2.0, 9.81).unwrap();
    let mut scenario = Scenario::paper();
    scenario.controller.t_min = Some(10.0);
    scenario.controller.t_max = Some(5000.0);
    scenario.trajectory.start = Some(pose.iter().copied().collect());
    let controller = LengthControl::new(&scenario, robot);
    let reference = Reference {
        position: pose,
        ..Reference::default()
    };
    // Only poses where the static distribution holds the effector inside the box.
    let l0 = controller.reel_lengths(&reference);
    let pull = |p: Vector<3>| {
        let out = controller.output(
            &reference,
            &Effector {
                position: p,
                velocity: Vector::zeros(),
            },
            &[],
        );
        (out.wrench, out.tensions)
    };
    let (_, t) = pull(pose);
    prop_assume!(t.iter().all(|&v| v > 1.0));
    let ea = controller.axial_stiffness;
    let mut closed = Matrix::<3>::zeros();
    for i in 0..robot.cables() {
        let c = robot.chord(i, &pose);
        closed += c.direction * c.direction.transpose() * (ea / c.length)
            + Matrix::<3>::identity() * (t[i] / c.length);
        prop_assert!((c.length / (1.0 + t[i] / ea) - l0[i]).abs() < 1e-12);
    }
    let h = 1e-6;
    for j in 0..3 {
        let mut dp = Vector::<3>::zeros();
        dp[j] = h;
        let column = -(pull(pose + dp).0 - pull(pose - dp).0) / (2.0 * h);
        for i in 0..3 {
            let scale = closed.abs().max();
            prop_assert!(
                (column[i] - closed[(i, j)]).abs() < 1e-6 * scale,
                "K[{i}][{j}] = {} against {}",
                column[i],
                closed[(i, j)]
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn locked_reels_have_the_closed_form_stiffness(
        m in 4usize..=8,
        radius in 1.0f64..3.0,
        heights in proptest::collection::vec(-0.5f64..3.0, 8),
        phase in 0.0f64..1.0,
        px in -0.3f64..0.3,
        py in -0.3f64..0.3,
        pz in 0.0f64..0.6,
    ) {
        let anchors: Vec<Vector<3>> = (0..m)
            .map(|i| {
                let a = std::f64::consts::TAU * (i as f64 + phase) / m as f64;
                // One anchor high above the others keeps the weight holdable.
                let z = if i == 0 { 4.0 } else { heights[i] };
                Vector::<3>::new(radius * a.cos(), radius * a.sin(), z)
            })
            .collect();
        locked_reel_stiffness(&anchors, Vector::<3>::new(px, py, pz))?;
    }
}

/// Locked reels (the `length` controller with a move of zero length) conserve the effector's
/// kinetic and gravity energy plus the cables' strain energy Σ EA (l − l0)²/(2 l0), computed
/// here from the sampled lengths — after a 2 mm push off the rest pose. DOPRI5 at rtol 1e-10
/// drifts the total by its local errors only: 1e-8 of the oscillation's energy.
#[test]
fn locked_reels_conserve_energy() {
    let scenario = hangprinter(
        "[controller]\nkind = \"length\"\n[trajectory]\nend = [0.0, 0.0, 0.0]\n[simulation]\nrtol = 1e-10\natol = 1e-13\nt_final = 0.5\nsample_period = 1e-4",
    );
    let robot = scenario.spatial_robot().unwrap();
    let ea = scenario.cable.axial_stiffness();
    let model = Elastic::new(robot, ea);
    let mut sys = ClosedLoop::new(model, &scenario).unwrap();
    let (mut y0, eq) = sys.initial_state().unwrap();
    // Small enough that no cable goes slack (k ≈ EA/l ≈ 13 kN/m against ≥ 10 N of pretension).
    y0[0] += 3e-4;
    y0[2] -= 2e-4;
    let run = simulate_from(&mut sys, y0, eq, &RunOptions::from(&scenario), &mut |_| {}).unwrap();
    let s = &run.series;
    let start = Reference {
        position: Vector::<3>::zeros(),
        ..Reference::default()
    };
    let l0 = LengthControl::new(&scenario, robot).reel_lengths(&start);
    let energy = |k: usize| {
        let p = Vector::<3>::new(
            s.channel(Channel::X).unwrap()[k],
            s.channel(Channel::Y).unwrap()[k],
            s.channel(Channel::Z).unwrap()[k],
        );
        let strain: f64 = (0..4)
            .map(|i| {
                let stretch = (robot.chord(i, &p).length - l0[i]).max(0.0);
                ea * stretch * stretch / (2.0 * l0[i])
            })
            .sum();
        s.channel(Channel::EKinetic).unwrap()[k] + s.channel(Channel::EGravity).unwrap()[k] + strain
    };
    let e0 = energy(0);
    let swing = (0..s.len())
        .map(|k| s.channel(Channel::EKinetic).unwrap()[k])
        .fold(0.0, f64::max);
    assert!(
        swing > 1e-4,
        "the push sets the effector swinging ({swing} J)"
    );
    let drift = (0..s.len())
        .map(|k| (energy(k) - e0).abs())
        .fold(0.0, f64::max);
    assert!(
        drift < 1e-8 * swing.max(1.0),
        "energy drifts by {drift:e} J of {swing} J"
    );
}

/// Computed-torque in 3-D: after a push off the reference, every component of the error obeys
/// ë + K_d ė + K_p e + K_i ∫e = 0 (unfiltered velocity), integrated here by RK4 at 1e-6 s; the
/// run (DOPRI5 at rtol 1e-10) agrees to 1e-6 of the push.
#[test]
fn computed_torque_gives_its_designed_error_dynamics_in_space() {
    let scenario = hangprinter(
        "[controller]\nkind = \"computed-torque\"\nvelocity_filter = inf\n[trajectory]\nend = [0.0, 0.0, 0.0]\n[simulation]\nrtol = 1e-10\natol = 1e-13\nt_final = 0.2\nsample_period = 1e-3",
    );
    let robot = scenario.spatial_robot().unwrap();
    let c = &scenario.controller;
    let model = Elastic::new(robot, scenario.cable.axial_stiffness());
    let mut sys = ClosedLoop::new(model, &scenario).unwrap();
    let (mut y0, eq) = sys.initial_state().unwrap();
    // Small enough that K_p e keeps the tensions inside the box (no clamp, no anti-windup).
    let push = [1e-5, -2e-5, 0.5e-5];
    for k in 0..3 {
        y0[k] += push[k];
    }
    let run = simulate_from(&mut sys, y0, eq, &RunOptions::from(&scenario), &mut |_| {}).unwrap();
    let s = &run.series;
    for (k, channel) in [Channel::X, Channel::Y, Channel::Z].into_iter().enumerate() {
        // e = −p (the reference is the origin): (σ, e, ė) from (0, −push, 0).
        let mut state = [0.0, -push[k], 0.0];
        let f = |s: [f64; 3]| [s[1], s[2], -c.kd * s[2] - c.kp * s[1] - c.ki * s[0]];
        let h = 1e-6;
        let mut t = 0.0;
        let p = s.channel(channel).unwrap();
        let times = s.channel(Channel::Time).unwrap();
        for (i, &ti) in times.iter().enumerate() {
            while t < ti - 0.5 * h {
                let k1 = f(state);
                let k2 = f(std::array::from_fn(|j| state[j] + 0.5 * h * k1[j]));
                let k3 = f(std::array::from_fn(|j| state[j] + 0.5 * h * k2[j]));
                let k4 = f(std::array::from_fn(|j| state[j] + h * k3[j]));
                state = std::array::from_fn(|j| {
                    state[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
                });
                t += h;
            }
            let e = -p[i];
            assert!(
                (e - state[1]).abs() < 1e-6 * push[k].abs(),
                "{channel} at t = {ti}: e = {e:e}, designed {:e}",
                state[1]
            );
        }
    }
}

/// The Hangprinter move, 0.11 m in 0.2 s: computed-torque and LQR follow it within
/// 1 µm on the elastic model with every distribution; the firmware's `length` controller with
/// its static flex compensation misses it by far more (no feedback: it rings), and feeding the
/// acceleration forward (`dynamic`) removes most of that.
#[test]
fn hangprinter_move_goals() {
    for kind in ["computed-torque", "lqr"] {
        for method in ["closed-form", "improved-closed-form", "puncture", "qp"] {
            let s = hangprinter(&format!(
                "[controller]\nkind = \"{kind}\"\ndistribution = \"{method}\""
            ));
            let m = run_spatial(&s).unwrap().metrics;
            assert!(
                m.path_err_max_move < 1e-6,
                "{kind}/{method}: {}",
                m.path_err_max_move
            );
            assert!(
                m.tension_min >= 10.0 - 1e-9 && m.tension_max <= 70.0 + 1e-9,
                "{kind}/{method}: {m:?}"
            );
            assert_eq!(m.saturated_s, 0.0, "{kind}/{method}");
        }
    }
    let firmware = run_spatial(&hangprinter("[controller]\nkind = \"length\""))
        .unwrap()
        .metrics;
    let dynamic = run_spatial(&hangprinter(
        "[controller]\nkind = \"length\"\nflex_compensation = \"dynamic\"",
    ))
    .unwrap()
    .metrics;
    assert!(firmware.path_err_max_move > 1e-4, "{firmware:?}");
    assert!(
        firmware.path_err_max_after_1s > 1e-4,
        "it rings: {firmware:?}"
    );
    assert!(
        dynamic.path_err_max_move < 0.01 * firmware.path_err_max_move,
        "{dynamic:?}"
    );
}

/// Reels driven by length report what they paid out: on the firmware's Hangprinter move a cable
/// goes slack, and there its `l0` exceeds its chord (the reel paid out more than the chord
/// takes up; l/(1 + T/EA) would say l0 = l); where taut and undamped, l0 = l/(1 + T/EA) to
/// round-off (1e-12 relative). With the line's damping the tension includes C (l̇ − l̇0)/l0, and
/// the channel still reports the reel's length, not l/(1 + T/EA).
#[test]
fn length_driven_reels_report_what_they_paid_out() {
    for damping in [0.0, 8.5] {
        let s = hangprinter(&format!(
            "[controller]\nkind = \"length\"\n[cable]\naxial_damping = {damping}"
        ));
        let run = run_spatial(&s).unwrap().run;
        let ea = s.cable.axial_stiffness();
        let (mut slack, mut damped_off) = (0usize, 0.0f64);
        for i in 1..=4 {
            let t = run.series.channel_named(&format!("T{i}")).unwrap();
            let l = run.series.channel_named(&format!("l{i}")).unwrap();
            let l0 = run.series.channel_named(&format!("l0_{i}")).unwrap();
            for k in 0..t.len() {
                let strain_law = l[k] / (1.0 + t[k] / ea);
                // (Damped, a line shortening fast goes slack while still stretched: the
                // damper cannot push either.)
                if t[k] == 0.0 && damping == 0.0 {
                    slack += 1;
                    assert!(
                        l0[k] > l[k],
                        "cable {i} slack at sample {k}: l0 {} ≤ l {}",
                        l0[k],
                        l[k]
                    );
                } else if damping == 0.0 {
                    assert!(
                        (l0[k] / strain_law - 1.0).abs() < 1e-12,
                        "cable {i}, sample {k}"
                    );
                } else {
                    damped_off = damped_off.max((l0[k] / strain_law - 1.0).abs());
                }
            }
        }
        if damping == 0.0 {
            assert!(slack > 0, "the firmware's move lets a cable go slack");
        } else {
            assert!(
                damped_off > 1e-9,
                "the damped tension is not the strain's: {damped_off}"
            );
        }
    }
}

/// Every example robot's own move (Hangprinter 4 cables; CoGiRo and IPAnema 8, IPAnema with
/// t_min = 0 so that four cables rest idle at 0 N) under computed-torque with the exact QP: the
/// path within 1 µm, every tension inside the file's box.
#[test]
fn every_example_robot_follows_its_move() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots");
    for name in ["hangprinter", "cogiro", "ipanema"] {
        let s = cdpr_bench::scenario_from_file(&dir.join(format!("{name}.toml"))).unwrap();
        let m = run_spatial(&s).unwrap().metrics;
        let (t_min, t_max) = (s.controller.t_min.unwrap(), s.controller.t_max.unwrap());
        assert!(
            m.path_err_max_move < 1e-6,
            "{name}: {}",
            m.path_err_max_move
        );
        assert!(
            m.tension_min >= t_min - 1e-9 && m.tension_max <= t_max + 1e-9,
            "{name}: {m:?}"
        );
        assert_eq!(m.saturated_s, 0.0, "{name}");
    }
}

/// Bad input gets a named error before any work.
#[test]
fn bad_spatial_input_is_refused_by_name() {
    let refuse = |extra: &str, key: &str| {
        let err = match cdpr_bench::scenario_from_toml_str(&hangprinter_text(extra)) {
            Err(e) => e.to_string(),
            Ok(s) => match run_spatial(&s) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("{extra} accepted"),
            },
        };
        assert!(err.contains(key), "{extra}: {err}");
    };
    refuse("[robot]\nanchors = [[0.0, 0.0, 0.0]]", "robot.anchors");
    refuse(
        "[robot]\nanchors = [[0,0,0],[1,0,0],[2,0,0],[3,0,0],[0,1,0],[1,1,0],[2,1,0],[3,1,0],[4,4,4]]",
        "robot.anchors",
    );
    refuse(
        "[robot]\nanchors = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]",
        "robot.anchors",
    );
    refuse(
        "[robot]\nanchors = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]",
        "collinear",
    );
    refuse(
        "[robot]\nanchors = [[0.0, 0.0, nan], [1.0, 0.0, 0.0], [2.0, 1.0, 0.0]]",
        "robot.anchors",
    );
    refuse(
        "[robot]\nanchors = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]\n[controller]\nkind = \"computed-torque\"",
        "controller.kind",
    );
    refuse("[trajectory]\nend = [5.0, 0.0, 0.0]", "trajectory.end");
    refuse("[controller]\nt_max = 11.0", "wrench-feasible");
    refuse(
        "[trajectory]\nend = [0.3, 0.2, 0.2]\nt2 = 0.05",
        "wrench-feasible",
    );
    // FE cables in space: the line must cover the move (here 1 m against 2.3 m chords).
    refuse("[model]\nkind = \"fe\"", "cable.modelled_length");
    refuse("[model]\nkind = \"lumped\"", "cable.modelled_length");
    refuse(
        "[model]\nkind = \"lumped\"\nelements = 2\n[cable]\nmodelled_length = 3.2",
        "model.elements",
    );
    refuse(
        "[robot]\nreel_directions = [[0, 0, 1]]",
        "robot.reel_directions",
    );
    refuse(
        "[trajectory]\nshaper = \"zv\"",
        "trajectory.shaper_frequency",
    );
    let planar_length =
        cdpr_bench::scenario_from_toml_str("[controller]\nkind = \"length\"").unwrap_err();
    assert!(
        planar_length.to_string().contains("controller.kind"),
        "{planar_length}"
    );
}

/// The start refused when no distribution in the box holds the weight: named with the time 0,
/// the pose and the cable.
#[test]
fn a_start_no_box_can_hold_is_named() {
    let s = hangprinter("[controller]\nt_max = 11.0");
    let err = run_spatial(&s).err().expect("refused").to_string();
    assert!(err.contains("at t = 0 s") && err.contains("cable"), "{err}");
}
