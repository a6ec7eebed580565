//! `cargo xtask sweep` as a person and a Slurm array use it: shards run apart and merged give
//! the one-machine sweep's records, and every bad input is refused with the key, value or shard
//! named, before any point runs.

mod common;

use common::TempDir;
use std::path::Path;
use std::process::{Command, Output};

const GRID: &str = r#"
[scenario]
simulation = { t_final = 1.0 }
analysis = { modes = "off" }
[axes]
"robot.effector_mass" = { from = 0.5, to = 2.0, steps = 3, scale = "log" }
"trajectory.t2" = [0.2, 0.3]
"#;

fn sweep(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("sweep")
        .args(args)
        .output()
        .unwrap()
}

fn records_without_wall(dir: &Path) -> Vec<String> {
    std::fs::read_to_string(dir.join("results.jsonl"))
        .unwrap()
        .lines()
        .map(|l| l.split("\"wall_s\":").next().unwrap().to_string())
        .collect()
}

#[test]
fn shards_merged_equal_the_one_machine_sweep() {
    let dir = TempDir::new("sweep-cli");
    let grid = dir.join("grid.toml");
    std::fs::write(&grid, GRID).unwrap();
    let grid = grid.to_str().unwrap();
    let whole = dir.join("whole");
    let out = sweep(&["--grid", grid, "--out", whole.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut shard_dirs = Vec::new();
    for i in 0..3 {
        let d = dir.join(format!("shard{i}"));
        let out = sweep(&[
            "--grid",
            grid,
            "--out",
            d.to_str().unwrap(),
            "--shard",
            &format!("{i}/3"),
            "--jobs",
            "1",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        shard_dirs.push(d);
    }
    let merged = dir.join("merged");
    let mut args = vec!["--out", merged.to_str().unwrap(), "--merge"];
    args.extend(shard_dirs.iter().map(|d| d.to_str().unwrap()));
    let out = sweep(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let records = records_without_wall(&whole);
    assert_eq!(records.len(), 7, "a header and six records");
    assert_eq!(records, records_without_wall(&merged));
    assert!(merged.join("results.csv").exists());
}

#[test]
fn bad_input_is_refused_before_any_work() {
    let dir = TempDir::new("sweep-cli-errors");
    let grid = dir.join("grid.toml");
    std::fs::write(&grid, GRID).unwrap();
    let bad_key = dir.join("bad_key.toml");
    std::fs::write(&bad_key, "[axes]\n\"robot.mass\" = [1.0]\n").unwrap();
    let bad_value = dir.join("bad_value.toml");
    std::fs::write(&bad_value, "[axes]\n\"trajectory.t2\" = [0.2, -0.1]\n").unwrap();
    let out_dir = dir.join("out");
    let out = out_dir.to_str().unwrap();
    let g = grid.to_str().unwrap();
    for (args, needles) in [
        (
            vec!["--grid", g, "--out", out, "--shard", "3/2"],
            vec!["3/2", "I must be < N"],
        ),
        (
            vec!["--grid", g, "--out", out, "--shard", "0/0"],
            vec!["0/0", "N must be ≥ 1"],
        ),
        (
            vec!["--grid", g, "--out", out, "--jobs", "0"],
            vec!["--jobs 0"],
        ),
        (
            vec!["--grid", bad_key.to_str().unwrap(), "--out", out],
            vec!["point 0", "mass"],
        ),
        (
            vec!["--grid", bad_value.to_str().unwrap(), "--out", out],
            vec!["point 1", "trajectory.t2", "-0.1"],
        ),
        (
            vec![
                "--grid",
                dir.join("none.toml").to_str().unwrap(),
                "--out",
                out,
            ],
            vec!["none.toml"],
        ),
    ] {
        let o = sweep(&args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        for n in needles {
            assert!(stderr.contains(n), "{args:?}: {stderr}");
        }
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(
            !out_dir.join("results.jsonl").exists(),
            "{args:?} wrote results"
        );
    }
}

/// The shipped Slurm script, run as each task of a 3-task array would run it (Slurm's
/// environment variables set by hand), then merged: the one-machine sweep's records.
#[test]
fn the_slurm_array_script_covers_the_grid() {
    let dir = TempDir::new("sweep-slurm");
    let grid = dir.join("grid.toml");
    std::fs::write(&grid, GRID).unwrap();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/slurm/sweep.sbatch"
    );
    let out = dir.join("array");
    // Slurm runs a copy of the script from its spool directory: the binary is found under the
    // directory sbatch was run from (a checkout with target/release/xtask), not the job's.
    let submit = dir.join("checkout");
    std::fs::create_dir_all(submit.join("target/release")).unwrap();
    std::os::unix::fs::symlink(
        env!("CARGO_BIN_EXE_xtask"),
        submit.join("target/release/xtask"),
    )
    .unwrap();
    for task in 0..3 {
        let mut c = Command::new("bash");
        c.arg(script)
            .arg(&grid)
            .arg(&out)
            .env("SLURM_ARRAY_TASK_ID", task.to_string())
            .env("SLURM_ARRAY_TASK_COUNT", "3")
            .env("SLURM_CPUS_PER_TASK", "1");
        if task == 0 {
            c.env("SLURM_SUBMIT_DIR", &submit)
                .env_remove("XTASK")
                .current_dir("/");
        } else {
            c.env("XTASK", env!("CARGO_BIN_EXE_xtask"));
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let merged = dir.join("merged");
    let mut args = vec!["--out", merged.to_str().unwrap(), "--merge"];
    let shards: Vec<String> = (0..3)
        .map(|i| out.join(format!("shard-{i}")).display().to_string())
        .collect();
    args.extend(shards.iter().map(String::as_str));
    assert!(sweep(&args).status.success());
    let whole = dir.join("whole");
    let o = sweep(&[
        "--grid",
        grid.to_str().unwrap(),
        "--out",
        whole.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    assert_eq!(records_without_wall(&whole), records_without_wall(&merged));
}

/// A sweep killed (SIGKILL) at an arbitrary moment leaves a file whose every complete line is a
/// record, and the same command resumes it to the one-machine sweep's records.
#[test]
fn a_killed_sweep_leaves_readable_records_and_resumes() {
    let dir = TempDir::new("sweep-kill");
    let grid = dir.join("grid.toml");
    std::fs::write(
        &grid,
        "[scenario]\nsimulation = { t_final = 1.0 }\nanalysis = { modes = \"off\" }\n\
         [axes]\n\"robot.effector_mass\" = { from = 0.5, to = 2.0, steps = 24 }\n",
    )
    .unwrap();
    let out = dir.join("killed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["sweep", "--jobs", "2", "--grid"])
        .arg(&grid)
        .arg("--out")
        .arg(&out)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Wait for the first records, then kill without warning.
    let results = out.join("results.jsonl");
    let start = std::time::Instant::now();
    while std::fs::read_to_string(&results)
        .map(|t| t.lines().count() < 3)
        .unwrap_or(true)
        && start.elapsed().as_secs() < 60
    {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let text = std::fs::read_to_string(&results).unwrap();
    let complete = &text[..text.rfind('\n').map_or(0, |i| i + 1)];
    for line in complete.lines() {
        serde_json::from_str::<serde_json::Value>(line).unwrap_or_else(|e| panic!("{e}: {line}"));
    }
    let o = sweep(&[
        "--grid",
        grid.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let fresh = dir.join("fresh");
    let o = sweep(&[
        "--grid",
        grid.to_str().unwrap(),
        "--out",
        fresh.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    assert_eq!(records_without_wall(&fresh), records_without_wall(&out));
}
