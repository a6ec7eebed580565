//! `cargo xtask plan` and `print` as a user runs them: the plan of a real slicer's file equals
//! Klipper's, bad G-code and layers are refused before any work naming the line or the option,
//! and an interrupted print keeps what it printed, marked so.

mod common;

use common::TempDir;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn xtask() -> Command {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn metrics(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap()
}

fn rows(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// The whole cube with Klipper's defaults (300 mm/s, 3 000 mm/s², origin 0): every row of
/// `plan.csv` is Klipper's to the bit, then one more, the robot driving home for the file's
/// closing `G28 X0` (Klipper sets the position without a move).
#[test]
fn plan_of_a_sliced_cube_is_klippers() {
    let dir = TempDir::new("plan");
    let output = xtask()
        .args(["plan", "--gcode"])
        .arg(root().join("verify/data/print/cube.gcode"))
        .arg("--out")
        .arg(&*dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(
        stderr.contains("skipped M104"),
        "skipped commands listed: {stderr}"
    );
    let ours = std::fs::read_to_string(dir.join("plan.csv")).unwrap();
    let klipper =
        std::fs::read_to_string(root().join("verify/data/print/plan_cube_full_a3000.csv")).unwrap();
    assert_eq!(ours.lines().next(), klipper.lines().next(), "the columns");
    let (ours, klipper) = (rows(&ours), rows(&klipper));
    assert_eq!(ours.len(), klipper.len() + 1);
    for (i, (a, b)) in ours.iter().zip(&klipper).enumerate() {
        let same = a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "row {i}: {a:?} against Klipper's {b:?}");
    }
    let home = ours.last().unwrap();
    assert_eq!(
        (home[7], home[8], home[9]),
        (-1.0, 0.0, 0.0),
        "home along −X"
    );
}

/// A malformed line stops the print before anything is written, naming its line and text.
#[test]
fn a_malformed_line_is_refused_before_work() {
    let dir = TempDir::new("bad-gcode");
    let gcode = dir.join("bad.gcode");
    std::fs::write(&gcode, "G28\nG1 X110 Y100 F6000\nG1 X1.2.3 Y5\n").unwrap();
    let out = dir.join("out");
    let output = xtask()
        .args(["print", "--scenario"])
        .arg(root().join("examples/printing/hangprinter.toml"))
        .arg("--gcode")
        .arg(&gcode)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        stderr.contains("line 3") && stderr.contains("G1 X1.2.3 Y5"),
        "{stderr}"
    );
    assert!(!out.join("metrics.json").exists() && !out.join("print.csv").exists());
}

/// Layers the file does not have are refused by the option's name.
#[test]
fn layers_without_moves_are_refused() {
    let dir = TempDir::new("layers");
    let output = xtask()
        .args(["print", "--scenario"])
        .arg(root().join("examples/printing/hangprinter.toml"))
        .arg("--gcode")
        .arg(root().join("verify/data/print/cube.gcode"))
        .args(["--layers", "500..600", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        stderr.contains("--layers") && stderr.contains("500..600"),
        "{stderr}"
    );
}

/// SIGINT stops a long print at the next step: `print.csv` holds every row it sampled (each
/// complete), `metrics.json` says "interrupted" with the contour error of what was printed.
#[test]
fn an_interrupted_print_keeps_what_it_printed() {
    let dir = TempDir::new("print-sigint");
    let out = dir.join("out");
    let child = xtask()
        .args(["print", "--scenario"])
        .arg(root().join("examples/printing/hangprinter.toml"))
        .arg("--gcode")
        .arg(root().join("verify/data/print/cube.gcode"))
        .args(["--layers", "1..30", "--out"])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let partial = out.join("print.partial.csv");
    let start = Instant::now();
    let streamed = || std::fs::read_to_string(&partial).map_or(0, |csv| csv.matches('\n').count());
    while streamed() <= 2000 {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no rows streamed"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{stderr}");
    let m = metrics(&out);
    assert_eq!(m["status"], "interrupted", "{stderr}");
    let t_reached = m["t_reached"].as_f64().unwrap();
    let csv = std::fs::read_to_string(out.join("print.csv")).unwrap();
    let printed = rows(&csv);
    assert!(printed.iter().all(|r| r.len() == printed[0].len()));
    // Samples every millisecond from 0 to the time reached.
    let expected = (t_reached / 1e-3).floor() + 1.0;
    assert!(
        (printed.len() as f64 - expected).abs() <= 1.0,
        "{} rows, {expected}",
        printed.len()
    );
    assert!(m["contour_err_max"].as_f64().unwrap() > 0.0);
    assert!(!partial.exists());
}
