//! The report's parameter studies (`examples/sweeps/*mass_time_*.toml`): the paper's move on each
//! cable model over effector mass 0.25–4 kg × move time 0.1–0.5 s, once per controller (the
//! paper's PID, the LQR) and once per input shaper on the PID (none, ZVD, 2-hump EI). Runs the
//! grids with `cdpr-sweep` into `DIR/sweeps/`, draws heat maps of the vertical residual vibration
//! and the transition error, and writes the REPORT.md section.

use crate::{Result, StudyError};
use cdpr_bench::ModelKind;
use cdpr_bench::core::scenario::Scenario;
use cdpr_sweep::{Grid, Options, Record, Shard};
use std::path::{Path, PathBuf};

pub const MASS: &str = "robot.effector_mass";
pub const MOVE: &str = "trajectory.t2";

/// One study: its grid files' stem, the axis whose values make the heat maps' rows, and the
/// prefix of its figures.
#[derive(Clone, Copy)]
pub struct Spec {
    pub stem: &'static str,
    pub group_key: &'static str,
    pub groups: &'static [&'static str],
    pub figure_prefix: &'static str,
    pub what: &'static str,
}

/// The report's two studies.
pub const STUDIES: [Spec; 2] = [
    Spec {
        stem: "mass_time",
        group_key: "controller.kind",
        groups: &["pid", "lqr"],
        figure_prefix: "sweep",
        what: "the paper's PID and the LQR",
    },
    Spec {
        stem: "shaper_mass_time",
        group_key: "trajectory.shaper",
        groups: &["none", "zvd", "2hump-ei"],
        figure_prefix: "sweep_shaper",
        what: "the paper's PID unshaped and with ZVD and 2-hump EI shapers designed from the modal analysis",
    },
];

/// The metrics drawn: key, figure name suffix, title.
pub const METRICS: [(&str, &str, &str); 2] = [
    (
        "z_p2p",
        "z_p2p",
        "vertical residual vibration: z peak-to-peak over [t2 + 0.8 s, 5 s] [m]",
    ),
    (
        "err_max_transition",
        "err_transition",
        "transition error: max |x_ref − x| during the move [m]",
    ),
];

/// One model's grid and its records.
pub struct ModelSweep {
    pub kind: ModelKind,
    pub grid: Grid,
    pub records: Vec<Record>,
    pub wall_s: f64,
}

pub struct SweepStudy {
    pub spec: Spec,
    pub sweeps: Vec<ModelSweep>,
}

fn grid_path(spec: &Spec, kind: ModelKind) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/sweeps")
        .join(format!("{}_{}.toml", spec.stem, kind.name()))
}

/// Runs a study's three grids afresh into `out/sweeps/<stem>_<model>/` on every core, for the
/// report's `simulation.t_final` (5 s for the paper; shorter for a quick report).
pub fn compute(spec: Spec, base: &Scenario, out: &Path) -> Result<SweepStudy> {
    let mut sweeps = Vec::new();
    for kind in ModelKind::ALL {
        let path = grid_path(&spec, kind);
        let mut grid = Grid::from_file(&path).map_err(|e| StudyError::Sweep {
            what: format!("the grid {}", path.display()),
            source: e,
        })?;
        if let toml::Value::Table(simulation) = grid
            .base
            .entry("simulation")
            .or_insert_with(|| toml::Value::Table(Default::default()))
        {
            simulation.insert("t_final".into(), base.simulation.t_final.into());
        }
        let dir = out
            .join("sweeps")
            .join(format!("mass_time_{}", kind.name()));
        // A report is made afresh: an earlier report's records are not resumed.
        for file in [cdpr_sweep::store::RESULTS, cdpr_sweep::store::RESULTS_CSV] {
            let _ = std::fs::remove_file(dir.join(file));
        }
        let start = std::time::Instant::now();
        cdpr_sweep::run(
            &grid,
            &dir,
            Options {
                jobs: cdpr_sweep::all_cores(),
                shard: Shard::ALL,
                stop: None,
            },
            &mut |_| {},
        )
        .map_err(|e| StudyError::Sweep {
            what: format!("the {} sweep of {}", kind.name(), spec.stem),
            source: e,
        })?;
        let wall_s = start.elapsed().as_secs_f64();
        let results = dir.join(cdpr_sweep::store::RESULTS);
        let (_, records) =
            cdpr_sweep::store::read_records(&results).map_err(|e| StudyError::Sweep {
                what: format!("the records {}", results.display()),
                source: e,
            })?;
        sweeps.push(ModelSweep {
            kind,
            grid,
            records,
            wall_s,
        });
    }
    Ok(SweepStudy { spec, sweeps })
}

/// The values of an axis, in order.
pub fn axis(grid: &Grid, key: &str) -> Vec<f64> {
    grid.axes
        .iter()
        .find(|a| a.key == key)
        .map(|a| {
            (0..a.values.len())
                .filter_map(|k| a.values.get(k).as_float())
                .collect()
        })
        .unwrap_or_default()
}

fn param(r: &Record, key: &str) -> Option<f64> {
    r.params.get(key).and_then(|v| v.as_f64())
}

impl ModelSweep {
    /// values[mass index][move index] of `metric` for the group value `group` of `key` (None:
    /// failed or null).
    pub fn table(&self, key: &str, group: &str, metric: &str) -> Vec<Vec<Option<f64>>> {
        let (masses, moves) = (axis(&self.grid, MASS), axis(&self.grid, MOVE));
        masses
            .iter()
            .map(|&m| {
                moves
                    .iter()
                    .map(|&t| {
                        self.records
                            .iter()
                            .find(|r| {
                                r.params.get(key).and_then(|v| v.as_str()) == Some(group)
                                    && param(r, MASS) == Some(m)
                                    && param(r, MOVE) == Some(t)
                            })
                            .filter(|r| r.status == "complete")
                            .and_then(|r| r.metrics.get(metric).and_then(|v| v.as_f64()))
                    })
                    .collect()
            })
            .collect()
    }
}

impl SweepStudy {
    /// The REPORT.md subsection.
    pub fn section(&self, figures: &[String]) -> String {
        let spec = &self.spec;
        let mut s = format!(
            "### Effector mass × move time: {}\n\n\
             `cargo xtask sweep --grid examples/sweeps/{}_<model>.toml`; records in \
             `sweeps/{}_<model>/`. A cross marks a point that failed (a cable went slack).\n\n",
            spec.what, spec.stem, spec.stem
        );
        let points: usize = self.sweeps.iter().map(|s| s.records.len()).sum();
        let wall: f64 = self.sweeps.iter().map(|s| s.wall_s).sum();
        s.push_str(&format!(
            "{points} points in {wall:.1} s on {} cores.\n\n",
            cdpr_sweep::all_cores()
        ));
        for f in figures {
            s.push_str(&format!("![{f}]({f}.svg)\n\n"));
        }
        s.push_str(&format!(
            "| model | {} | points | failed | z p2p range [µm] | transition error range [mm] |\n\
             |---|---|---|---|---|---|\n",
            spec.group_key
        ));
        for sweep in &self.sweeps {
            for &c in spec.groups {
                let range = |metric: &str, scale: f64| {
                    let v: Vec<f64> = sweep
                        .table(spec.group_key, c, metric)
                        .into_iter()
                        .flatten()
                        .flatten()
                        .collect();
                    if v.is_empty() {
                        return "–".to_string();
                    }
                    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    format!("{} – {}", significant(lo * scale), significant(hi * scale))
                };
                let ours: Vec<&Record> = sweep
                    .records
                    .iter()
                    .filter(|r| r.params.get(spec.group_key).and_then(|v| v.as_str()) == Some(c))
                    .collect();
                let failed = ours.iter().filter(|r| r.status != "complete").count();
                s.push_str(&format!(
                    "| {} | {c} | {} | {failed} | {} | {} |\n",
                    sweep.kind.name(),
                    ours.len(),
                    range("z_p2p", 1e6),
                    range("err_max_transition", 1e3),
                ));
            }
        }
        s.push('\n');
        s
    }
}

/// Three significant digits, plain between 0.01 and 10⁵, else in exponent form.
fn significant(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if !(0.01..1e5).contains(&v.abs()) {
        format!("{v:.2e}")
    } else {
        let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    }
}
