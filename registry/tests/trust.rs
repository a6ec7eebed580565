//! Numbers that look valid and are not: metrics of a move that never finished, windows of a
//! shaped move, peaks of a signal without one, times beyond the run, loops that diverge; and the
//! runs that cannot start, refused before any work with the keys that stop them.

use cdpr_bench::{Assessed, Error, assess, prepare, scenario_from_toml_str};
use serde_json::Value;

fn assessed(toml: &str) -> Assessed {
    let scenario = scenario_from_toml_str(toml).unwrap();
    assess(&prepare(&scenario).unwrap(), &mut |_| {}).unwrap()
}

fn json(a: &Assessed) -> Value {
    serde_json::to_value(&a.metrics).unwrap()
}

/// Asserts `key` is null with a reason containing `why`.
#[track_caller]
fn null_because(a: &Assessed, key: &str, why: &str) {
    let m = json(a);
    assert!(m[key].is_null(), "{key} = {}", m[key]);
    let reason = m["unavailable"][key]
        .as_str()
        .unwrap_or_else(|| panic!("no reason for {key}"));
    assert!(reason.contains(why), "{key}: {reason}");
}

/// A run that ends before its move does reported overshoot −0.1, settle times 0.0 and a
/// transition maximum as if the move had been made: every metric of the move is null with its
/// reason, and no window is printed inverted.
#[test]
fn a_move_that_never_finished_has_no_move_metrics() {
    for toml in [
        "[trajectory]\nt2 = 6.0\n[simulation]\nt_final = 5.0\nsample_period = 1e-3\n",
        // A shaper designed for 1e-6 rad/s ends the shaped move at 3.1e6 s.
        "[trajectory]\nshaper = \"zv\"\nshaper_frequency = 1e-6\nshaper_damping = 0.0\n\
         [simulation]\nt_final = 3.0\nsample_period = 1e-3\n",
    ] {
        let a = assessed(toml);
        let move_end = a.metrics.control.move_end_s;
        assert!(move_end > 5.0, "{move_end}");
        for key in [
            "overshoot",
            "err_max_transition",
            "x_settle_s",
            "z_settle_s",
            "ex_max_transition",
            "ez_max_transition",
            "path_err_max_transition",
        ] {
            null_because(&a, key, "before the");
        }
        for key in [
            "err_max_settled",
            "z_p2p",
            "z_peak_rad_s",
            "t1_mean_last_1s",
        ] {
            assert!(json(&a)[key].is_null(), "{key}");
        }
        let w = &json(&a)["windows"];
        assert!(
            w["settled"].is_null() && w["settled_strict"].is_null(),
            "{w}"
        );
        assert_eq!(w["transition"][1], move_end);
    }
}

/// With a shaper the windows followed t2: 3-hump EI's "transition" covered 0.2 s of a 0.82 s
/// move and "settled" began inside the move. They now follow the shaped reference's end.
#[test]
fn the_windows_of_a_shaped_move_follow_its_end() {
    let a = assessed(
        "[trajectory]\nshaper = \"3hump-ei\"\nshaper_frequency = 20.37\nshaper_damping = 0.0\n\
         [simulation]\nt_final = 5.0\nsample_period = 1e-3\n",
    );
    let move_end = a.metrics.control.move_end_s;
    assert!(
        (move_end - 0.2 - 2.0 * 2.0 * std::f64::consts::PI / 20.37).abs() < 1e-9,
        "{move_end}"
    );
    let w = a.metrics.windows;
    assert_eq!(w.transition, [0.0, move_end]);
    assert_eq!(w.settled, Some([move_end + 0.8, 5.0]));
    assert_eq!(w.settled_strict, Some([move_end + 1.3, 5.0]));
    // The transition maximum is the error's over the whole shaped move.
    let s = &a.run.series;
    let (t, e) = (
        s.channel(cdpr_bench::core::channel::Channel::Time).unwrap(),
        s.channel(cdpr_bench::core::channel::Channel::Error)
            .unwrap(),
    );
    let expected = t
        .iter()
        .zip(e)
        .filter(|&(&t, _)| t <= move_end + 5e-4)
        .fold(0.0f64, |m, (_, e)| m.max(e.abs()));
    assert_eq!(a.metrics.err_max_transition, expected);
}

/// z held flat by computed-torque (7e-12 m peak to peak on the elastic model) reported a "peak"
/// at 0.96 rad/s; a signal without a peak has none, and says why. `saturated_s` counted one
/// sample period too many (5.0001 s of a 5 s run): a run at a limit throughout counts its
/// length.
#[test]
fn no_peak_on_a_flat_signal_and_no_time_beyond_the_run() {
    let a = assessed(
        "[controller]\nkind = \"computed-torque\"\n[simulation]\nt_final = 3.0\nsample_period = 1e-3\n",
    );
    assert!(a.metrics.z_p2p < 1e-9, "{}", a.metrics.z_p2p);
    null_because(&a, "z_peak_rad_s", "no refined spectral peak");
    null_because(&a, "z_plain_peak_rad_s", "no plain spectral peak");
    // The paper PID's z rings at the vertical mode: its peak is there.
    let pid = assessed("[simulation]\nt_final = 3.0\nsample_period = 1e-3\n");
    assert!(
        (pid.metrics.spectral.z_peak_rad_s - 20.37).abs() < 0.05,
        "{}",
        pid.metrics.spectral.z_peak_rad_s
    );
    // A limit the tensions sit at from the start: ΣT = 200 N rests at 100 N in each cable, and
    // t_max = 100 N (the least allowed) holds whichever is pulled harder.
    let saturated = assessed(
        "[controller]\nt_min = 10.0\nt_max = 100.0\n[simulation]\nt_final = 2.0\nsample_period = 1e-3\n",
    );
    let s = saturated.metrics.control.saturated_s;
    assert!(s <= 2.0, "{s}");
    assert!(s > 1.9, "saturated throughout: {s}");
}

/// A gain that destabilises the loop (the paper PID with p = 0; pid-xz with d_z = 0) ran to
/// "complete" with no word, and on the elastic model z stayed at its rest to 1e-16, so every
/// time-domain number looked perfect: the growing mode is now a warning.
#[test]
fn a_loop_with_a_growing_mode_is_reported() {
    for toml in [
        "[controller]\np = 0.0\n[simulation]\nt_final = 1.5\nsample_period = 1e-3\n",
        "[controller]\nkind = \"pid-xz\"\nd_z = 0.0\n[simulation]\nt_final = 1.5\nsample_period = 1e-3\n",
    ] {
        let a = assessed(toml);
        assert!(!a.warnings.is_empty(), "{toml}");
        assert!(a.warnings[0].contains("growing"), "{:?}", a.warnings);
    }
    let paper = assessed("[simulation]\nt_final = 1.5\nsample_period = 1e-3\n");
    assert!(paper.warnings.is_empty(), "{:?}", paper.warnings);
}

/// What can be known before a run is refused before it, naming the keys: no gravity, the
/// implicit path for the elastic model, an LQR without integral weight, an "auto" shaper for a
/// loop with no vertical mode to shape, a start the statics cannot find.
#[test]
fn runs_that_cannot_start_are_refused_with_their_keys() {
    for (toml, needles) in [
        ("[robot]\ngravity = 0.0\n", &["robot.gravity", "> 0"][..]),
        (
            "[simulation]\nintegrator = \"implicit\"\n",
            &["simulation.integrator", "elastic"][..],
        ),
        (
            "[controller]\nkind = \"lqr\"\nq_integral = 0.0\n",
            &["controller.q_integral", "> 0"][..],
        ),
        (
            "[controller]\nkind = \"pid-xz\"\n[trajectory]\nshaper = \"zv\"\n",
            &[
                "trajectory.shaper_frequency = \"auto\"",
                "pid-xz",
                "no lightly damped",
            ][..],
        ),
        (
            "[controller]\ntension_sum = 1e15\n",
            &[
                "controller.tension_sum = 1000000000000000",
                "cannot start",
                "equilibrium",
            ][..],
        ),
    ] {
        let e = scenario_from_toml_str(toml)
            .map_err(Error::from)
            .and_then(|s| prepare(&s))
            .unwrap_err();
        assert!(matches!(e, Error::Scenario(_)), "{toml}: {e:?}");
        let message = e.to_string();
        for n in needles {
            assert!(message.contains(n), "{n:?} not in: {message}");
        }
    }
}
