//! `cargo xtask distribution` as a printer builder uses it: the example robots' statics at a
//! pose, checked against the balance and the box, and the named errors of bad robots.

mod common;

use common::TempDir;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/robots")
        .join(name)
}

fn distribution(scenario: &Path, at: &str, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["distribution", "--scenario"])
        .arg(scenario)
        .args(["--at", at, "--out"])
        .arg(out)
        .output()
        .unwrap()
}

/// Hangprinter at (0, 0, 0.3) m and CoGiRo at (0, 0, 2) m: every method's tensions balance the
/// weight along the cable directions computed here from the anchors, and the feasible ones keep
/// the file's box; the margin is positive and no larger than half the box.
#[test]
fn example_robots_hold_their_weight() {
    let dir = TempDir::new("distribution");
    for (file, at, pose, mass, (t_min, t_max), anchors) in [
        (
            "hangprinter.toml",
            "0,0,0.3",
            [0.0, 0.0, 0.3],
            1.0,
            (10.0, 70.0),
            vec![
                [0.0, -1.61098, -0.13153],
                [1.31422, 1.26814, -0.12128],
                [-1.41573, 0.70761, -0.12182],
                [0.0, 0.0, 2.29983],
            ],
        ),
        (
            "cogiro.toml",
            "0,0,2",
            [0.0, 0.0, 2.0],
            91.058,
            (100.0, 5000.0),
            vec![
                [-7.6807, -4.9433, 5.3911],
                [-6.9497, -5.5012, 4.4023],
                [-6.8879, 5.4640, 5.3976],
                [-7.5986, 5.1192, 4.4098],
                [7.7430, 4.8831, 5.4093],
                [7.0210, 5.4255, 4.4209],
                [6.9440, -5.5289, 5.3881],
                [7.6653, -5.1879, 4.3997],
            ],
        ),
    ] {
        let out = dir.join(file);
        let output = distribution(&example(file), at, &out);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("distribution.json")).unwrap())
                .unwrap();
        let weight = mass * 9.81;
        for (name, m) in json["methods"].as_object().unwrap() {
            let t: Vec<f64> = m["tensions"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert_eq!(t.len(), anchors.len());
            let mut force = [0.0; 3];
            for (ti, a) in t.iter().zip(&anchors) {
                let d: Vec<f64> = (0..3).map(|k| a[k] - pose[k]).collect();
                let l = d.iter().map(|v| v * v).sum::<f64>().sqrt();
                for k in 0..3 {
                    force[k] += ti * d[k] / l;
                }
            }
            let residual =
                (force[0].powi(2) + force[1].powi(2) + (force[2] - weight).powi(2)).sqrt();
            // Anchors in the file have 5 digits, as here: the balance holds to round-off.
            assert!(
                residual < 1e-9 * (weight + t_max),
                "{file} {name}: {residual}"
            );
            if m["feasible"].as_bool().unwrap() {
                assert!(
                    t.iter().all(|&v| v >= t_min - 1e-9 && v <= t_max + 1e-9),
                    "{file} {name}: {t:?}"
                );
            }
        }
        let margin = json["margin"].as_f64().unwrap();
        assert!(
            margin > 0.0 && margin <= 0.5 * (t_max - t_min),
            "{file}: {margin}"
        );
        assert_eq!(json["methods"]["qp"]["feasible"], true);
    }
}

/// Bad robots are named before any work: too many anchors, two at one point, a NaN, a pose on an
/// anchor.
#[test]
fn bad_robots_get_named_errors() {
    let dir = TempDir::new("distribution-errors");
    let box_keys = "[controller]\nt_min = 10.0\nt_max = 70.0\n";
    let cases = [
        (
            "nine.toml",
            format!(
                "[robot]\nanchors = [{}]\n{box_keys}",
                ["[0.0, 0.0, 1.0]"; 9].join(", ")
            ),
            "2 to 8 anchors",
        ),
        (
            "twice.toml",
            format!(
                "[robot]\nanchors = [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]\n{box_keys}"
            ),
            "anchors 1 and 2",
        ),
        (
            "line.toml",
            format!(
                "[robot]\nanchors = [[0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [0.0, 0.0, 3.0]]\n{box_keys}"
            ),
            "collinear",
        ),
        (
            "flat.toml",
            format!("[robot]\nanchors = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]\n{box_keys}"),
            "two 2-vectors",
        ),
        (
            "nobox.toml",
            "[robot]\nanchors = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]]\n".to_string(),
            "controller.t_min, controller.t_max",
        ),
    ];
    for (file, text, expected) in cases {
        let path = dir.join(file);
        std::fs::write(&path, text).unwrap();
        let output = distribution(&path, "0,0,0", &dir.join("out"));
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{file}");
        assert!(
            stderr.contains("robot.anchors") || stderr.contains("controller.t_"),
            "{file}: {stderr}"
        );
        assert!(stderr.contains(expected), "{file}: {stderr}");
    }
    let on_anchor = distribution(
        &example("hangprinter.toml"),
        "0,0,2.29983",
        &dir.join("out"),
    );
    assert!(String::from_utf8_lossy(&on_anchor.stderr).contains("coincides with anchor 4"));
}
