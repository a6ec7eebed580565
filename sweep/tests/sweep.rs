//! Sweeps against what they must equal: the grid's enumeration against its definition (every
//! combination once, shards a partition), a sharded-and-merged sweep and a resumed sweep against
//! the one-machine sweep byte for byte (wall times aside), each point's record against a
//! separate run of its scenario, and every bad input as a named error before any point runs.

use cdpr_sweep::store::{RESULTS, RESULTS_CSV, read_records};
use cdpr_sweep::{Grid, Options, Shard, SweepError};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// A small elastic study: 3 masses × 2 move times, 1.2 s runs, modes off.
const GRID: &str = r#"
[scenario]
simulation = { t_final = 1.2 }
analysis = { modes = "off" }
[axes]
"robot.effector_mass" = [0.5, 1.0, 2.0]
"trajectory.t2" = { from = 0.15, to = 0.3, steps = 2 }
"#;

fn grid() -> Grid {
    Grid::from_toml_str(GRID, "test").unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cdpr-sweep-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn sweep(grid: &Grid, dir: &Path, jobs: usize, shard: Shard) -> cdpr_sweep::Summary {
    cdpr_sweep::run(
        grid,
        dir,
        Options {
            jobs,
            shard,
            stop: None,
        },
        &mut |_| {},
    )
    .unwrap()
}

/// The file with every `"wall_s":…` value (JSONL) or last CSV column blanked.
fn without_wall(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .map(|line| match line.find("\"wall_s\":") {
            Some(at) => line[..at].to_string(),
            None => match line.rfind(',') {
                Some(at) if path.extension().is_some_and(|e| e == "csv") => line[..at].into(),
                _ => line.into(),
            },
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn shards_merged_and_resumed_sweeps_equal_the_one_machine_sweep() {
    let g = grid();
    let whole = tmp("whole");
    let s = sweep(&g, &whole, 2, Shard::ALL);
    assert_eq!(
        (s.shard_points, s.ran, s.failed, s.interrupted),
        (6, 6, 0, false)
    );

    let shards: Vec<PathBuf> = (0..4)
        .map(|i| {
            let dir = tmp(&format!("shard{i}"));
            let shard = Shard { index: i, count: 4 };
            let s = sweep(&g, &dir, 1, shard);
            assert_eq!(s.shard_points, (0..6).filter(|p| p % 4 == i).count());
            dir
        })
        .collect();
    let merged = tmp("merged");
    let (_, n) = cdpr_sweep::merge(&shards, &merged, None).unwrap();
    assert_eq!(n, 6);
    for file in [RESULTS, RESULTS_CSV] {
        assert_eq!(
            without_wall(&whole.join(file)),
            without_wall(&merged.join(file)),
            "{file}: merged shards differ from the one-machine sweep"
        );
    }

    // Two shards run one after the other into one directory: the second keeps the first's
    // records, and together they are the whole sweep.
    let shared = tmp("shared");
    let first = sweep(&g, &shared, 1, Shard { index: 0, count: 2 });
    let second = sweep(&g, &shared, 1, Shard { index: 1, count: 2 });
    assert_eq!((first.ran, second.ran, second.resumed), (3, 3, 0));
    assert_eq!(
        without_wall(&whole.join(RESULTS)),
        without_wall(&shared.join(RESULTS))
    );

    // An interrupted sweep: the header, two records and a torn line. The resume runs the four
    // points left and ends with the same file.
    let resumed = tmp("resumed");
    std::fs::create_dir_all(&resumed).unwrap();
    let text = std::fs::read_to_string(whole.join(RESULTS)).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let torn = format!(
        "{}\n{}\n{}\n{}",
        lines[0],
        lines[1],
        lines[4],
        &lines[2][..40]
    );
    std::fs::write(resumed.join(RESULTS), torn).unwrap();
    let s = sweep(&g, &resumed, 2, Shard::ALL);
    assert_eq!((s.resumed, s.ran), (2, 4));
    assert_eq!(
        without_wall(&whole.join(RESULTS)),
        without_wall(&resumed.join(RESULTS))
    );
    // Nothing left: a second resume runs nothing and changes nothing.
    let s = sweep(&g, &resumed, 2, Shard::ALL);
    assert_eq!((s.resumed, s.ran), (6, 0));
}

/// A record's metrics are those of its scenario run on its own, bit for bit.
#[test]
fn a_record_is_its_scenario_s_own_run() {
    let g = grid();
    let record = cdpr_sweep::evaluate(&g, 3, None).unwrap();
    assert_eq!(record.params["robot.effector_mass"], 1.0);
    assert_eq!(record.params["trajectory.t2"], 0.3);
    let scenario = cdpr_sweep::point::scenario(&g, &g.point(3)).unwrap();
    assert_eq!(scenario.robot.effector_mass, 1.0);
    assert_eq!(scenario.trajectory.t2, 0.3);
    let assessed = cdpr_bench::assess(&scenario, &mut |_| {}).unwrap();
    let mut own = cdpr_sweep::metrics_map(&scenario, &assessed);
    own.remove("wall_s");
    assert_eq!(record.metrics, own);
    assert_eq!(record.t_reached, 1.2);
}

/// A point whose run fails (a 20 ms move slackens a cable, MODELS.md §2) is recorded with its
/// error and the time it failed at, and the sweep goes on.
#[test]
fn a_failed_point_is_recorded_and_the_sweep_goes_on() {
    let g = Grid::from_toml_str(
        r#"
        [scenario]
        simulation = { t_final = 0.5 }
        analysis = { modes = "off" }
        [axes]
        "trajectory.t2" = [0.02, 0.3]
        "#,
        "test",
    )
    .unwrap();
    let dir = tmp("failed");
    let s = sweep(&g, &dir, 2, Shard::ALL);
    assert_eq!((s.ran, s.failed), (2, 1));
    let (_, mut records) = read_records(&dir.join(RESULTS)).unwrap();
    records.sort_by_key(|r| r.point);
    let failed = &records[0];
    assert_eq!(failed.status, "failed");
    let error = failed.error.as_deref().unwrap();
    assert!(error.contains("slack"), "{error}");
    assert!(
        failed.t_reached > 0.0 && failed.t_reached < 0.02,
        "{}",
        failed.t_reached
    );
    assert_eq!(records[1].status, "complete");
}

fn grid_error(text: &str) -> String {
    Grid::from_toml_str(text, "g.toml").unwrap_err().to_string()
}

#[test]
fn bad_grids_are_named_errors() {
    let cases = [
        ("[axes]\n\"robot.effector_mass\" = []", "has no points"),
        ("[scenario]\n", "at least one scenario key"),
        (
            "[axes]\n\"trajectory.t2\" = { from = 0.1, to = 0.5 }",
            "needs `steps`",
        ),
        (
            "[axes]\n\"trajectory.t2\" = { from = 0.1, to = 0.5, steps = 0 }",
            "steps = 0",
        ),
        (
            "[axes]\n\"trajectory.t2\" = { from = 0.0, to = 0.5, steps = 3, scale = \"log\" }",
            "log range needs from > 0",
        ),
        (
            "[axes]\n\"trajectory.t2\" = { from = 0.1, to = 0.5, steps = 3, scale = \"cubic\" }",
            "scale = \"cubic\"",
        ),
        (
            "[axes]\n\"a.b\" = [1, 2]\n\"c.d\" = [1]\n[sweep]\ncombine = \"zip\"",
            "needs axes of one length",
        ),
        (
            "[axes]\n\"a.b\" = [1]\n[sweep]\ncombine = \"cross\"",
            "sweep.combine",
        ),
        (
            "[axes]\n\"a.b\" = [1]\n[extra]\nx = 1",
            "unknown section [extra]",
        ),
        ("[axes\n", "g.toml"),
    ];
    for (text, needle) in cases {
        let e = grid_error(text);
        assert!(e.contains(needle), "{text:?}: {e}");
        assert!(e.starts_with("grid g.toml"), "{e}");
    }
}

/// An unknown key and a value outside its range name the point, the key and the range, before
/// any point runs (no results file is written).
#[test]
fn bad_points_are_refused_before_any_work() {
    for (axes, needles) in [
        (
            "\"robot.effector_mas\" = [1.0]",
            &["point 0", "effector_mas"][..],
        ),
        (
            "\"robot.effector_mass\" = [1.0, -2.0]",
            &[
                "point 1",
                "robot.effector_mass = -2.0",
                "robot.effector_mass",
                "allowed",
            ],
        ),
        ("\"robot\" = [1.0]", &["dotted path"]),
    ] {
        let g = Grid::from_toml_str(&format!("[axes]\n{axes}"), "test").unwrap();
        let dir = tmp("refused");
        let e = cdpr_sweep::run(
            &g,
            &dir,
            Options {
                jobs: 1,
                shard: Shard::ALL,
                stop: None,
            },
            &mut |_| {},
        )
        .unwrap_err();
        assert!(matches!(e, SweepError::Point { .. }), "{e}");
        let message = e.to_string();
        for n in needles {
            assert!(message.contains(n), "{axes}: {message}");
        }
        assert!(
            !dir.join(RESULTS).exists(),
            "nothing written before the check"
        );
    }
}

#[test]
fn bad_shards_and_foreign_results_are_named_errors() {
    for (given, needle) in [
        ("3/2", "I must be < N"),
        ("0/0", "N must be ≥ 1"),
        ("1-4", "I/N"),
        ("a/4", "integers"),
    ] {
        let e = given.parse::<Shard>().unwrap_err().to_string();
        assert!(e.contains(needle) && e.contains(given), "{e}");
    }
    let dir = tmp("foreign");
    std::fs::create_dir_all(&dir).unwrap();
    let other = Grid::from_toml_str("[axes]\n\"robot.effector_mass\" = [1.0]", "x").unwrap();
    let options = Options {
        jobs: 1,
        shard: Shard::ALL,
        stop: None,
    };
    for (content, needle) in [
        (
            "{\"cdpr_sweep\":1,\"grid\":\"0\",\"points\":6}\n",
            "no format-2 header",
        ),
        (
            &format!(
                "{}\n",
                serde_json::to_string(&cdpr_sweep::Header::of(&grid())).unwrap()
            ),
            "another grid",
        ),
        ("time,x\n0,1\n", "no format-2 header"),
        (
            &format!(
                "{}\nnot json\n{{}}\n",
                serde_json::to_string(&cdpr_sweep::Header::of(&other)).unwrap()
            ),
            "line 2: not a record",
        ),
    ] {
        std::fs::write(dir.join(RESULTS), content).unwrap();
        let e = cdpr_sweep::run(&other, &dir, options, &mut |_| {})
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle) && e.contains(RESULTS), "{e}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Over axis counts 1–4 of 1–5 points and shard counts 1–7: the points are every
    /// combination exactly once, in mixed-radix order (last axis fastest), and the shards
    /// partition them; zip takes the k-th value of every axis.
    #[test]
    fn points_enumerate_the_combinations_and_shards_partition_them(
        lengths in proptest::collection::vec(1usize..6, 1..5),
        count in 1usize..8,
    ) {
        let axes: String = lengths
            .iter()
            .enumerate()
            .map(|(k, n)| format!("\"s.k{k}\" = {:?}\n", (0..*n).collect::<Vec<_>>()))
            .collect();
        let g = Grid::from_toml_str(&format!("[axes]\n{axes}"), "p").unwrap();
        let total: usize = lengths.iter().product();
        prop_assert_eq!(g.len(), total);
        let mut seen = std::collections::HashSet::new();
        for i in 0..total {
            let digits: Vec<i64> = g.point(i).values.iter().map(|(_, v)| v.as_integer().unwrap()).collect();
            let mut index = 0usize;
            for (d, n) in digits.iter().zip(&lengths) {
                index = index * n + *d as usize;
            }
            prop_assert_eq!(index, i);
            prop_assert!(seen.insert(digits));
            let owners = (0..count).filter(|&s| Shard { index: s, count }.owns(i)).count();
            prop_assert_eq!(owners, 1);
        }
        let n = lengths[0];
        let zip = Grid::from_toml_str(
            &format!("[axes]\n\"s.a\" = {:?}\n\"s.b\" = {:?}\n[sweep]\ncombine = \"zip\"", (0..n).collect::<Vec<_>>(), (0..n).map(|k| 10 * k).collect::<Vec<_>>()),
            "z",
        ).unwrap();
        prop_assert_eq!(zip.len(), n);
        for k in 0..n {
            let v = zip.point(k).values;
            prop_assert_eq!(v[0].1.as_integer(), Some(k as i64));
            prop_assert_eq!(v[1].1.as_integer(), Some(10 * k as i64));
        }
    }

    /// A range has its `steps` points, both ends exact, linear steps equal and log steps of one
    /// ratio (to 1e-12 relative: a few roundings of ln and exp).
    #[test]
    fn ranges_are_evenly_spaced(from in 0.01f64..10.0, span in 0.1f64..100.0, steps in 2usize..40, log in any::<bool>()) {
        let to = from + span;
        let scale = if log { "log" } else { "linear" };
        let g = Grid::from_toml_str(
            &format!("[axes]\n\"s.k\" = {{ from = {from:?}, to = {to:?}, steps = {steps}, scale = \"{scale}\" }}"),
            "r",
        ).unwrap();
        let v: Vec<f64> = (0..steps).map(|i| g.point(i).values[0].1.as_float().unwrap()).collect();
        prop_assert_eq!(v.len(), steps);
        prop_assert_eq!(v[0], from);
        prop_assert_eq!(v[steps - 1], to);
        for w in v.windows(3) {
            if log {
                prop_assert!(((w[2] / w[1]) / (w[1] / w[0]) - 1.0).abs() < 1e-12);
            } else {
                prop_assert!(((w[2] - w[1]) - (w[1] - w[0])).abs() < 1e-12 * to);
            }
        }
    }
}

/// A spatial robot swept over an array element: the height of Hangprinter's top anchor
/// (`robot.anchors[3][2]`, 0-based) and the end's x (`trajectory.end[0]`). Each record is its
/// scenario's own spatial run (the scenario built here by editing the anchors by hand), and the
/// sweep's records equal across thread counts.
#[test]
fn spatial_points_sweep_array_elements() {
    let text = r#"
[scenario]
robot = { anchors = [[0.0, -1.61098, -0.13153], [1.31422, 1.26814, -0.12128], [-1.41573, 0.70761, -0.12182], [0.0, 0.0, 2.29983]], effector_mass = 1.0 }
cable = { youngs_modulus = 2.105e10, area = 9.503e-7 }
controller = { kind = "computed-torque", t_min = 10.0, t_max = 70.0 }
trajectory = { start = [0.0, 0.0, 0.0], end = [0.1, 0.05, 0.02], t2 = 0.2 }
simulation = { t_final = 1.3, sample_period = 1e-3 }
[axes]
"robot.anchors[3][2]" = [1.8, 2.29983, 3.0]
"trajectory.end[0]" = [0.05, 0.1]
"#;
    let g = Grid::from_toml_str(text, "test").unwrap();
    assert_eq!(g.len(), 6);
    let record = cdpr_sweep::evaluate(&g, 1, None).unwrap();
    assert_eq!(record.status, "complete", "{:?}", record.error);
    assert_eq!(record.params["robot.anchors[3][2]"], 1.8);
    assert_eq!(record.params["trajectory.end[0]"], 0.1);
    let scenario = cdpr_bench::scenario_from_toml_str(
        "[robot]\nanchors = [[0.0, -1.61098, -0.13153], [1.31422, 1.26814, -0.12128], \
         [-1.41573, 0.70761, -0.12182], [0.0, 0.0, 1.8]]\neffector_mass = 1.0\n\
         [cable]\nyoungs_modulus = 2.105e10\narea = 9.503e-7\n\
         [controller]\nkind = \"computed-torque\"\nt_min = 10.0\nt_max = 70.0\n\
         [trajectory]\nstart = [0.0, 0.0, 0.0]\nend = [0.1, 0.05, 0.02]\nt2 = 0.2\n\
         [simulation]\nt_final = 1.3\nsample_period = 1e-3\n",
    )
    .unwrap();
    let own = cdpr_bench::simulate_spatial(
        &scenario,
        &mut cdpr_bench::core::runner::Observer::progress(&mut |_| {}),
    )
    .unwrap();
    let own_metrics = serde_json::to_value(&own.metrics).unwrap();
    for (key, value) in own_metrics.as_object().unwrap() {
        assert_eq!(&record.metrics[key], value, "{key}");
    }
    assert_eq!(record.metrics["steps"], own.run.stats.steps_accepted);
    let (one, two) = (tmp("spatial-1"), tmp("spatial-2"));
    sweep(&g, &one, 1, Shard::ALL);
    sweep(&g, &two, 2, Shard::ALL);
    assert_eq!(
        without_wall(&one.join(RESULTS)),
        without_wall(&two.join(RESULTS))
    );
    let bad = Grid::from_toml_str(&text.replace("anchors[3][2]", "anchors[4][2]"), "test").unwrap();
    let err = cdpr_sweep::point::scenario(&bad, &bad.point(0))
        .unwrap_err()
        .to_string();
    assert!(err.contains("index 4 outside an array of 4"), "{err}");
}
