//! The controllers against what they did not produce: computed-torque's designed error dynamics
//! in closed form on the elastic model, the LQR design's plant against a finite-difference
//! linearisation of the elastic model and its gain against the Riccati equation, `pid-xz`'s z
//! loop against the roots of its characteristic polynomial, saturation and anti-windup on a
//! move that saturates, and the velocity filter's implicit step against its defining rule.

use cdpr_bench::analysis::modes::Loop;
use cdpr_bench::core::Vector2;
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::controller::lqr::Lqr;
use cdpr_bench::core::controller::velocity_filter::VelocityFilter;
use cdpr_bench::core::controller::{self, Controller, Reference, StepStart, TensionLimits};
use cdpr_bench::core::model::CableModel;
use cdpr_bench::core::robot::{Effector, Tensions};
use cdpr_bench::core::runner::{RunOptions, simulate_from};
use cdpr_bench::core::scenario::{ControllerKind, Scenario};
use cdpr_bench::elastic::Elastic;
use cdpr_bench::numerics::Dopri5Options;
use cdpr_bench::{analyse, assess, scenario_from_toml_str};
use faer::Mat;
use proptest::prelude::*;

fn scenario(text: &str) -> Scenario {
    scenario_from_toml_str(text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Computed-torque on the elastic model (massless cables: the effector feels the commanded
/// tension) makes each error component obey ë + K_d ė + K_p e + K_i ∫e = 0. With the gains
/// (3ω, 3ω², ω³) and the effector released at rest δ from the held reference, u = ∫e obeys
/// u(0) = 0, u'(0) = −δ, u''(0) = 0, so e(t) = u' = −δ e^{−ωt} (1 + ωt − ω²t²). Bound: DOPRI5 at
/// rtol 1e-10 commits ≤ rtol·|x| ≈ 5e-11 m per step over ≤ 200 steps: 1e-8 m.
#[test]
fn computed_torque_gives_the_designed_error_dynamics_on_the_elastic_model() {
    let omega: f64 = 40.0;
    let s = scenario(&format!(
        "[controller]\nkind = \"computed-torque\"\nkp = {}\nkd = {}\nki = {}\nvelocity_filter = inf\n\
         [trajectory]\nt1 = 10.0\nt2 = 11.0\n",
        3.0 * omega * omega,
        3.0 * omega,
        omega.powi(3)
    ));
    let mut sys = ClosedLoop::new(Elastic::from_scenario(&s), &s).unwrap();
    let (mut y0, eq) = sys.initial_state().unwrap();
    let (dx, dz) = (1e-3, -5e-4);
    y0[0] += dx;
    y0[1] += dz;
    let z0 = sys.hold_height().unwrap();
    let opts = RunOptions::dopri5(
        0.5,
        1e-3,
        Dopri5Options {
            rtol: 1e-10,
            atol: 1e-14,
            ..Dopri5Options::default()
        },
    );
    let run = simulate_from(&mut sys, y0, eq, &opts, &mut |_| {}).unwrap();
    let col = |c| run.series.column(c).unwrap();
    let (t, x, z) = (col(Channel::Time), col(Channel::X), col(Channel::Z));
    let closed_form = |delta: f64, t: f64| {
        let wt = omega * t;
        -delta * (-wt).exp() * (1.0 + wt - wt * wt)
    };
    let mut worst: f64 = 0.0;
    for i in 0..t.len() {
        let (ex, ez) = (s.trajectory.x1 - x[i], z0 - z[i]);
        worst = worst
            .max((ex - closed_form(dx, t[i])).abs())
            .max((ez - closed_form(dz, t[i])).abs());
    }
    assert!(
        worst <= 1e-8,
        "largest deviation from the closed form {worst:e} m"
    );
}

/// On the paper's move the feedforward of the reference's acceleration leaves nothing for the
/// feedback to do on the elastic model: the path error stays at integrator round-off whatever
/// the gains and filter (here the defaults, and computed-torque without its integral), where the
/// paper PID errs by 5.8 mm. The LQR's gains in the run's record are the design's at the
/// reported design point (x2, the held height).
#[test]
fn computed_torque_and_lqr_track_the_move_exactly_on_the_elastic_model() {
    for (kind, extra) in [
        ("computed-torque", ""),
        ("computed-torque", "ki = 0\n"),
        ("lqr", ""),
    ] {
        let s = scenario(&format!(
            "[controller]\nkind = \"{kind}\"\n{extra}t_min = 10\nt_max = 400\n[simulation]\n\
             t_final = 1.2\nsample_period = 1e-4\n"
        ));
        let assessed = assess(&s, &mut |_| {}).unwrap();
        if kind == "lqr" {
            let gains = &assessed.run.controller_gains;
            let point = &gains
                .iter()
                .find(|(k, _)| *k == "lqr_design_point")
                .unwrap()
                .1;
            assert_eq!(point[0], s.trajectory.x2);
            let designed = Lqr::new(&s, s.robot()).designed_at(point[1]).unwrap();
            assert_eq!(*gains, designed.gains(), "the run reports its design");
            assert!(gains.iter().any(|(k, v)| *k == "lqr_gain" && v.len() == 12));
        }
        let m = assessed.metrics;
        // DOPRI5 at the paper's rtol 1e-5 on an error that is 0 in exact arithmetic: the 1e-9
        // atol level, far below the 10 µm goal.
        assert!(
            m.control.path_err_max_transition < 1e-8,
            "{kind}: {:e}",
            m.control.path_err_max_transition
        );
        // Without the integral its state is a free integrator of the error: eigenvalue 0 (the
        // finite-difference Jacobian puts it within 1e-9); every other mode decays.
        let bound = if extra.is_empty() { 0.0 } else { 1e-9 };
        assert!(
            m.control.least_stable_growth < bound,
            "{kind} {extra}: every mode decays ({:e} 1/s)",
            m.control.least_stable_growth
        );
        assert_eq!(m.control.controller, kind);
        assert_eq!(m.control.saturated_s, 0.0);
    }
}

/// Central difference of f at x with step h (error ~h² f''').
fn central(f: impl Fn(f64) -> Vec<f64>, h: f64) -> Vec<f64> {
    let (a, b) = (f(h), f(-h));
    a.iter().zip(&b).map(|(p, m)| (p - m) / (2.0 * h)).collect()
}

/// The LQR's design plant (the rigid-cable linearisation at (x2, z0): geometric stiffness G and
/// structure matrix W in closed form) equals the elastic model's right-hand side differentiated
/// numerically at that rest point; the gain solves the Riccati equation (residual at round-off of
/// ‖Q‖) and makes A − B K stable.
#[test]
fn lqr_design_matches_the_elastic_linearisation_and_the_riccati_equation() {
    let s = scenario("[controller]\nkind = \"lqr\"\n");
    let robot = s.robot();
    let model = Elastic::from_scenario(&s);
    for z0 in [-0.0247, -0.05, -0.1] {
        let lqr = Lqr::new(&s, robot).designed_at(z0).unwrap();
        let (a, b) = lqr.linearisation();
        let p = Vector2::new(s.trajectory.x2, z0);
        let hold = controller::tensions_for_acceleration(&robot, &p, &Vector2::zeros());
        let rate = |model: &mut Elastic<2>, y: [f64; 4], t: Tensions| {
            let mut r = vec![0.0; 4];
            model.rhs(0.0, &y, &t, &mut r);
            r
        };
        let y = [p.x, p.y, 0.0, 0.0];
        for j in 0..4 {
            let col = central(
                |h| {
                    let mut yy = y;
                    yy[j] += h;
                    rate(&mut model.clone(), yy, hold)
                },
                1e-6,
            );
            for i in 0..4 {
                let expected = a[i * 6 + j];
                assert!(
                    (col[i] - expected).abs() <= 1e-6 * (1.0 + expected.abs()),
                    "A[{i},{j}] at z0 = {z0}: {} vs {expected}",
                    col[i]
                );
            }
        }
        for j in 0..2 {
            let col = central(
                |h| {
                    let mut t = hold;
                    t[j] += h;
                    rate(&mut model.clone(), y, t)
                },
                1e-3,
            );
            for i in 0..4 {
                let expected = b[i * 2 + j];
                assert!(
                    (col[i] - expected).abs() <= 1e-9,
                    "B[{i},{j}]: {} vs {expected}",
                    col[i]
                );
            }
        }
        // The closed loop A − B K of the design.
        let k = &lqr.gain;
        let closed = Mat::from_fn(6, 6, |i, j| {
            a[i * 6 + j] - (0..2).map(|m| b[i * 2 + m] * k[m * 6 + j]).sum::<f64>()
        });
        let eig = closed.eigenvalues().unwrap();
        assert!(eig.iter().all(|l| l.re < 0.0), "A − BK stable: {eig:?}");
        // Residual relative to the largest weight (q_integral = 1e10).
        assert!(
            lqr.care_residual <= 1e-12 * 1e10,
            "residual {:e}",
            lqr.care_residual
        );
    }
}

/// `pid-xz` on the elastic model: W⁻¹ cancels the geometry, so z obeys M z̈ = C_z(s) e_z with
/// C_z(s) = P + I/s + D N s/(s + N): M s⁴ + M N s³ + (P + D N) s² + (P N + I) s + I N = 0.
/// Every root is a mode of the modal analysis of the nonlinear loop (finite-difference
/// Jacobian, 1e-6 relative), and the x loop's quartic likewise, for z gains unlike x's.
#[test]
fn pid_xz_z_loop_has_the_damping_its_gains_predict() {
    // A lightly damped z loop (ζ ≈ 0.1 at 30 rad/s), so the check is about damping, next to
    // the x loop's default gains, whose roots are all real.
    let (pz, iz, dz) = (900.0, 500.0, 6.0);
    let mut oscillatory = 0;
    let s = scenario(&format!(
        "[controller]\nkind = \"pid-xz\"\np_z = {pz}\ni_z = {iz}\nd_z = {dz}\n"
    ));
    let c = &s.controller;
    let m = s.robot.effector_mass;
    let analysis = analyse(&s, s.trajectory.x2, Loop::Closed).unwrap();
    for (p, i, d) in [(pz, iz, dz), (c.p, c.i, c.d)] {
        let n = c.filter;
        let coefficients = [m * n, p + d * n, p * n + i, i * n].map(|v| v / m);
        let companion = Mat::from_fn(4, 4, |r, col| {
            if r == 0 {
                -coefficients[col]
            } else if col + 1 == r {
                1.0
            } else {
                0.0
            }
        });
        for root in companion.eigenvalues().unwrap() {
            if root.im < 0.0 {
                continue;
            }
            if root.im > 0.0 {
                oscillatory += 1;
            }
            let nearest = analysis
                .modes
                .iter()
                .map(|mode| (mode.mode.growth - root.re).hypot(mode.mode.omega - root.im))
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest <= 1e-6 * root.norm(),
                "root {root:?} (ζ = {:.3}) is {nearest:e} from every analysed mode",
                -root.re / root.norm()
            );
        }
    }
    assert!(oscillatory > 0, "the z loop's pair is oscillatory");
}

/// A move the limits cannot follow: computed-torque asks for more than t_max while the effector
/// accelerates. The commanded tensions stay inside [t_min, t_max] (the limit is hit exactly),
/// the saturated time is reported, and anti-windup keeps the integral from winding up: after
/// the move the effector still settles inside 10 µm.
#[test]
fn saturation_holds_the_limits_and_anti_windup_lets_the_loop_settle() {
    let s = scenario(
        "[controller]\nkind = \"computed-torque\"\nt_min = 90\nt_max = 105\n\
         [simulation]\nt_final = 2.0\nsample_period = 1e-4\n",
    );
    let a = assess(&s, &mut |_| {}).unwrap();
    let c = &a.metrics.control;
    assert!(
        c.saturated_s > 0.01,
        "the move saturates: {} s",
        c.saturated_s
    );
    assert!(
        c.tension_min >= 90.0 && c.tension_max <= 105.0,
        "{} – {}",
        c.tension_min,
        c.tension_max
    );
    assert!(
        c.tension_max == 105.0 || c.tension_min == 90.0,
        "a limit is reached exactly"
    );
    assert!(
        c.x_settle_s.is_finite() && c.x_settle_s < 2.0,
        "settles: {}",
        c.x_settle_s
    );
    // While saturated the integrals' rates are zero and the implicit step holds them.
    let limits = TensionLimits::from(&s.controller);
    assert_eq!(
        limits.clamp(&Tensions::pair([80.0, 100.0])),
        (Tensions::pair([90.0, 100.0]), true)
    );
    for kind in [
        ControllerKind::PidXz,
        ControllerKind::ComputedTorque,
        ControllerKind::Lqr,
    ] {
        let mut sc = s.clone();
        sc.controller.kind = kind;
        let mut ctl = controller::build(&sc, sc.robot());
        ctl.hold_height(-0.025).unwrap();
        let states = vec![0.3; ctl.state_len()];
        let reference = Reference {
            position: Vector2::new(0.6, -0.025),
            ..Reference::default()
        };
        let effector = Effector {
            position: Vector2::new(0.59, -0.02),
            velocity: Vector2::new(0.1, 0.0),
        };
        let mut rate = vec![1.0; ctl.state_len()];
        ctl.state_rate(&reference, &effector, &states, true, &mut rate);
        let integrals: &[usize] = if kind == ControllerKind::PidXz {
            &[0, 2]
        } else {
            &[0, 1]
        };
        for &k in integrals {
            assert_eq!(rate[k], 0.0, "{kind:?}: integral {k} holds");
        }
        let start = StepStart {
            reference,
            effector,
            states: &states,
            saturated: true,
        };
        let mut out = vec![0.0; ctl.state_len()];
        ctl.trapezoidal_step(1e-3, &start, &reference, &effector, &mut out);
        for &k in integrals {
            assert_eq!(
                out[k], states[k],
                "{kind:?}: integral {k} held over the implicit step"
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The filter's implicit step satisfies its definition, the trapezoidal rule
    /// s₁ − s₀ = h/2 (f(s₀, u₀) + f(s₁, u₁)), to round-off, for any corner, step and inputs.
    #[test]
    fn velocity_filter_step_is_the_trapezoidal_rule(
        omega in 10.0f64..1e4,
        h in 1e-6f64..1e-2,
        s0 in proptest::array::uniform4(-1.0f64..1.0),
        u0 in proptest::array::uniform2(-1.0f64..1.0),
        u1 in proptest::array::uniform2(-1.0f64..1.0),
    ) {
        let filter = VelocityFilter { omega };
        let mut s1 = [0.0; 4];
        filter.trapezoidal_step(&s0, &u0, &u1, h, &mut s1);
        let (mut f0, mut f1) = ([0.0; 4], [0.0; 4]);
        filter.rate(&s0, &u0, &mut f0);
        filter.rate(&s1, &u1, &mut f1);
        let scale = 1.0 + omega * omega * h;
        for k in 0..4 {
            let defect = s1[k] - s0[k] - 0.5 * h * (f0[k] + f1[k]);
            prop_assert!(defect.abs() <= 1e-13 * scale * (1.0 + omega), "{k}: {defect:e}");
        }
    }
}

/// The closed loop's implicit iteration matrix with each controller, against central
/// differences of the closed-loop residual (model and controller's trapezoidal step together):
/// the tension rows' columns of the effector's x and z (z only for controllers that measure it),
/// weighted by c_q for positions and c_v for the velocities the controller feeds back, are what
/// the differences find. Steps and the model part's tolerance as in `implicit.rs`
/// (`check_iteration_matrix`); the effector columns of the tension rows are ~1e-4 of the
/// matrix's largest entry, so they are checked on their own to 1e-3 of themselves (the
/// controllers' one-sided 1e-6 m probes of a W⁻¹ curved on the 0.1 m scale err by ~1e-5).
#[test]
fn closed_loop_iteration_matrices_match_differences_for_every_controller() {
    use cdpr_bench::core::closed_loop::ClosedLoop;
    use cdpr_bench::numerics::{AlphaCoefficients, SecondOrderSystem};
    let (c_v, c_q) = AlphaCoefficients::new(0.9).derivatives(1e-4);
    for model in ["lumped", "fe"] {
        for kind in ["pid", "pid-xz", "computed-torque", "lqr"] {
            let s = scenario(&format!(
                "[model]\nkind = \"{model}\"\n[controller]\nkind = \"{kind}\"\n\
                 [simulation]\nintegrator = \"implicit\"\n"
            ));
            let mut sys = ClosedLoop::new(cdpr_bench::build(&s).unwrap(), &s).unwrap();
            let (mut y, _) = sys.initial_state().unwrap();
            let n = sys.dofs();
            for i in 0..n {
                y[n + i] = 0.02 * ((i as f64) * 1.3).sin();
            }
            let qdd: Vec<f64> = (0..n).map(|i| 3.0 * ((i as f64) * 0.7).cos()).collect();
            let t = 0.1;
            sys.begin_step(t - 1e-4, &y, 1e-4);
            let pattern = sys.iteration_pattern();
            let mut values = vec![0.0; pattern.len()];
            sys.iteration_matrix(t, &y, &qdd, c_v, c_q, &mut values);
            let mut ours = vec![0.0; n * n];
            for (&(r, c), v) in pattern.iter().zip(&values) {
                ours[r * n + c] += v;
            }
            let mut fd = vec![0.0; n * n];
            let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
            for col in 0..n {
                for (slot, weight) in [(col, c_q), (n + col, c_v)] {
                    let step = 1e-7 * y[slot].abs().max(1e-2);
                    let mut yy = y.clone();
                    yy[slot] += step;
                    sys.residual(t, &yy, &qdd, &mut plus);
                    yy[slot] -= 2.0 * step;
                    sys.residual(t, &yy, &qdd, &mut minus);
                    for row in 0..n {
                        fd[row * n + col] += weight * (plus[row] - minus[row]) / (2.0 * step);
                    }
                }
                let step = 1e-7 * qdd[col].abs().max(1e-2);
                let mut a = qdd.clone();
                a[col] += step;
                sys.residual(t, &y, &a, &mut plus);
                a[col] -= 2.0 * step;
                sys.residual(t, &y, &a, &mut minus);
                for row in 0..n {
                    fd[row * n + col] += (plus[row] - minus[row]) / (2.0 * step);
                }
            }
            let scale = fd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let form = sys.model.second_order().unwrap();
            let rows = form.tension_rows();
            let effector = [form.effector_coordinate(0), form.effector_coordinate(1)];
            let mut checked = 0;
            for row in 0..n {
                for col in 0..n {
                    let (o, f) = (ours[row * n + col], fd[row * n + col]);
                    let feedback = rows.contains(&row) && effector.contains(&col);
                    let tolerance = if feedback {
                        1e-3 * f.abs() + 1e-12
                    } else {
                        1e-6 * scale
                    };
                    assert!(
                        (o - f).abs() <= tolerance,
                        "{kind} on {model}: S[{row}][{col}] = {o:e}, differences {f:e}"
                    );
                    if feedback && f.abs() > 1e-12 {
                        checked += 1;
                    }
                }
            }
            // pid feeds back x only; the others x and z.
            let expected = if kind == "pid" { 1 } else { 2 } * rows.len();
            assert!(
                checked >= expected,
                "{kind} on {model}: {checked} feedback entries"
            );
        }
    }
}

/// Each controller's rest states are a rest: started at the static equilibrium of an
/// off-centre position (x1 = x2 = 0.62 m, where the tensions differ and every state that holds
/// a force is non-zero) with the reference at rest there, the elastic run stays put for 0.5 s
/// within 1e-9 m (DOPRI5's atol level; a wrong rest state moves the effector by ~mm). Only the
/// LQR designs gains the run reports; the fixed-gain controllers report none.
#[test]
fn every_controller_holds_its_rest_state_off_centre() {
    for kind in ["pid", "pid-xz", "computed-torque", "lqr"] {
        let s = scenario(&format!(
            "[controller]\nkind = \"{kind}\"\n[trajectory]\nx1 = 0.62\nx2 = 0.62\n\
             [simulation]\nt_final = 0.5\nsample_period = 1e-3\n"
        ));
        let run = assess(&s, &mut |_| {}).unwrap().run;
        for channel in [Channel::X, Channel::Z] {
            let v = run.series.column(channel).unwrap();
            let drift = v.iter().map(|q| (q - v[0]).abs()).fold(0.0, f64::max);
            assert!(
                drift < 1e-9,
                "{kind}: {channel:?} drifts {drift:e} m from rest"
            );
        }
        assert_eq!(run.controller_gains.is_empty(), kind != "lqr", "{kind}");
    }
}
