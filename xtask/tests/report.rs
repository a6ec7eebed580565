//! `cargo xtask report` into a temporary directory reproduces the committed `reports/` bit for
//! bit — every file, figure and number, but for the wall times and the compiler and revision it
//! names — and its files are whole: the PNGs decode at the right size, the SVGs parse, REPORT.md
//! has a row per §8 quantity and model.
//!
//! One run checks both that the report is the same from run to run and that the committed one
//! is what this code writes; a regenerated `reports/` belongs in the commit that changes a
//! number.

mod common;

use common::TempDir;
use std::path::{Path, PathBuf};
use std::process::Command;

const FIGURES: [&str; 17] = [
    "print-frontier",
    "spatial_hangprinter_modes",
    "spatial_hangprinter_flex",
    "spatial_hangprinter_rest",
    "spatial_hangprinter_move",
    "spatial_cogiro_modes",
    "spatial_cogiro_flex",
    "spatial_cogiro_rest",
    "sweep_z_p2p",
    "sweep_err_transition",
    "sweep_shaper_z_p2p",
    "sweep_shaper_err_transition",
    "fig5_position",
    "fig6_error",
    "fig7_spectrum",
    "fig8_tensions",
    "step5_reference",
];

/// The per-model quantities of MODELS.md §8 (the report's row names).
const QUANTITIES: [&str; 14] = [
    "T1 minimum",
    "T1 maximum",
    "T1 settled (mean over [4, 5] s)",
    "T2 settled (mean over [4, 5] s)",
    "T1(5 s), T2(5 s)",
    "max \\|error\\| in the transition [0, 0.2] s",
    "overshoot",
    "max \\|error\\| over [1, 5] s",
    "max \\|error\\| over [1.5, 5] s",
    "z peak-to-peak over [1, 5] s",
    "z refined spectral peak over [1, 5] s",
    "error refined spectral peak over [1, 5] s",
    "plain FFT peak of z over [0, 5] s",
    "high-frequency content of the error spectrum",
];

/// The committed report (`cargo xtask report` at the repository's root).
fn committed() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../reports")
}

#[test]
fn report_reproduces_the_committed_report() {
    let dir = TempDir::new("report");
    let out = dir.join("out");
    let output = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["report", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");

    for name in FIGURES {
        let png = image::open(out.join(format!("{name}.png"))).unwrap();
        assert_eq!((png.width(), png.height()), (1920, 1280), "{name}.png");
        let svg = std::fs::read_to_string(out.join(format!("{name}.svg"))).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{name}.svg: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg");
        assert!(
            svg.contains("<path") || svg.contains("<polyline"),
            "{name}.svg has curves"
        );
    }

    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    let models: Vec<String> = json["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["model"].as_str().unwrap().to_owned())
        .collect();
    assert!(
        models.contains(&"elastic".to_owned()) && models.contains(&"lumped".to_owned()),
        "{models:?}"
    );
    for model in &models {
        for q in QUANTITIES {
            let row = format!("| {q} | {model} |");
            assert!(md.contains(&row), "REPORT.md lacks the row `{row}`");
        }
    }
    assert!(md.contains("| eq. 15 at x = 0.6 | all |"));
    // The modes section and its files.
    assert!(md.contains("## Modes of every model\n"));
    assert!(md.contains("| lumped | 0.6 | closed | vertical |"));
    assert!(out.join("modes.csv").exists() && out.join("damping_sweep.csv").exists());
    for name in FIGURES {
        assert!(
            md.contains(&format!("({name}.svg)")),
            "REPORT.md embeds {name}"
        );
    }
    // The spatial section: its study and its animation.
    assert!(md.contains("## What the lines' mass does to a printer\n"));
    let spatial: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("spatial.json")).unwrap()).unwrap();
    assert_eq!(spatial["printers"].as_array().unwrap().len(), 2);
    // Elastic, lumped and FE cables.
    assert_eq!(spatial["leaderboard"].as_array().unwrap().len(), 3);
    let gif = std::fs::File::open(out.join("spatial_hangprinter_move.gif")).unwrap();
    let frames = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(gif))
        .and_then(|d| image::AnimationDecoder::into_frames(d).collect_frames())
        .unwrap();
    // The Hangprinter move's 1.2 s, a frame every 0.04 s from t = 0.
    assert_eq!(frames.len(), 31, "frames of the move's GIF");
    // The print study: the cube on the massive lines at 3 000 mm/s², every setup printed to its
    // end; the tension controllers there within 3 µm of the elastic prints (the lines' 3 g
    // against the 1 kg effector change the 35 µm error by ~1 µm: 0.2–1.1 µm measured).
    let study: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("print-study.json")).unwrap())
            .unwrap();
    let rows = study["rows"].as_array().unwrap();
    let unshaped = |model: &str, setup: &str| {
        rows.iter()
            .find(|r| {
                r["model"] == model
                    && r["part"] == rows[0]["part"]
                    && r["setup"] == setup
                    && r["accel_mm_s2"] == 3000.0
                    && r["shaper"] == "none"
            })
            .unwrap_or_else(|| panic!("no {model} {setup} print"))
    };
    for model in ["lumped", "fe"] {
        let massive: Vec<_> = rows.iter().filter(|r| r["model"] == model).collect();
        assert_eq!(
            massive.len(),
            10,
            "{model}: five setups, unshaped and shaped"
        );
        assert!(
            massive.iter().all(|r| r.get("stopped").is_none()),
            "{model}: a print stopped"
        );
        for setup in ["computed-torque", "lqr"] {
            let [a, b] = [model, "elastic"].map(|m| {
                unshaped(m, setup)["contour_err_max_printing"]
                    .as_f64()
                    .unwrap()
            });
            assert!(
                (a - b).abs() <= 3e-6,
                "{model} {setup}: {a} m against elastic {b} m"
            );
        }
    }
    shaping_study_is_sound(&out);
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");

    let differences = differences(&out, &committed());
    assert!(
        differences.is_empty(),
        "the report differs from the committed reports/ (regenerate it with `cargo xtask report` \
         in the commit that changes its numbers):\n{}",
        differences.join("\n")
    );
}

/// The shaping section (`cargo xtask shaping`'s study on the paper scenario): every shaper on
/// every model over the frequency-error sweep (7 shapers × 3 models × 17 errors); at its design
/// frequency ZV's analytic residual vanishes (1e-9 %: the impulses' round-off) and every shaper's
/// simulated residual is below the unshaped run's (100 %); a table row per shaper and model, and
/// a figure per model.
fn shaping_study_is_sound(out: &Path) {
    let csv = std::fs::read_to_string(out.join("shaping.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(csv_fields).collect();
    assert_eq!(rows.len(), 7 * 3 * 17);
    for r in &rows {
        let residual: f64 = r[6].parse().unwrap();
        assert!(residual.is_finite() && residual > 0.0, "{r:?}");
        if r[1] == "zv" && r[2] == "0" {
            let v: f64 = r[7].parse().unwrap();
            assert!(v < 1e-9, "ZV at its design: V = {v} %");
        }
        if r[2] == "0" {
            assert!(residual < 100.0, "{r:?}");
        }
    }
    let md = std::fs::read_to_string(out.join("shaping.md")).unwrap();
    assert!(md.contains("| 2hump-ei | lumped |") && md.contains("What limits shaping"));
    for model in ["elastic", "lumped", "fe"] {
        assert!(out.join(format!("shaping_{model}.png")).exists());
    }
}

/// Committed files that `cargo xtask report` does not write (`cargo xtask work-precision`'s).
const NOT_THE_REPORTS: [&str; 3] = [
    "work_precision.csv",
    "work_precision.svg",
    "work_precision.png",
];

/// Every way the report in `fresh` differs from the committed one in `committed`, machine-free
/// (see [`machine_free`]): a file one side lacks, or the first line that differs.
fn differences(fresh: &Path, committed: &Path) -> Vec<String> {
    let (fresh_files, committed_files) = (files(fresh), files(committed));
    let mut found = Vec::new();
    for name in &committed_files {
        if !fresh_files.contains(name) && !NOT_THE_REPORTS.contains(&name.as_str()) {
            found.push(format!("{name}: committed, not written"));
        }
    }
    for name in &fresh_files {
        if !committed_files.contains(name) {
            found.push(format!("{name}: written, not committed"));
            continue;
        }
        let [a, b] = [fresh, committed]
            .map(|root| machine_free(name, &std::fs::read(root.join(name)).unwrap()));
        if a != b {
            let line = a
                .split(|&c| c == b'\n')
                .zip(b.split(|&c| c == b'\n'))
                .position(|(x, y)| x != y)
                .map_or("the length".to_owned(), |i| format!("line {}", i + 1));
            found.push(format!("{name}: differs at {line}"));
        }
    }
    found
}

/// The files under `root`, as `/`-separated paths relative to it, sorted.
fn files(root: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut dirs = vec![PathBuf::new()];
    while let Some(rel) = dirs.pop() {
        for entry in std::fs::read_dir(root.join(&rel)).unwrap() {
            let entry = entry.unwrap();
            let path = rel.join(entry.file_name());
            if entry.file_type().unwrap().is_dir() {
                dirs.push(path);
            } else {
                found.push(path.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    found.sort();
    found
}

/// Markdown columns that hold wall times, or ratios of them.
const WALL_COLUMNS: [&str; 3] = ["wall [s]", "wall time [s]", "cost / PID"];

/// `bytes` of the report file `name` without what depends on the machine and the checkout: the
/// wall times (JSON's `wall_s`, the CSV column `wall_s`, the Markdown tables' [`WALL_COLUMNS`],
/// a study's "N points in W s on C cores.") and the Software section's revision and compiler.
/// Every other byte is kept.
fn machine_free(name: &str, bytes: &[u8]) -> Vec<u8> {
    let text = || String::from_utf8(bytes.to_vec()).unwrap();
    let kept = match Path::new(name).extension().and_then(|e| e.to_str()) {
        Some("json") => without_wall(serde_json::from_slice(bytes).unwrap()).to_string(),
        Some("jsonl") => text()
            .lines()
            .map(|l| without_wall(serde_json::from_str(l).unwrap()).to_string() + "\n")
            .collect(),
        Some("csv") => csv_without_wall(&text()),
        Some("md") => markdown_without_wall(&text()),
        _ => return bytes.to_vec(),
    };
    kept.into_bytes()
}

fn without_wall(mut value: serde_json::Value) -> serde_json::Value {
    match &mut value {
        serde_json::Value::Object(map) => {
            map.remove("wall_s");
            for v in map.values_mut() {
                *v = without_wall(v.take());
            }
        }
        serde_json::Value::Array(items) => {
            for v in items {
                *v = without_wall(v.take());
            }
        }
        _ => {}
    }
    value
}

/// A CSV's `wall_s` column emptied (fields may be quoted and hold commas).
fn csv_without_wall(text: &str) -> String {
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    let Some(wall) = csv_fields(header).iter().position(|f| *f == "wall_s") else {
        return text.to_owned();
    };
    std::iter::once(header)
        .chain(lines)
        .map(|line| blanked(csv_fields(line), &[wall], ","))
        .collect()
}

/// `parts` joined by `separator` into a line, with those at `columns` emptied.
fn blanked(mut parts: Vec<&str>, columns: &[usize], separator: &str) -> String {
    for &i in columns {
        if let Some(part) = parts.get_mut(i) {
            *part = "";
        }
    }
    parts.join(separator) + "\n"
}

/// A CSV line's fields (a quoted field may hold commas).
fn csv_fields(line: &str) -> Vec<&str> {
    let mut quoted = false;
    split_unshielded(line, ',', |c| {
        quoted ^= c == '"';
        quoted
    })
}

/// A Markdown file with its tables' [`WALL_COLUMNS`] emptied, a study's wall time and cores cut
/// from "N points in W s on C cores.", and the Software section's revision and compiler lines
/// replaced by their first words.
fn markdown_without_wall(text: &str) -> String {
    let mut kept = String::new();
    let mut wall: Vec<usize> = Vec::new();
    let mut in_table = false;
    for line in text.lines() {
        if line.starts_with("- cdpr-bench ") || line.starts_with("- rustc ") {
            kept += &(line.split(' ').take(2).collect::<Vec<_>>().join(" ") + "\n");
            continue;
        }
        if let Some((points, _)) = line.split_once(" points in ")
            && line.ends_with(" cores.")
        {
            kept += &(points.to_owned() + " points\n");
            continue;
        }
        if !line.starts_with('|') {
            in_table = false;
            kept += &(line.to_owned() + "\n");
            continue;
        }
        let cells = markdown_cells(line);
        if in_table {
            kept += &blanked(cells, &wall, "|");
        } else {
            // The header row names the columns to empty in the rows below it.
            in_table = true;
            wall = (0..cells.len())
                .filter(|&i| WALL_COLUMNS.contains(&cells[i].trim()))
                .collect();
            kept += &blanked(cells, &[], "|");
        }
    }
    kept
}

/// A table row split at its unescaped `|` (a cell may hold `\|`).
fn markdown_cells(line: &str) -> Vec<&str> {
    let mut escaped = false;
    split_unshielded(line, '|', |c| {
        let shielded = escaped;
        escaped = c == '\\' && !escaped;
        shielded
    })
}

/// `line` split at each `separator` that `shielded` does not protect; `shielded` sees every
/// character in turn and says whether it is protected.
fn split_unshielded(
    line: &str,
    separator: char,
    mut shielded: impl FnMut(char) -> bool,
) -> Vec<&str> {
    let (mut parts, mut start) = (Vec::new(), 0);
    for (i, c) in line.char_indices() {
        if !shielded(c) && c == separator {
            parts.push(&line[start..i]);
            start = i + 1;
        }
    }
    parts.push(&line[start..]);
    parts
}
