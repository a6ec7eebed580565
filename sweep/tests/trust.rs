//! Records that can be trusted at scale: the same bits for a point whatever the thread, the
//! order, the worker count or the shard; results files that are checked record by record on
//! resume and merge; one writer per directory; grids and memory bounded before any work; a check
//! that stops when asked.

use cdpr_sweep::store::{DirLock, RESULTS, read_records};
use cdpr_sweep::{Grid, Header, Options, Record, Shard, SweepError};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cdpr-trust-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn options(jobs: usize, shard: Shard, stop: Option<&AtomicBool>) -> Options<'_> {
    Options { jobs, shard, stop }
}

fn run(grid: &Grid, dir: &Path, options: Options) -> Result<cdpr_sweep::Summary, SweepError> {
    cdpr_sweep::run(grid, dir, options, &mut |_| {})
}

fn records(dir: &Path) -> Vec<Record> {
    let (_, mut records) = read_records(&dir.join(RESULTS)).unwrap();
    records.sort_by_key(|r| r.point);
    for r in &mut records {
        r.wall_s = 0.0;
    }
    records
}

/// A study over t_final at 0.1 ms: its records' spectra have 80 lengths, and rustfft's shared
/// planner built some lengths' plans on another length's cached parts, so 4 of these 80 records
/// differed in their refined peaks between `--jobs 1` and `--jobs 2` (and `--merge` of the two
/// runs failed). Now every record equals its point run alone on a fresh thread, bit for bit.
#[test]
fn records_are_the_same_bits_whatever_the_thread_order_or_jobs() {
    let grid = Grid::from_toml_str(
        r#"
        [scenario]
        analysis = { modes = "off" }
        simulation = { sample_period = 1e-4 }
        [axes]
        "simulation.t_final" = { from = 2.0, to = 5.0, steps = 40 }
        "trajectory.t2" = [0.2, 0.35]
        "#,
        "t_final",
    )
    .unwrap();
    let (one, two) = (tmp("jobs1"), tmp("jobs2"));
    run(&grid, &one, options(1, Shard::ALL, None)).unwrap();
    run(&grid, &two, options(2, Shard::ALL, None)).unwrap();
    let (a, b) = (records(&one), records(&two));
    assert_eq!(a.len(), 80);
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(
            x, y,
            "point {} differs between --jobs 1 and --jobs 2",
            x.point
        );
    }
    // Each record is its point alone, on a thread that transformed nothing before.
    for x in &a {
        let g = grid.clone();
        let index = x.point;
        let mut alone = std::thread::spawn(move || cdpr_sweep::evaluate(&g, index, None))
            .join()
            .unwrap()
            .unwrap();
        alone.wall_s = 0.0;
        assert_eq!(
            *x, alone,
            "point {index} in a sweep differs from its run alone"
        );
    }
    // Two full runs merge (every point recorded twice, alike but for wall_s).
    let merged = tmp("merged-twice");
    let (_, n) = cdpr_sweep::merge(&[one, two], &merged, None).unwrap();
    assert_eq!(n, 80);
    assert_eq!(records(&merged), a);
}

/// A small grid and a file of its header, for the tampering cases.
fn small() -> (Grid, String) {
    let grid = Grid::from_toml_str(
        "[scenario]\nsimulation = { t_final = 0.3, sample_period = 1e-3 }\n\
         analysis = { modes = \"off\" }\n[axes]\n\"robot.effector_mass\" = [0.8, 1.0, 1.2, 1.4, 1.6]\n",
        "small",
    )
    .unwrap();
    let header = serde_json::to_string(&Header::of(&grid)).unwrap();
    (grid, header)
}

/// Resume reads whatever results.jsonl holds, so each record is checked against the grid
/// before any work: a point outside the grid, parameters that are not the point's, two
/// different records of one point and an unknown status are named errors with their line; a
/// point recorded twice alike is kept once.
#[test]
fn tampered_results_files_are_refused_before_any_work() {
    let (grid, header) = small();
    let source = tmp("source");
    run(&grid, &source, options(2, Shard::ALL, None)).unwrap();
    let good = records(&source);
    let line = |r: &Record| serde_json::to_string(r).unwrap();
    let mut point_99 = good[2].clone();
    point_99.point = 99;
    let mut wrong_params = good[2].clone();
    wrong_params.params["robot.effector_mass"] = serde_json::json!(5.0);
    let mut conflicting = good[1].clone();
    conflicting.metrics["z_p2p"] = serde_json::json!(1.0);
    let mut odd_status = good[3].clone();
    odd_status.status = "fine".into();
    for (tampered, needles) in [
        (&point_99, &["line 3", "point 99", "points 0 … 4"][..]),
        (
            &wrong_params,
            &["line 3", "point 2's parameters", "5.0"][..],
        ),
        (
            &conflicting,
            &["point 1 is recorded twice", "lines 2 and 3"][..],
        ),
        (&odd_status, &["line 3", "status \"fine\""][..]),
    ] {
        let dir = tmp("tampered");
        std::fs::create_dir_all(&dir).unwrap();
        let text = format!("{header}\n{}\n{}\n", line(&good[1]), line(tampered));
        std::fs::write(dir.join(RESULTS), &text).unwrap();
        let e = run(&grid, &dir, options(1, Shard::ALL, None))
            .unwrap_err()
            .to_string();
        for n in needles {
            assert!(e.contains(n), "{n:?} not in: {e}");
        }
        assert_eq!(
            std::fs::read_to_string(dir.join(RESULTS)).unwrap(),
            text,
            "untouched"
        );
        // The same file is refused by --merge.
        let e = cdpr_sweep::merge(std::slice::from_ref(&dir), &tmp("merge-tampered"), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains(needles[0]), "{e}");
    }
    // A duplicate alike (a resumed sweep killed between its append and its rewrite) is kept once.
    let dir = tmp("duplicate");
    std::fs::create_dir_all(&dir).unwrap();
    let mut again = good[1].clone();
    again.wall_s = 123.0;
    let text = format!("{header}\n{}\n{}\n", line(&good[1]), line(&again));
    std::fs::write(dir.join(RESULTS), text).unwrap();
    let s = run(&grid, &dir, options(2, Shard::ALL, None)).unwrap();
    assert_eq!((s.resumed, s.ran), (1, 4));
    assert_eq!(records(&dir), good);
}

/// Two runs into one directory lost or mixed records (two shards at once kept 40 of 80): now
/// the second is refused before any work, naming the directory and the run that holds it.
#[test]
fn a_directory_in_use_is_refused() {
    let (grid, _) = small();
    let dir = tmp("busy");
    std::fs::create_dir_all(&dir).unwrap();
    let held = DirLock::acquire(&dir, "sweep shard 0/2").unwrap();
    let e = run(&grid, &dir, options(1, Shard { index: 1, count: 2 }, None)).unwrap_err();
    assert!(matches!(e, SweepError::Busy { .. }), "{e}");
    let message = e.to_string();
    assert!(
        message.contains("sweep shard 0/2") && message.contains("in use"),
        "{message}"
    );
    assert!(!dir.join(RESULTS).exists());
    let e = cdpr_sweep::merge(&[tmp("nothing")], &dir, None).unwrap_err();
    assert!(matches!(e, SweepError::Busy { .. }), "{e}");
    drop(held);
    let s = run(&grid, &dir, options(1, Shard { index: 1, count: 2 }, None)).unwrap();
    assert_eq!(s.ran, 2);
}

/// An axis of 1e9 steps aborted on a 32 GB allocation while the grid was read, and two axes of
/// 1e5 steps checked points for hours: both are refused as the file is read, in milliseconds.
#[test]
fn grids_too_large_are_refused_as_they_are_read() {
    for (axes, needles) in [
        (
            "\"trajectory.t2\" = { from = 0.1, to = 0.5, steps = 1000000000 }",
            &["steps = 1000000000", "[1, 1000000]"][..],
        ),
        (
            "\"trajectory.t2\" = { from = 0.1, to = 0.5, steps = 100000 }\n\
             \"robot.effector_mass\" = { from = 0.5, to = 2.0, steps = 100000 }",
            &["1e10 points", "1000000 points"][..],
        ),
    ] {
        let started = Instant::now();
        let e = Grid::from_toml_str(&format!("[axes]\n{axes}"), "big")
            .unwrap_err()
            .to_string();
        assert!(started.elapsed() < Duration::from_millis(100));
        for n in needles {
            assert!(e.contains(n), "{n:?} not in: {e}");
        }
    }
}

/// Runs whose samples cannot fit were started and then killed by the OS (six 1e-6 points on six
/// workers need ~20 GB): the runs at once times the hungriest point's estimate are checked
/// against the machine before any work, naming the point, its sample period and the jobs that
/// fit.
#[test]
fn sweeps_that_cannot_fit_in_memory_are_refused() {
    let point =
        cdpr_bench::scenario_from_toml_str("[simulation]\nsample_period = 2.5e-7\n").unwrap();
    let each = cdpr_bench::memory::run_memory(&point).unwrap();
    assert!(
        each > 4e9,
        "2e7 samples of 18 channels and their spectra: {each} B"
    );
    let Some(available) = cdpr_bench::memory::available_memory() else {
        eprintln!("no /proc/meminfo: nothing to check against");
        return;
    };
    // Enough of them at once to need twice the available memory.
    let jobs = (2.0 * available / each).ceil() as usize + 1;
    assert!(
        jobs <= 64,
        "a machine of {available} B: the grid would be too long to write"
    );
    let masses: Vec<String> = (0..jobs)
        .map(|k| format!("{:.3}", 1.0 + 0.001 * k as f64))
        .collect();
    let grid = Grid::from_toml_str(
        &format!(
            "[scenario]\nanalysis = {{ modes = \"off\" }}\nsimulation = {{ sample_period = 2.5e-7 }}\n\
             [axes]\n\"robot.effector_mass\" = [{}]\n",
            masses.join(", ")
        ),
        "memory",
    )
    .unwrap();
    let dir = tmp("memory");
    let started = Instant::now();
    let e = run(&grid, &dir, options(jobs, Shard::ALL, None)).unwrap_err();
    assert!(
        started.elapsed() < Duration::from_secs(5),
        "refused before the runs"
    );
    assert!(matches!(e, SweepError::Memory(_)), "{e}");
    let message = e.to_string();
    for n in ["point 0", "sample_period = 0.00000025", "GB", "--jobs"] {
        assert!(message.contains(n), "{n:?} not in: {message}");
    }
    assert!(!dir.join(RESULTS).exists());
}

/// SIGINT during the check of a million points was ignored for its whole length: the check
/// stops within a point's check of the flag.
#[test]
fn the_check_of_a_large_grid_stops_when_asked() {
    let grid = Grid::from_toml_str(
        "[axes]\n\"trajectory.t2\" = { from = 0.1, to = 0.5, steps = 1000 }\n\
         \"robot.effector_mass\" = { from = 0.5, to = 2.0, steps = 1000 }\n",
        "million",
    )
    .unwrap();
    assert_eq!(grid.len(), 1_000_000);
    let stop = AtomicBool::new(false);
    let dir = tmp("stop-check");
    let started = Instant::now();
    let result = std::thread::scope(|scope| {
        scope.spawn(|| {
            std::thread::sleep(Duration::from_millis(300));
            stop.store(true, Ordering::Relaxed);
        });
        run(&grid, &dir, options(2, Shard::ALL, Some(&stop)))
    });
    let elapsed = started.elapsed();
    assert!(
        matches!(result, Err(SweepError::Interrupted(_))),
        "{result:?}"
    );
    assert!(elapsed < Duration::from_millis(1300), "{elapsed:?}");
    assert!(!dir.join(RESULTS).exists());
}
