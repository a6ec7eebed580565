//! The command line as a person uses it: files written, errors printed, exit codes.

mod common;

use common::TempDir;
use std::process::Command;

fn xtask() -> Command {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
}

#[test]
fn simulate_writes_timeseries_and_metrics() {
    let dir = TempDir::new("simulate");
    let scenario = dir.join("short.toml");
    std::fs::write(
        &scenario,
        "[simulation]\nt_final = 1.2\nsample_period = 1e-4\n",
    )
    .unwrap();
    let out = dir.join("out");
    let status = xtask()
        .args(["simulate", "--scenario"])
        .arg(&scenario)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let csv = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    assert!(
        header.starts_with("t [s],x_ref [m],x [m],z [m],error [m],F [N],T1 [N],T2 [N],"),
        "{header}"
    );
    assert_eq!(lines.count(), 12001, "samples at 0, 1e-4, …, 1.2 s");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    for key in [
        "t1_min",
        "t1_max",
        "t1_final",
        "t2_final",
        "t1_mean_last_1s",
        "t2_mean_last_1s",
        "err_max_transition",
        "err_max_settled",
        "overshoot",
        "z_mean",
        "z_p2p",
        "z_peak_rad_s",
        "err_peak_rad_s",
        "z_fft_record_rad_s",
        "err_hf_peak_rad_s",
        "err_hf_peak_db",
        "rhs_evals",
        "steps_accepted",
        "steps_rejected",
        "wall_s",
    ] {
        assert!(json.get(key).is_some(), "metrics.json lacks `{key}`");
    }
    // No temporary files are left behind by the atomic writes.
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn bad_scenario_is_reported_with_key_and_range() {
    let dir = TempDir::new("bad");
    let scenario = dir.join("bad.toml");
    std::fs::write(&scenario, "[robot]\neffector_mass = -1.0\n").unwrap();
    let output = xtask()
        .args(["simulate", "--scenario"])
        .arg(&scenario)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("robot.effector_mass") && stderr.contains("allowed"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// `spatial` refuses a grid it cannot draw (one target per axis) before any work.
#[test]
fn spatial_refuses_a_one_point_grid() {
    let dir = TempDir::new("spatial-points");
    let output = xtask()
        .args(["spatial", "--points", "1", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("--points") && stderr.contains("2..=20"),
        "{stderr}"
    );
    assert!(!dir.join("out").exists(), "nothing written");
}

#[test]
fn unknown_models_are_clear_errors() {
    let dir = TempDir::new("model");
    for (model, expect) in [
        ("rigid", "invalid value 'rigid' for '--model <MODEL>'"),
        ("", "a value is required for '--model <MODEL>'"),
    ] {
        let output = xtask()
            .args(["simulate", "--model", model, "--out"])
            .arg(dir.join("out"))
            .output()
            .unwrap();
        assert!(!output.status.success());
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(expect), "{model}: {stderr}");
        assert!(
            stderr.contains("possible values: elastic, lumped, fe"),
            "{model}: {stderr}"
        );
    }
}

/// `modes --at X`: the three models' modes (CSV with every mode, Markdown with the key ones), the
/// spectrum figure and the damping sweep. The lumped model's growing axial mode (MODELS.md §4)
/// must be in the CSV with σ > 0.5 1/s, and the sweep must name a damping for both massive models.
#[test]
fn modes_writes_tables_figure_and_sweep() {
    let dir = TempDir::new("modes");
    let out = dir.join("out");
    let status = xtask()
        .args(["modes", "--at", "0.6", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let csv = std::fs::read_to_string(out.join("modes.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .starts_with("model,loop,x_m,z_m,kind,order,omega_rad_s,growth_1_s")
    );
    let growing = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| f[0] == "lumped" && f[1] == "closed" && f[4].starts_with("axial"))
        .filter(|f| f[7].parse::<f64>().unwrap() > 0.5)
        .count();
    assert_eq!(growing, 1, "one growing lumped axial mode");
    let md = std::fs::read_to_string(out.join("modes.md")).unwrap();
    assert!(md.contains("| lumped | 0.6 | closed | vertical |"), "{md}");
    for model in ["lumped", "fe"] {
        assert!(
            md.contains(&format!("- {model} at x = 0.6: **C = ")),
            "{md}"
        );
    }
    let sweep = std::fs::read_to_string(out.join("damping_sweep.csv")).unwrap();
    assert!(sweep.lines().count() > 20);
    for ext in ["svg", "png"] {
        assert!(
            out.join(format!("modes_x0.6.{ext}"))
                .metadata()
                .unwrap()
                .len()
                > 1000
        );
    }
}

/// An effector position outside the workspace is a clear error and a non-zero exit.
#[test]
fn modes_outside_the_workspace_is_an_error() {
    let dir = TempDir::new("modes-bad");
    let status = xtask()
        .args(["modes", "--at", "1.5", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(!status.status.success());
    let stderr = String::from_utf8_lossy(&status.stderr);
    assert!(
        stderr.contains("x = 1.5") && stderr.contains("effector x"),
        "{stderr}"
    );
}

/// The 100 × 20 grid over the lumped property test's ranges on which the first two failures of
/// the statics beside a pulley were found (x = 0.1745 and 0.8255 m at ΣT = 197 N): every start
/// now finds its equilibrium, and the summary says so.
#[test]
fn statics_sweep_finds_every_lumped_equilibrium() {
    let output = xtask()
        .args([
            "statics-sweep",
            "--model",
            "lumped",
            "--x-steps",
            "100",
            "--tension-steps",
            "20",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        stdout.contains("lumped: 0 of 2000 starts found no equilibrium"),
        "{stdout}"
    );
}

/// A sweep range outside the workspace names the option and the allowed interval.
#[test]
fn statics_sweep_outside_the_workspace_is_an_error() {
    let output = xtask()
        .args(["statics-sweep", "--x-max", "1.2"])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("--x-max") && stderr.contains("(0, 1)"),
        "{stderr}"
    );
}

/// Runs `command --scenario DIR/scenario.toml --out DIR/out` on a scenario of `text`; returns
/// the process's output and the output directory.
fn run_on(dir: &TempDir, command: &str, text: &str) -> (std::process::Output, std::path::PathBuf) {
    let scenario = dir.join("scenario.toml");
    std::fs::write(&scenario, text).unwrap();
    let out = dir.join("out");
    let output = xtask()
        .args([command, "--scenario"])
        .arg(&scenario)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    (output, out)
}

/// [`run_on`] with a record of `t_final` seconds, expecting success; returns the output
/// directory.
fn run_short(dir: &TempDir, command: &str, t_final: f64) -> std::path::PathBuf {
    let (output, out) = run_on(
        dir,
        command,
        &format!("[simulation]\nt_final = {t_final}\n"),
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    out
}

/// `control` runs every controller on every model (a short record, for time) and writes the
/// leaderboard: one CSV row per pair, the paper PID's path error in millimetres and the
/// feedforward controllers' at round-off on the elastic model, the tables and figures in
/// control.md.
#[test]
fn control_writes_the_leaderboard() {
    let dir = TempDir::new("control");
    let out = run_short(&dir, "control", 1.5);
    let csv = std::fs::read_to_string(out.join("control.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 12, "4 controllers × 3 models");
    let path_error = |controller: &str, model: &str| -> f64 {
        let row = rows
            .iter()
            .find(|r| r[0] == controller && r[1] == model)
            .unwrap_or_else(|| panic!("no row for {controller} on {model}"));
        row[4].parse().unwrap()
    };
    // The paper's 5.9 mm overshoot class of error, on every model.
    for model in ["elastic", "lumped", "fe"] {
        let e = path_error("pid", model);
        assert!((5e-3..7e-3).contains(&e), "pid on {model}: {e}");
    }
    for controller in ["computed-torque", "lqr"] {
        assert!(path_error(controller, "elastic") < 1e-8, "{controller}");
        assert!(path_error(controller, "lumped") < 1e-4, "{controller}");
    }
    let md = std::fs::read_to_string(out.join("control.md")).unwrap();
    for needle in [
        "| pid | elastic |",
        "### Goals",
        "control_ex.svg",
        "control_spectrum.svg",
    ] {
        assert!(md.contains(needle), "control.md lacks {needle}");
    }
    for figure in ["control_ex", "control_ez", "control_spectrum"] {
        assert!(out.join(format!("{figure}.png")).exists(), "{figure}.png");
    }
}

/// `modes --controller` analyses the chosen controller's loop (its states in the Jacobian).
#[test]
fn modes_takes_the_controller() {
    let dir = TempDir::new("modes-controller");
    let out = dir.join("out");
    let status = xtask()
        .args(["modes", "--controller", "lqr", "--at", "0.6", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let csv = std::fs::read_to_string(out.join("modes.csv")).unwrap();
    // The LQR's closed elastic loop: 4 effector + 6 controller states, every mode decaying.
    let elastic: Vec<f64> = csv
        .lines()
        .filter(|l| l.starts_with("elastic,closed"))
        .map(|l| l.split(',').nth(7).unwrap().parse().unwrap())
        .collect();
    assert!(
        !elastic.is_empty() && elastic.iter().all(|&g| g < 0.0),
        "{elastic:?}"
    );
}

/// `shaping` refuses a scenario it cannot run before any of its runs, naming the key and
/// writing nothing. Its study itself (`cdpr_studies::shaping::compute` and the same writer) is
/// the report's shaping section, checked in report.rs on the report's own run.
#[test]
fn shaping_refuses_a_bad_scenario_before_work() {
    let dir = TempDir::new("shaping");
    let (output, out) = run_on(&dir, "shaping", "[simulation]\nt_final = -1.0\n");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        stderr.contains("t_final") && stderr.contains("-1"),
        "{stderr}"
    );
    assert!(!out.join("shaping.csv").exists());
}
