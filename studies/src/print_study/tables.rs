//! The study's section of the report: what was printed, the frontier figure, each setup's knee
//! and the tables of contour errors, and the massive lines against the elastic ones.

use super::{ACCELERATIONS, GOOD_CONTOUR, MASSIVE, PrintStudy, Row, SETUPS};
use cdpr_bench::ModelKind;
use std::fmt::Write as _;

impl PrintStudy {
    /// The report's section: what was printed, the frontier figure, the tables.
    pub fn section(&self, figure: &str) -> String {
        format!(
            "## Printing: the speed–accuracy frontier\n\nBeyond the paper (`cargo xtask print-study`; \
             print-study.json has every print): the first layer of a 20 mm cube and of a 20 mm \
             cylinder sliced by PrusaSlicer 2.5.0 (verify/data/print), planned by Klipper's \
             planner (300 mm/s, square corner velocity 5 mm/s) at each acceleration, printed by \
             the Hangprinter-like robot (examples/printing/hangprinter.toml: elastic cables, \
             line damping ζ = 2 % at the lowest locked-reel mode), each controller unshaped and \
             with the best of Klipper's ZV, MZV and EI at the loop's least-damped modes at the \
             layer's centre. Contour error: the nozzle's distance to the commanded path.\n\n\
             ![{figure}]({figure}.svg)\n\n{}",
            self.markdown()
        )
    }

    /// The unshaped print and the best shaped one (lowest contour error) of a cable model, part,
    /// setup and acceleration.
    pub fn pair(&self, model: &str, part: &str, setup: &str, accel: f64) -> Option<(&Row, &Row)> {
        let mine = || {
            self.rows.iter().filter(move |r| {
                r.model == model && r.part == part && r.setup == setup && r.accel_mm_s2 == accel
            })
        };
        let unshaped = mine().find(|r| r.shaper == "none")?;
        let best = mine().filter(|r| r.shaper != "none").min_by(|a, b| {
            a.contour_err_max_printing
                .total_cmp(&b.contour_err_max_printing)
        })?;
        Some((unshaped, best))
    }

    /// The highest acceleration whose contour error stays within [`GOOD_CONTOUR`] (None: not
    /// even the lowest), unshaped and best-shaped.
    pub fn knee(&self, model: &str, part: &str, setup: &str) -> [Option<f64>; 2] {
        let mut knee = [None, None];
        for accel in ACCELERATIONS {
            if let Some((u, b)) = self.pair(model, part, setup, accel) {
                for (slot, row) in knee.iter_mut().zip([u, b]) {
                    if row.contour_err_max_printing <= GOOD_CONTOUR {
                        *slot = Some(accel);
                    }
                }
            }
        }
        knee
    }

    /// The study's tables: per part, each setup and acceleration unshaped and best-shaped,
    /// then each setup's knee; then the cube on every cable model.
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let elastic = ModelKind::Elastic.name();
        let mut parts: Vec<&str> = self
            .rows
            .iter()
            .filter(|r| r.model == elastic)
            .map(|r| r.part.as_str())
            .collect();
        parts.dedup();
        let um = |v: f64| format!("{:.1}", v * 1e6);
        for part in parts {
            let _ = writeln!(
                md,
                "**{part}** — contour error of the printing moves [µm] (max / rms; all moves' max, \
                 travel included, in brackets) against print time [s]\n\n\
                 | controller | accel [mm/s²] | print time | unshaped max | rms | best shaper (x, y Hz) | max | rms |\n\
                 |---|---:|---:|---:|---:|---|---:|---:|"
            );
            for setup in SETUPS {
                for accel in ACCELERATIONS {
                    let Some((u, b)) = self.pair(elastic, part, setup.label, accel) else {
                        continue;
                    };
                    let _ = writeln!(
                        md,
                        "| {} | {accel:.0} | {:.2} | {} ({}) | {} | {} ({:.1}, {:.1}) | {} ({}) | {} |",
                        setup.label,
                        u.print_time_s,
                        um(u.contour_err_max_printing),
                        um(u.contour_err_max),
                        um(u.contour_err_rms_printing),
                        b.shaper,
                        b.shaper_freq_hz[0],
                        b.shaper_freq_hz[1],
                        um(b.contour_err_max_printing),
                        um(b.contour_err_max),
                        um(b.contour_err_rms_printing)
                    );
                }
            }
            let _ = writeln!(
                md,
                "\nKnee (highest acceleration with the printing moves' contour error ≤ {:.0} µm), \
                 unshaped / best-shaped: {}\n",
                GOOD_CONTOUR * 1e6,
                SETUPS
                    .iter()
                    .map(|s| {
                        let [u, b] = self.knee(elastic, part, s.label);
                        let f =
                            |k: Option<f64>| k.map_or("none".to_string(), |a| format!("{a:.0}"));
                        format!("{} {} / {}", s.label, f(u), f(b))
                    })
                    .collect::<Vec<_>>()
                    .join("; ")
            );
        }
        md + &self.massive_markdown()
    }

    /// The cube on every cable model: per setup and acceleration the printing moves' largest
    /// contour error, unshaped / with the elastic study's best shaper, and each model's knees.
    fn massive_markdown(&self) -> String {
        let Some(part) = self
            .rows
            .iter()
            .find(|r| r.model != ModelKind::Elastic.name())
        else {
            return String::new();
        };
        let part = part.part.as_str();
        let models: Vec<&str> = std::iter::once(ModelKind::Elastic)
            .chain(MASSIVE.map(|(m, _)| m))
            .map(|m| m.name())
            .collect();
        let mut md = format!(
            "**{part} on every cable model** (lumped lines of {} springs and FE cables of {} \
             elements on the implicit path, h = 1e-4 s) — the printing moves' largest contour \
             error [µm], unshaped / with the elastic study's best shaper at its frequencies\n\n\
             | controller | accel [mm/s²] | {} |\n|---|---:|{}\n",
            MASSIVE[0].1,
            MASSIVE[1].1,
            models.join(" | "),
            "---:|".repeat(models.len())
        );
        let accelerations = self.massive_accelerations();
        for setup in SETUPS {
            for &accel in &accelerations {
                let cells: Vec<String> = models
                    .iter()
                    .map(|m| self.massive_cell(m, part, setup.label, accel))
                    .collect();
                let _ = writeln!(
                    md,
                    "| {} | {accel:.0} | {} |",
                    setup.label,
                    cells.join(" | ")
                );
            }
        }
        let knees = self.massive_knees(&models, part);
        if accelerations.len() == ACCELERATIONS.len() {
            let _ = writeln!(
                md,
                "\nKnees, unshaped / best-shaped — {}\n",
                knees.join(". ")
            );
        } else {
            md.push('\n');
        }
        md
    }

    /// One every-model table cell: largest printing contour error [µm] unshaped / shaped, or why none.
    fn massive_cell(&self, model: &str, part: &str, setup: &str, accel: f64) -> String {
        match self.pair(model, part, setup, accel) {
            Some((u, b)) => format!(
                "{:.1} / {:.1}",
                u.contour_err_max_printing * 1e6,
                b.contour_err_max_printing * 1e6
            ),
            None => {
                let stopped = self.rows.iter().any(|r| {
                    r.model == model
                        && r.setup == setup
                        && r.accel_mm_s2 == accel
                        && r.stopped.is_some()
                });
                if stopped {
                    "stopped".into()
                } else {
                    "—".into()
                }
            }
        }
    }

    /// The accelerations the massive cable models printed at, ascending and without repeats.
    fn massive_accelerations(&self) -> Vec<f64> {
        let mut accelerations: Vec<f64> = self
            .rows
            .iter()
            .filter(|r| r.model != ModelKind::Elastic.name())
            .map(|r| r.accel_mm_s2)
            .collect();
        accelerations.sort_by(f64::total_cmp);
        accelerations.dedup();
        accelerations
    }

    /// Each cable model's knees per setup, unshaped / best-shaped ("model: setup u / b; …").
    fn massive_knees(&self, models: &[&str], part: &str) -> Vec<String> {
        models
            .iter()
            .map(|m| {
                let per: Vec<String> = SETUPS
                    .iter()
                    .map(|s| {
                        let [u, b] = self.knee(m, part, s.label);
                        let f =
                            |k: Option<f64>| k.map_or("none".to_string(), |a| format!("{a:.0}"));
                        format!("{} {} / {}", s.label, f(u), f(b))
                    })
                    .collect();
                format!("{m}: {}", per.join("; "))
            })
            .collect()
    }
}
