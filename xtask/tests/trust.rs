//! The command line trusted at scale: one writer per output directory (sweeps, merges and
//! simulate runs into one `--out` refused, not mixed), a full disk that stops a run at once and
//! keeps what it wrote, interrupts honoured while a large grid is checked, and the small
//! first-contact mends (`--version`, `--every 0`, `--out` that is a file).

mod common;

use common::TempDir;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn xtask() -> Command {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
}

fn file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn metrics(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap()
}

/// Waits until `path` exists and holds more than `bytes`.
fn wait_for(path: &Path, bytes: u64) {
    let start = Instant::now();
    while std::fs::metadata(path).map_or(true, |m| m.len() <= bytes) {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "{} never grew",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn interrupt(child: &Child) {
    let ok = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
}

/// The FE paper run on DOPRI5 (~10 s): long enough to meet while it runs.
fn spawn_long_run(dir: &Path, out: &Path) -> Child {
    let scenario = file(dir, "fe.toml", "[model]\nkind = \"fe\"\n");
    xtask()
        .args(["simulate", "--scenario"])
        .arg(&scenario)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Two `simulate` runs into one `--out` left one's metrics.json beside the other's time series
/// (5 of 5 trials). The second is now refused at once, naming the run that holds the directory;
/// the first finishes with its own files.
#[test]
fn a_second_simulate_into_a_busy_out_is_refused() {
    let dir = TempDir::new("busy-simulate");
    let out = dir.join("out");
    let first = spawn_long_run(&dir, &out);
    wait_for(&out.join("timeseries.partial.csv"), 10_000);
    let short = file(&dir, "short.toml", "[simulation]\nt_final = 0.01\n");
    let started = Instant::now();
    let second = xtask()
        .args(["simulate", "--scenario"])
        .arg(&short)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!second.status.success());
    assert!(started.elapsed() < Duration::from_secs(5));
    let e = stderr(&second);
    assert!(
        e.contains("in use by another run") && e.contains("simulate, pid"),
        "{e}"
    );
    interrupt(&first);
    let o = first.wait_with_output().unwrap();
    assert!(!o.status.success(), "interrupted");
    let m = metrics(&out);
    assert_eq!(m["status"], "interrupted");
    assert_eq!(
        m["provenance"]["model"], "fe",
        "the first run's own metrics"
    );
    assert!(
        !out.join(".cdpr-lock").exists(),
        "the lock file is removed with the lock"
    );
}

/// Two shards started together into one `--out` kept 40 of 80 records and both reported all
/// theirs recorded. The second is now refused before any work; run after the first, it
/// completes the grid.
#[test]
fn two_shards_at_once_into_one_out_are_refused() {
    let dir = TempDir::new("busy-sweep");
    let grid = file(
        &dir,
        "grid.toml",
        "[scenario]\nmodel = { kind = \"fe\" }\nsimulation = { t_final = 0.6, sample_period = 1e-3 }\n\
         analysis = { modes = \"off\" }\n[axes]\n\"robot.effector_mass\" = [0.8, 0.9, 1.0, 1.1, 1.2, 1.3]\n",
    );
    let out = dir.join("out");
    let shard = |i: usize| {
        let mut c = xtask();
        c.args([
            "sweep",
            "--jobs",
            "1",
            "--shard",
            &format!("{i}/2"),
            "--grid",
        ])
        .arg(&grid)
        .arg("--out")
        .arg(&out);
        c
    };
    let first = shard(0)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&out.join(".cdpr-lock"), 0);
    let second = shard(1).output().unwrap();
    assert!(!second.status.success());
    let e = stderr(&second);
    assert!(
        e.contains("in use by another run") && e.contains("sweep shard 0/2"),
        "{e}"
    );
    let o = first.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let o = shard(1).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("results.jsonl")).unwrap();
    assert_eq!(text.lines().count(), 1 + 6, "the header and every point");
}

/// `bash -c` with a file-size limit of `blocks` KiB and SIGXFSZ ignored, so that a write past
/// it fails with EFBIG as on a full disk.
fn limited(blocks: u32) -> Command {
    let mut c = Command::new("bash");
    c.arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f {blocks}; exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_xtask"));
    c
}

/// A full disk was reported only after the whole run, with no metrics.json: the run now stops
/// at the failed write, names the file, and keeps what it wrote and its metrics.
#[test]
fn a_full_disk_stops_a_run_at_once_and_keeps_what_it_wrote() {
    let dir = TempDir::new("full-simulate");
    let out = dir.join("out");
    // The FE paper run on DOPRI5 writes ~200 MB of samples over ~10 s; 200 KiB fill in the
    // first few milliseconds of simulated time.
    let scenario = file(&dir, "fe.toml", "[model]\nkind = \"fe\"\n");
    let started = Instant::now();
    let o = limited(200)
        .args(["simulate", "--scenario"])
        .arg(&scenario)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(
        started.elapsed() < Duration::from_secs(5),
        "stopped at once"
    );
    let e = stderr(&o);
    assert!(
        e.contains("timeseries.partial.csv") && e.contains("File too large"),
        "{e}"
    );
    let m = metrics(&out);
    assert_eq!(m["status"], "failed");
    assert!(m["error"].as_str().unwrap().contains("File too large"));
    let t = m["t_reached"].as_f64().unwrap();
    assert!(t > 0.0 && t < 0.1, "{t}");
    let partial = std::fs::read_to_string(out.join("timeseries.partial.csv")).unwrap();
    assert!(
        partial.len() >= 200 * 1024 - 4096,
        "{} bytes kept",
        partial.len()
    );
}

/// A sweep whose results file cannot grow stops at the failed write with the path; the records
/// written are whole, and the same command without the limit resumes to the full grid.
#[test]
fn a_full_disk_stops_a_sweep_at_once_and_it_resumes() {
    let dir = TempDir::new("full-sweep");
    let grid = file(
        &dir,
        "grid.toml",
        "[scenario]\nsimulation = { t_final = 1.2, sample_period = 1e-3 }\n\
         analysis = { modes = \"off\" }\n[axes]\n\"robot.effector_mass\" = { from = 0.5, to = 2.0, steps = 30 }\n",
    );
    let out = dir.join("out");
    let args = |c: &mut Command| {
        c.args(["sweep", "--jobs", "1", "--grid"])
            .arg(&grid)
            .arg("--out")
            .arg(&out);
    };
    let mut c = limited(12);
    args(&mut c);
    let o = c.output().unwrap();
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("results.jsonl") && e.contains("File too large"),
        "{e}"
    );
    let text = std::fs::read_to_string(out.join("results.jsonl")).unwrap();
    let complete = &text[..text.rfind('\n').unwrap() + 1];
    let kept = complete.lines().count() - 1;
    assert!((1..30).contains(&kept), "{kept} records kept");
    for line in complete.lines() {
        serde_json::from_str::<serde_json::Value>(line).unwrap();
    }
    let mut c = xtask();
    args(&mut c);
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = String::from_utf8_lossy(&o.stdout);
    assert!(
        summary.contains(&format!("({kept} resumed, {} run", 30 - kept)),
        "{summary}"
    );
}

/// SIGINT and SIGTERM were ignored for the hours two 1e5-step axes took to check; a grid is now
/// bounded as it is read, and the check of a million points stops within a second.
#[test]
fn an_interrupt_during_the_check_stops_the_sweep_within_a_second() {
    let dir = TempDir::new("check-interrupt");
    let grid = file(
        &dir,
        "grid.toml",
        "[axes]\n\"trajectory.t2\" = { from = 0.1, to = 0.5, steps = 1000 }\n\
         \"robot.effector_mass\" = { from = 0.5, to = 2.0, steps = 1000 }\n",
    );
    let out = dir.join("out");
    let child = xtask()
        .args(["sweep", "--grid"])
        .arg(&grid)
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&out.join(".cdpr-lock"), 0);
    std::thread::sleep(Duration::from_millis(500));
    let sent = Instant::now();
    interrupt(&child);
    let o = child.wait_with_output().unwrap();
    assert!(
        sent.elapsed() < Duration::from_secs(1),
        "{:?}",
        sent.elapsed()
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("interrupted while checking"),
        "{}",
        stderr(&o)
    );
    assert!(!out.join("results.jsonl").exists());

    let big = file(
        &dir,
        "big.toml",
        "[axes]\n\"trajectory.t2\" = { from = 0.1, to = 0.5, steps = 100000 }\n\
         \"robot.effector_mass\" = { from = 0.5, to = 2.0, steps = 100000 }\n",
    );
    let started = Instant::now();
    let o = xtask()
        .args(["sweep", "--grid"])
        .arg(&big)
        .arg("--out")
        .arg(dir.join("big"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(started.elapsed() < Duration::from_secs(2));
    assert!(stderr(&o).contains("1e10 points"), "{}", stderr(&o));
}

/// `--version` answers; `--every 0` (which meant 1) and an `--out` that is a file (which failed
/// after every run of a study) are refused before any work, naming them; an OS error is printed
/// once.
#[test]
fn first_contact() {
    let o = xtask().arg("--version").output().unwrap();
    assert!(o.status.success());
    assert!(
        String::from_utf8_lossy(&o.stdout).contains(env!("CARGO_PKG_VERSION")),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let dir = TempDir::new("first-contact");
    let o = xtask()
        .args(["simulate", "--every", "0", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--every"), "{}", stderr(&o));
    let not_a_dir = file(&dir, "a-file", "");
    for command in ["control", "shaping", "modes"] {
        let started = Instant::now();
        let o = xtask()
            .args([command, "--out"])
            .arg(&not_a_dir)
            .output()
            .unwrap();
        assert!(!o.status.success());
        assert!(
            started.elapsed() < Duration::from_secs(3),
            "{command}: refused before its runs"
        );
        assert!(stderr(&o).contains("--out"), "{command}: {}", stderr(&o));
    }
    let grid = file(
        &dir,
        "grid.toml",
        "[axes]\n\"robot.effector_mass\" = [1.0]\n",
    );
    let o = xtask()
        .args(["sweep", "--grid"])
        .arg(&grid)
        .arg("--out")
        .arg(&not_a_dir)
        .output()
        .unwrap();
    let e = stderr(&o);
    assert!(!o.status.success());
    assert_eq!(e.matches("os error").count(), 1, "{e}");
}
