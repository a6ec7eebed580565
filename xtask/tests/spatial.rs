//! `cargo xtask simulate` and `cargo xtask spatial-moves` on a spatial robot, as a printer
//! builder runs them: the files, their channels and metrics, checked against what the test
//! computes itself from the anchors; refusals before any file is written.

mod common;

use common::TempDir;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/robots")
        .join(name)
}

fn xtask(args: &[&str], scenario: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(args)
        .arg("--scenario")
        .arg(scenario)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

/// `out/timeseries.csv`: the channels' names (units stripped) and the rows.
fn timeseries(out: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let mut lines = text.lines();
    let names = lines
        .next()
        .unwrap()
        .split(',')
        .map(|h| h.split(" [").next().unwrap().to_owned())
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (names, rows)
}

/// The Hangprinter example's move: every sample's tensions pull the effector with W T, W from
/// the anchors here, the effector's own acceleration M p̈ + M g (second differences of the
/// samples, O(Δt²) with the dense output's interpolation: 1.9e-5 N seen, 1e-4 N allowed, of
/// 16 N); the lengths are the anchors' distances; the metrics
/// reproduce from the CSV.
#[test]
fn hangprinter_move_writes_a_consistent_record() {
    let dir = TempDir::new("spatial-simulate");
    let out = dir.join("out");
    let run = xtask(&["simulate"], &example("hangprinter.toml"), &out);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["status"], "complete");
    assert_eq!(metrics["cables"], 4);
    for figure in ["path.svg", "path.png", "tensions.svg", "tensions.png"] {
        let bytes = std::fs::metadata(out.join(figure)).map_or(0, |m| m.len());
        assert!(bytes > 1000, "{figure}: {bytes} B");
    }
    assert!(metrics["path_err_max_move"].as_f64().unwrap() < 1e-6);
    let (names, rows) = timeseries(&out);
    let col = |name: &str| names.iter().position(|n| *n == name).unwrap();
    let anchors = [
        [0.0, -1.61098, -0.13153],
        [1.31422, 1.26814, -0.12128],
        [-1.41573, 0.70761, -0.12182],
        [0.0, 0.0, 2.29983],
    ];
    let dt = rows[1][0] - rows[0][0];
    let mut t_max_seen = f64::NEG_INFINITY;
    for k in 1..rows.len() - 1 {
        let p = |r: &Vec<f64>| [r[col("x")], r[col("y")], r[col("z")]];
        let (a, b, c) = (p(&rows[k - 1]), p(&rows[k]), p(&rows[k + 1]));
        let mut pull = [0.0; 3];
        for (i, anchor) in anchors.iter().enumerate() {
            let d: Vec<f64> = (0..3).map(|j| anchor[j] - b[j]).collect();
            let l = d.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!((rows[k][col(&format!("l{}", i + 1))] - l).abs() < 1e-12);
            let t = rows[k][col(&format!("T{}", i + 1))];
            t_max_seen = t_max_seen.max(t);
            for j in 0..3 {
                pull[j] += t * d[j] / l;
            }
        }
        // step5's jerk jumps at t1 = 0 and t2 = 0.2 s: a second difference straddling the jump
        // is off by ~ jerk Δt / 3 ≈ 0.03 N there.
        if (rows[k][0] - 0.2).abs() < 1.5 * dt {
            continue;
        }
        for j in 0..3 {
            let acc = (a[j] - 2.0 * b[j] + c[j]) / (dt * dt);
            let needed = acc + if j == 2 { 9.81 } else { 0.0 };
            assert!(
                (pull[j] - needed).abs() < 2e-3,
                "t = {}: axis {j}",
                rows[k][0]
            );
        }
    }
    assert_eq!(metrics["tension_max"].as_f64().unwrap(), t_max_seen);
}

/// The Hangprinter move on lumped lines through the CLI: a complete record whose massive-cable
/// channels (tension at the effector and over the pulley, free length, stored nodes) are there
/// per cable, nodes cross the pulleys (a stored count changes), and the line's tension at the
/// effector stays within the commanded tension less the free line's weight and its dynamics
/// (2 N of 10–70 N: the line weighs 0.03 N; the undamped line's axial ringing after a node
/// crosses a pulley reached 0.93 N).
#[test]
fn hangprinter_move_on_lumped_lines_writes_its_cable_channels() {
    let dir = TempDir::new("spatial-lumped");
    let out = dir.join("out");
    let run = xtask(&["simulate"], &example("hangprinter-lumped.toml"), &out);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["status"], "complete");
    let (names, rows) = timeseries(&out);
    let column = |name: &str| {
        let k = names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("{name}"));
        rows.iter().map(|r| r[k]).collect::<Vec<f64>>()
    };
    let mut crossed = false;
    for cable in 1..=4 {
        let stored = column(&format!("stored_{cable}"));
        crossed |= stored.iter().any(|s| *s != stored[0]);
        let (commanded, at_effector) = (
            column(&format!("T{cable}")),
            column(&format!("T_effector_{cable}")),
        );
        for (k, (t, e)) in commanded.iter().zip(&at_effector).enumerate() {
            assert!(
                (t - e).abs() < 1.0,
                "cable {cable}, sample {k}: {t} N commanded, {e} N at the effector"
            );
        }
        assert!(
            column(&format!("l_free_{cable}"))
                .iter()
                .all(|l| *l > 0.5 && *l < 3.2)
        );
    }
    assert!(crossed, "no node crossed a pulley");
}

/// `cargo xtask flex-error` on the CoGiRo example's steel lines: a record per target whose error is
/// the distance from its rest to its target, the Markdown table's largest error the record's,
/// and a box given upside down refused before any file.
#[test]
fn flex_error_writes_a_consistent_record() {
    let dir = TempDir::new("flex-error");
    let out = dir.join("out");
    let run = xtask(
        &["flex-error", "--box=-4,4,-3,3,0.5,3.5", "--points", "2"],
        &example("cogiro-lumped.toml"),
        &out,
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let study: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("flex-error.json")).unwrap())
            .unwrap();
    let points = study["points"].as_array().unwrap();
    assert_eq!(points.len(), 8);
    let mut largest = 0.0f64;
    for p in points {
        let (rest, target) = (&p["rest"], &p["target"]);
        let d = (0..3)
            .map(|k| (rest[k].as_f64().unwrap() - target[k].as_f64().unwrap()).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!((d - p["error"].as_f64().unwrap()).abs() < 1e-15, "{p}");
        assert!(d > 1e-5 && d < 1e-2, "a sag error of {d} m");
        largest = largest.max(d);
    }
    assert_eq!(study["max"].as_f64().unwrap(), largest);
    let table = std::fs::read_to_string(out.join("flex-error.md")).unwrap();
    assert!(
        table.contains(&format!("largest error {largest:.3e} m")),
        "{table}"
    );
    let upside_down = dir.join("upside-down");
    let refused = xtask(
        &["flex-error", "--box=4,-4,-3,3,0.5,3.5"],
        &example("cogiro-lumped.toml"),
        &upside_down,
    );
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--box"));
    assert!(!upside_down.exists());
}

/// Refused before any file: a reference the box cannot follow (named with time, pose, cable),
/// a robot described for its statics only (no move), and lumped lines too short for the move
/// or reeled into the workspace.
#[test]
fn spatial_runs_are_refused_before_any_file() {
    let dir = TempDir::new("spatial-refusals");
    let base = std::fs::read_to_string(example("hangprinter.toml")).unwrap();
    let fast = base.replace("t2 = 0.2", "t2 = 0.03");
    let model = |keys: &str| format!("{base}\n[model]\n{keys}\n");
    let long =
        |text: String| text.replace("density = 970.0", "density = 970.0\nmodelled_length = 3.2");
    let inward = long(model("kind = \"lumped\"")).replace(
        "effector_mass = 1.0",
        "effector_mass = 1.0\nreel_directions = [[0, -1, 0], [1, 1, 0], [-1, 0, 0], [0, 0, -1]]",
    );

    for (file, text, expected) in [
        ("fast.toml", fast, "wrench-feasible workspace at t ="),
        (
            "short.toml",
            model("kind = \"lumped\""),
            "cable.modelled_length",
        ),
        ("inward.toml", inward, "robot.reel_directions"),
    ] {
        let path = dir.join(file);
        std::fs::write(&path, text).unwrap();
        let out = dir.join(file.replace(".toml", ""));
        let run = xtask(&["simulate"], &path, &out);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            !run.status.success() && stderr.contains(expected),
            "{file}: {stderr}"
        );
        assert!(!out.join("metrics.json").exists(), "{file}");
    }
    let statics = dir.join("statics.toml");
    let robot_only = base.split("[trajectory]").next().unwrap();
    std::fs::write(&statics, robot_only).unwrap();
    let statics_only = xtask(&["simulate"], &statics, &dir.join("statics"));
    let stderr = String::from_utf8_lossy(&statics_only.stderr);
    assert!(stderr.contains("trajectory.start"), "{stderr}");
}

/// The docs' table: every controller × distribution, the tension controllers within 1 µm.
#[test]
fn spatial_moves_table() {
    let dir = TempDir::new("spatial-moves");
    let out = dir.join("out");
    let run = xtask(&["spatial-moves"], &example("hangprinter.toml"), &out);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("moves.json")).unwrap()).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 6 * 4);
    for r in rows {
        let controller = r["controller"].as_str().unwrap();
        let err = r["metrics"]["path_err_max_move"].as_f64().unwrap();
        if controller == "computed-torque" || controller == "lqr" {
            assert!(err < 1e-6, "{controller}: {err}");
        }
    }
    assert!(
        std::fs::read_to_string(out.join("moves.md"))
            .unwrap()
            .contains("| length/static |")
    );
}

fn modes(dir: &Path, scenario_text: &str, at: &str) -> serde_json::Value {
    let path = dir.join("s.toml");
    std::fs::write(&path, scenario_text).unwrap();
    let out = dir.join("modes");
    let run = xtask(&["modes", "--at", at], &path, &out);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(out.join("modes.json")).unwrap()).unwrap()
}

/// The paper's robot in space, closed by the paper's PID: the loop's out-of-plane mode (from
/// the closed loop's finite-difference Jacobian) is the undamped pendulum ω_y² = Σ T_i/(M l_i),
/// computed here from the rest pose and tensions the command reports (1e-6 relative: the
/// differences' truncation).
#[test]
fn the_out_of_plane_mode_of_the_paper_robot_is_the_pendulum() {
    let dir = TempDir::new("spatial-modes-plane");
    let report = modes(
        &dir,
        "[robot]\nanchors = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]\n",
        "0.6",
    );
    let pose: Vec<f64> = serde_json::from_value(report["pose"].clone()).unwrap();
    let t: Vec<f64> = serde_json::from_value(report["tensions"].clone()).unwrap();
    let l = [pose[0].hypot(pose[2]), (1.0 - pose[0]).hypot(pose[2])];
    let pendulum = (t[0] / l[0] + t[1] / l[1]).sqrt();
    let closed: Vec<&serde_json::Value> = report["modes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["linearisation"] == "closed" && m["name"] == "out-of-plane (y)")
        .collect();
    assert_eq!(closed.len(), 1, "{report:#}");
    let omega = closed[0]["omega_rad_s"].as_f64().unwrap();
    assert!(
        (omega - pendulum).abs() < 1e-6 * pendulum,
        "{omega} against {pendulum}"
    );
    assert!(closed[0]["growth"].as_f64().unwrap().abs() < 1e-6);
}

/// Hangprinter at the move's end: the locked reels' modes (eigenvalues of the closed-form
/// stiffness) are the modes of the loop closed by the `length` controller holding its lengths
/// (eigenvalues of that loop's finite-difference Jacobian) — two computations that share
/// nothing but the robot; 1e-6 relative.
#[test]
fn locked_reel_modes_are_the_length_controlled_loops() {
    let dir = TempDir::new("spatial-modes-locked");
    let text = std::fs::read_to_string(example("hangprinter.toml"))
        .unwrap()
        .replace("kind = \"computed-torque\"", "kind = \"length\"");
    let report = modes(&dir, &text, "0.1,0.05,0.02");
    let omegas = |which: &str| -> Vec<f64> {
        let mut v: Vec<f64> = report["modes"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| m["linearisation"] == which && m["omega_rad_s"].as_f64().unwrap() > 0.0)
            .map(|m| m["omega_rad_s"].as_f64().unwrap())
            .collect();
        v.sort_by(f64::total_cmp);
        v
    };
    let (locked, closed) = (omegas("locked-reels"), omegas("closed"));
    assert_eq!(locked.len(), 3);
    assert_eq!(closed.len(), 3, "{report:#}");
    for (a, b) in locked.iter().zip(&closed) {
        assert!((a - b).abs() < 1e-6 * a, "{locked:?} against {closed:?}");
    }
}

/// The modes study on lumped lines adds every mode of the robot at rest with its reels locked,
/// named and in ascending order: the effector's three and each cable's string families (across
/// and in its vertical plane; the plumb line under the ceiling anchor has two in-plane ones).
/// Their values are checked against closed forms in verify/tests/lumped_spatial/modes.rs.
#[test]
fn the_lumped_lines_modes_are_listed_by_name() {
    let dir = TempDir::new("spatial-modes-lumped");
    let text = std::fs::read_to_string(example("hangprinter-lumped.toml")).unwrap();
    let report = modes(&dir, &text, "0,0,0");
    let lumped: Vec<&serde_json::Value> = report["modes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["linearisation"] == "lumped-locked-reels")
        .collect();
    let names: Vec<&str> = lumped.iter().map(|m| m["name"].as_str().unwrap()).collect();
    for expected in [
        "effector x #1",
        "effector y #1",
        "effector vertical #1",
        "out-of-plane string cable 1 #1",
        "in-plane string cable 1 #1",
        "out-of-plane string cable 3 #1",
        "in-plane string cable 4 #2",
        "axial cable 2 #1",
    ] {
        assert!(names.contains(&expected), "no {expected}: {names:?}");
    }
    let omega: Vec<f64> = lumped
        .iter()
        .map(|m| m["omega_rad_s"].as_f64().unwrap())
        .collect();
    assert!(omega.windows(2).all(|w| w[0] <= w[1]), "{omega:?}");
}
