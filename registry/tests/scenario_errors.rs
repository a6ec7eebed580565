//! Bad scenario files (MODELS.md §9): every numeric key refuses out-of-range values with a typed
//! error naming the key, its value and the allowed range; unknown keys, malformed TOML and wrong
//! types are syntax errors naming the culprit; nothing panics.

use cdpr_bench::ModelConfig;
use cdpr_bench::core::scenario::{Scenario, ScenarioError};
use cdpr_bench::{scenario_from_file, scenario_from_toml_str};
use proptest::prelude::*;
use proptest::test_runner::{TestCaseError, TestRunner};
use std::cell::Cell;

/// Parses `toml` and expects `OutOfRange` for `key`, with the value reported as `value`.
#[track_caller]
fn expect_out_of_range(toml: &str, key: &str, value: f64) {
    match scenario_from_toml_str(toml) {
        Err(e @ ScenarioError::OutOfRange { .. }) => {
            let msg = e.to_string();
            let ScenarioError::OutOfRange {
                key: k,
                value: v,
                allowed,
            } = e
            else {
                unreachable!()
            };
            assert_eq!(k, key, "wrong key for\n{toml}\nmessage: {msg}");
            assert!(msg.contains(key), "message does not name {key}: {msg}");
            assert!(msg.contains("allowed"), "message gives no range: {msg}");
            assert!(!allowed.is_empty(), "empty allowed range: {msg}");
            let reported: f64 = v
                .parse()
                .unwrap_or_else(|_| panic!("value `{v}` is not a number: {msg}"));
            assert!(
                reported == value || (reported.is_nan() && value.is_nan()),
                "reported value {v}, file value {value}: {msg}"
            );
            assert!(msg.contains(&v), "message does not show the value: {msg}");
        }
        other => panic!("expected OutOfRange for {key} from\n{toml}\ngot {other:?}"),
    }
}

/// `[section]\nname = literal` for a dotted key, after an optional prefix of other sections.
fn file(prefix: &str, key: &str, literal: &str) -> String {
    let (section, name) = key.split_once('.').unwrap();
    format!("{prefix}\n[{section}]\n{name} = {literal}\n")
}

/// (key, TOML literal, value it denotes) — at least one bad value per numeric key of §9, covering
/// negative, zero where positive is required, nan, ±inf and upper bounds.
const BAD: &[(&str, &str, f64)] = &[
    ("robot.anchor_distance", "-1.0", -1.0),
    ("robot.anchor_distance", "0.0", 0.0),
    ("robot.anchor_distance", "inf", f64::INFINITY),
    ("robot.effector_mass", "0.0", 0.0),
    ("robot.effector_mass", "nan", f64::NAN),
    ("robot.gravity", "-9.81", -9.81),
    ("robot.gravity", "inf", f64::INFINITY),
    ("cable.youngs_modulus", "0.0", 0.0),
    ("cable.youngs_modulus", "-inf", f64::NEG_INFINITY),
    ("cable.area", "-1.76e-6", -1.76e-6),
    ("cable.density", "nan", f64::NAN),
    ("cable.density", "0.0", 0.0),
    ("cable.modelled_length", "-1.0", -1.0),
    ("cable.axial_damping", "-0.5", -0.5),
    ("cable.axial_damping", "nan", f64::NAN),
    ("controller.p", "-1.0", -1.0),
    ("controller.p", "nan", f64::NAN),
    ("controller.i", "-8700.0", -8700.0),
    ("controller.i", "inf", f64::INFINITY),
    ("controller.d", "-100.0", -100.0),
    ("controller.d", "nan", f64::NAN),
    ("controller.filter", "0.0", 0.0),
    ("controller.filter", "-540.0", -540.0),
    ("controller.tension_sum", "0.0", 0.0),
    ("controller.tension_sum", "nan", f64::NAN),
    // Cannot hold a 1 kg effector against 9.81 N of weight.
    ("controller.tension_sum", "9.0", 9.0),
    ("controller.t_min", "-1.0", -1.0),
    ("controller.t_min", "nan", f64::NAN),
    // Not below the default tension_sum = 200 N.
    ("controller.t_min", "200.0", 200.0),
    ("controller.t_max", "0.0", 0.0),
    ("controller.t_max", "inf", f64::INFINITY),
    ("trajectory.x1", "0.0", 0.0),
    ("trajectory.x1", "nan", f64::NAN),
    ("trajectory.x1", "-0.5", -0.5),
    // Outside the workspace between the pulleys (d = 1).
    ("trajectory.x2", "1.2", 1.2),
    ("trajectory.x2", "1.0", 1.0),
    ("trajectory.x2", "inf", f64::INFINITY),
    ("trajectory.t1", "-0.1", -0.1),
    ("trajectory.t1", "nan", f64::NAN),
    // Not after the default t1 = 0.
    ("trajectory.t2", "0.0", 0.0),
    ("trajectory.t2", "-1.0", -1.0),
    ("trajectory.t2", "inf", f64::INFINITY),
    ("simulation.t_final", "0.0", 0.0),
    ("simulation.t_final", "nan", f64::NAN),
    ("simulation.rtol", "0.0", 0.0),
    ("simulation.rtol", "0.5", 0.5),
    ("simulation.rtol", "1e-15", 1e-15),
    ("simulation.rtol", "nan", f64::NAN),
    ("simulation.atol", "0.0", 0.0),
    ("simulation.atol", "-1e-9", -1e-9),
    ("simulation.sample_period", "0.0", 0.0),
    // Longer than the default t_final = 5 s.
    ("simulation.sample_period", "10.0", 10.0),
    // 5e9 samples: beyond the memory guard.
    ("simulation.sample_period", "1e-9", 1e-9),
    ("simulation.dopri_beta", "-0.01", -0.01),
    ("simulation.dopri_beta", "0.3", 0.3),
    ("simulation.dopri_beta", "nan", f64::NAN),
    ("simulation.step", "0.0", 0.0),
    ("simulation.step", "-1e-4", -1e-4),
    ("simulation.rho_inf", "1.5", 1.5),
    ("simulation.rho_inf", "-0.1", -0.1),
    ("simulation.rho_inf", "nan", f64::NAN),
];

const NUMERIC_KEYS: &[&str] = &[
    "robot.anchor_distance",
    "robot.effector_mass",
    "robot.gravity",
    "cable.youngs_modulus",
    "cable.area",
    "cable.density",
    "cable.modelled_length",
    "cable.axial_damping",
    "model.elements",
    "controller.p",
    "controller.i",
    "controller.d",
    "controller.filter",
    "controller.tension_sum",
    "controller.t_min",
    "controller.t_max",
    "trajectory.x1",
    "trajectory.x2",
    "trajectory.t1",
    "trajectory.t2",
    "simulation.t_final",
    "simulation.rtol",
    "simulation.atol",
    "simulation.sample_period",
    "simulation.dopri_beta",
    "simulation.step",
    "simulation.rho_inf",
];

#[test]
fn every_numeric_key_rejects_out_of_range_values() {
    for &(key, literal, value) in BAD {
        expect_out_of_range(&file("", key, literal), key, value);
    }
}

#[test]
fn every_numeric_key_is_covered() {
    // model.elements and the lumped-model modelled_length are covered by their own tests below.
    for key in NUMERIC_KEYS {
        let covered = BAD.iter().any(|(k, _, _)| k == key)
            || ["model.elements", "cable.modelled_length"].contains(key);
        assert!(covered, "no out-of-range case for {key}");
    }
    // And each key of the list exists: a valid value for it is accepted.
    for key in NUMERIC_KEYS {
        let literal = match *key {
            "model.elements" => "12",
            "controller.t_min" => "10.0",
            "controller.t_max" => "150.0",
            "trajectory.x1" | "trajectory.x2" => "0.55",
            "trajectory.t1" => "0.1",
            "trajectory.t2" => "0.3",
            "simulation.t_final" => "2.0",
            "simulation.rtol" => "1e-6",
            "simulation.dopri_beta" | "simulation.rho_inf" => "0.1",
            "simulation.sample_period" => "1e-4",
            "simulation.step" => "1e-5",
            "cable.modelled_length" => "1.5",
            "robot.anchor_distance" => "1.1",
            "robot.effector_mass" => "2.0",
            "robot.gravity" => "9.0",
            "controller.tension_sum" => "250.0",
            _ => "3.0",
        };
        let text = file("", key, literal);
        let s = scenario_from_toml_str(&text)
            .unwrap_or_else(|e| panic!("valid value refused for {key}: {e}"));
        assert_ne!(s, Scenario::paper(), "{key} was not read");
    }
}

#[test]
fn elements_out_of_range() {
    for (n, kind) in [
        (0i64, "lumped"),
        (-3, "fe"),
        (100_001, "lumped"),
        (0, "elastic"),
    ] {
        let text = format!("[model]\nkind = \"{kind}\"\nelements = {n}\n");
        expect_out_of_range(&text, "model.elements", n as f64);
    }
    // A float where an integer is expected is a type error, not a silent truncation.
    assert!(matches!(
        scenario_from_toml_str("[model]\nelements = 10.5"),
        Err(ScenarioError::Syntax(_))
    ));
}

#[test]
fn lumped_modelled_length_must_cover_the_trajectory() {
    // The paper's 1.0 m suffices; 0.5 m cannot reach x2 = 0.6 m from A1.
    scenario_from_toml_str("[model]\nkind = \"lumped\"\n[cable]\nmodelled_length = 1.0").unwrap();
    expect_out_of_range(
        "[model]\nkind = \"lumped\"\n[cable]\nmodelled_length = 0.5",
        "cable.modelled_length",
        0.5,
    );
    expect_out_of_range(
        "[model]\nkind = \"fe\"\n[cable]\nmodelled_length = 0.6",
        "cable.modelled_length",
        0.6,
    );
    // The elastic model stores no cable: the length is not constrained beyond > 0.
    scenario_from_toml_str("[cable]\nmodelled_length = 0.5").unwrap();
}

#[test]
fn trajectory_outside_the_workspace_names_x2() {
    expect_out_of_range("[trajectory]\nx2 = 1.2", "trajectory.x2", 1.2);
    // The workspace follows anchor_distance: 1.2 is fine between pulleys 2 m apart...
    scenario_from_toml_str("[robot]\nanchor_distance = 2.0\n[trajectory]\nx2 = 1.2").unwrap();
    // ...and x1 is checked against it too.
    expect_out_of_range(
        "[robot]\nanchor_distance = 0.4\n[trajectory]\nx2 = 0.3",
        "trajectory.x1",
        0.5,
    );
}

#[track_caller]
fn expect_syntax(toml: &str, must_contain: &[&str]) {
    match scenario_from_toml_str(toml) {
        Err(e @ ScenarioError::Syntax(_)) => {
            let msg = e.to_string();
            for word in must_contain {
                assert!(msg.contains(word), "message does not name `{word}`: {msg}");
            }
        }
        other => panic!("expected Syntax from\n{toml}\ngot {other:?}"),
    }
}

#[test]
fn syntax_errors_name_the_culprit() {
    expect_syntax("[robot]\nwheels = 4", &["wheels"]);
    expect_syntax("[simulation]\nrtol = 1e-5\nmax_steps = 10", &["max_steps"]);
    expect_syntax("[gearbox]\nratio = 3.0", &["gearbox"]);
    expect_syntax("top_level = 1", &["top_level"]);
    expect_syntax("[robot\nx=", &[]);
    expect_syntax("[robot]\nanchor_distance = ", &[]);
    expect_syntax("[robot]\nanchor_distance = \"one\"", &["anchor_distance"]);
    expect_syntax("[controller]\np = true", &["p = true"]);
    expect_syntax("[model]\nkind = \"spring\"", &["spring"]);
    expect_syntax("[model]\nfe_mass = \"heavy\"", &["heavy"]);
    expect_syntax("[trajectory]\nkind = \"step3\"", &["step3"]);
    expect_syntax("[simulation]\nintegrator = \"euler\"", &["euler"]);
    expect_syntax(
        "[robot]\nanchor_distance = 1.0\nanchor_distance = 2.0",
        &["anchor_distance"],
    );
}

#[test]
fn missing_file_is_an_io_error() {
    let path = std::env::temp_dir().join("cdpr-bench-no-such-dir/missing-scenario.toml");
    match scenario_from_file(&path) {
        Err(e @ ScenarioError::Io { .. }) => {
            assert!(e.to_string().contains("missing-scenario.toml"), "{e}");
        }
        other => panic!("expected Io, got {other:?}"),
    }
}

#[test]
fn file_round_trip() {
    let dir = std::env::temp_dir().join(format!("cdpr-core-scenario-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("good.toml");
    std::fs::write(&good, "[trajectory]\nx2 = 0.7\n").unwrap();
    assert_eq!(scenario_from_file(&good).unwrap().trajectory.x2, 0.7);
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[trajectory]\nx2 = 0.0\n").unwrap();
    let err = scenario_from_file(&bad);
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        matches!(
            err,
            Err(ScenarioError::OutOfRange {
                key: "trajectory.x2",
                ..
            })
        ),
        "{err:?}"
    );
}

// ---------------------------------------------------------------------------------------------
// Random files never panic, and whatever validates satisfies the documented ranges
// ---------------------------------------------------------------------------------------------

/// Finite values from every scale and sign, with the interesting points 0 and ±1 weighted in.
fn any_finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -2.0f64..2.0,
        2 => -1e4f64..1e4,
        2 => prop::num::f64::NORMAL | prop::num::f64::SUBNORMAL | prop::num::f64::ZERO,
        1 => Just(0.0),
        1 => Just(1.0),
    ]
}

/// A TOML float literal that parses back to exactly `v` (Rust's shortest round-trip form, with a
/// fraction added where TOML needs one).
fn literal(v: f64) -> String {
    let s = format!("{v:?}");
    if s.contains(['.', 'e', 'E']) {
        s
    } else {
        format!("{s}.0")
    }
}

/// Every float key of §9 with a typical valid value (the paper's, t_min/t_max chosen inside).
const FLOAT_KEYS: [(&str, &str, f64); 26] = [
    ("robot", "anchor_distance", 1.0),
    ("robot", "effector_mass", 1.0),
    ("robot", "gravity", 9.81),
    ("cable", "youngs_modulus", 102e9),
    ("cable", "area", 1.76e-6),
    ("cable", "density", 7850.0),
    ("cable", "modelled_length", 1.0),
    ("cable", "axial_damping", 0.1),
    ("controller", "p", 1860.0),
    ("controller", "i", 8700.0),
    ("controller", "d", 100.0),
    ("controller", "filter", 540.0),
    ("controller", "tension_sum", 200.0),
    ("controller", "t_min", 20.0),
    ("controller", "t_max", 180.0),
    ("trajectory", "x1", 0.5),
    ("trajectory", "x2", 0.6),
    ("trajectory", "t1", 0.1),
    ("trajectory", "t2", 0.3),
    ("simulation", "t_final", 5.0),
    ("simulation", "rtol", 1e-5),
    ("simulation", "atol", 1e-9),
    ("simulation", "sample_period", 1e-5),
    ("simulation", "dopri_beta", 0.04),
    ("simulation", "step", 1e-4),
    ("simulation", "rho_inf", 0.8),
];

/// A key absent, near its typical value, or any finite number: mixes valid and invalid files.
fn key_value(typical: f64) -> BoxedStrategy<Option<f64>> {
    prop_oneof![
        2 => Just(None),
        5 => (0.8f64..1.2).prop_map(move |f| Some(typical * f)),
        1 => any_finite().prop_map(Some),
    ]
    .boxed()
}

fn any_scenario_text() -> impl Strategy<Value = String> {
    let values: Vec<_> = FLOAT_KEYS.iter().map(|k| key_value(k.2)).collect();
    let elements = prop_oneof![
        2 => Just(None),
        3 => (5i64..60).prop_map(Some),
        1 => any::<i64>().prop_map(Some),
    ];
    let kind = prop_oneof![Just("elastic"), Just("lumped"), Just("fe")];
    (values, elements, kind).prop_map(|(values, elements, kind)| {
        let mut text = String::new();
        for section in ["robot", "cable", "controller", "trajectory", "simulation"] {
            text += &format!("[{section}]\n");
            for ((sec, name, _), v) in FLOAT_KEYS.iter().zip(&values) {
                if let (true, Some(v)) = (*sec == section, v) {
                    text += &format!("{name} = {}\n", literal(*v));
                }
            }
        }
        text += &format!("[model]\nkind = \"{kind}\"\n");
        if let Some(n) = elements {
            text += &format!("elements = {n}\n");
        }
        text
    })
}

/// Checks one file: it validates into §9's ranges or is refused with a range error naming a key.
/// Returns whether it validated.
fn check_file(text: &str) -> Result<bool, TestCaseError> {
    match scenario_from_toml_str(text) {
        Ok(s) => {
            let (r, c, k, t, m) = (
                &s.robot,
                &s.cable,
                &s.controller,
                &s.trajectory,
                &s.simulation,
            );
            prop_assert!(r.anchor_distance > 0.0 && r.effector_mass > 0.0 && r.gravity >= 0.0);
            prop_assert!(c.youngs_modulus > 0.0 && c.area > 0.0 && c.density > 0.0);
            prop_assert!(c.modelled_length > 0.0 && c.axial_damping >= 0.0);
            prop_assert!(k.p >= 0.0 && k.i >= 0.0 && k.d >= 0.0 && k.filter > 0.0);
            prop_assert!(k.tension_sum > r.effector_mass * r.gravity);
            if let Some(t_min) = k.t_min {
                prop_assert!(0.0 <= t_min && t_min < k.tension_sum);
            }
            if let Some(t_max) = k.t_max {
                prop_assert!(t_max > k.t_min.unwrap_or(0.0) && t_max.is_finite());
            }
            prop_assert!(0.0 < t.x1 && t.x1 < r.anchor_distance);
            prop_assert!(0.0 < t.x2 && t.x2 < r.anchor_distance);
            prop_assert!(t.t1 >= 0.0 && t.t2 > t.t1 && t.t2.is_finite());
            prop_assert!(m.t_final.is_finite() && m.t_final > 0.0);
            prop_assert!(m.sample_period > 0.0 && m.sample_period <= m.t_final);
            prop_assert!((1e-14..=0.1).contains(&m.rtol) && m.atol > 0.0 && m.step > 0.0);
            prop_assert!((0.0..=0.2).contains(&m.dopri_beta));
            prop_assert!((0.0..=1.0).contains(&m.rho_inf));
            if let Some(n) = ModelConfig::from_scenario(&s).unwrap().elements {
                prop_assert!((1..=100_000).contains(&n));
            }
            Ok(true)
        }
        Err(e @ ScenarioError::OutOfRange { .. }) => {
            let msg = e.to_string();
            let ScenarioError::OutOfRange { key, .. } = e else {
                unreachable!()
            };
            prop_assert!(NUMERIC_KEYS.contains(&key), "unknown key {key}");
            prop_assert!(msg.contains(key) && msg.contains("allowed"), "{msg}");
            Ok(false)
        }
        Err(e) => Err(TestCaseError::fail(format!(
            "finite values gave a non-range error {e}\n{text}"
        ))),
    }
}

#[test]
fn random_files_validate_or_fail_cleanly() {
    let mut runner = TestRunner::new(ProptestConfig {
        // Integration tests have no lib.rs next to them for proptest's regression files.
        failure_persistence: None,
        ..ProptestConfig::with_cases(3000)
    });
    let (accepted, refused) = (Cell::new(0u32), Cell::new(0u32));
    runner
        .run(&any_scenario_text(), |text| {
            let counter = if check_file(&text)? {
                &accepted
            } else {
                &refused
            };
            counter.set(counter.get() + 1);
            Ok(())
        })
        .unwrap();
    // Both branches must be exercised for the checks above to mean anything (each ≥ 5 %).
    assert!(
        accepted.get() >= 150 && refused.get() >= 150,
        "accepted {}, refused {}",
        accepted.get(),
        refused.get()
    );
}

/// Each controller kind's own gains, the velocity filter and the tension limits: negative,
/// non-finite or unstable values are named errors before any work starts.
#[test]
fn controller_kinds_refuse_bad_gains_and_limits() {
    let cases: &[(&str, &str, &str, f64)] = &[
        ("pid-xz", "p_z", "-1.0", -1.0),
        ("pid-xz", "i_z", "nan", f64::NAN),
        ("pid-xz", "d_z", "inf", f64::INFINITY),
        ("computed-torque", "kp", "0.0", 0.0),
        ("computed-torque", "kd", "-300.0", -300.0),
        ("computed-torque", "ki", "-1.0", -1.0),
        // Routh–Hurwitz: K_i must stay below K_d K_p = 300 · 30000.
        ("computed-torque", "ki", "9e6", 9e6),
        ("computed-torque", "velocity_filter", "0.0", 0.0),
        ("computed-torque", "velocity_filter", "nan", f64::NAN),
        ("lqr", "q_position", "0.0", 0.0),
        ("lqr", "q_velocity", "-1.0", -1.0),
        ("lqr", "q_integral", "inf", f64::INFINITY),
        ("lqr", "r", "0.0", 0.0),
        ("lqr", "velocity_filter", "-400.0", -400.0),
        // t_min ≥ t_max.
        ("lqr", "t_max", "5.0\nt_min = 5.0", 5.0),
        // Two cables at 4 N cannot hold 9.81 N, nor the start's ΣT = 200 N.
        ("pid", "t_max", "4.0", 4.0),
        ("computed-torque", "t_max", "60.0", 60.0),
    ];
    for &(kind, name, literal, value) in cases {
        let text = format!("[controller]\nkind = \"{kind}\"\n{name} = {literal}\n");
        expect_out_of_range(&text, &format!("controller.{name}"), value);
    }
    // Gains of another kind are not judged.
    scenario_from_toml_str("[controller]\nkind = \"pid\"\nkp = -1.0\n").unwrap();
    // An unknown controller names the allowed ones.
    expect_syntax(
        "[controller]\nkind = \"mpc\"\n",
        &["mpc", "pid-xz", "computed-torque", "lqr"],
    );
}

/// z_ref and the controller must agree: the paper's PID cannot hold z, the others regulate it.
#[test]
fn z_reference_must_fit_the_controller() {
    for (kind, z_ref) in [("pid", "hold"), ("lqr", "free"), ("pid-xz", "free")] {
        let text = format!("[controller]\nkind = \"{kind}\"\n[trajectory]\nz_ref = \"{z_ref}\"\n");
        let err = scenario_from_toml_str(&text).unwrap_err().to_string();
        assert!(
            err.contains("trajectory.z_ref") && err.contains(kind),
            "{err}"
        );
    }
    let s = scenario_from_toml_str("[controller]\nkind = \"lqr\"\n").unwrap();
    assert_eq!(s.z_ref(), cdpr_bench::core::scenario::ZRef::Hold);
    assert_eq!(
        Scenario::paper().z_ref(),
        cdpr_bench::core::scenario::ZRef::Free
    );
}
