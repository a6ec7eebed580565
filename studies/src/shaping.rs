//! The input-shaping study (`cargo xtask shaping`): every input shaper on every cable model with the paper's PID, designed
//! from the modal analysis ("auto"): the residual vertical vibration (z peak-to-peak from 0.8 s
//! after the shaped move ends to 5 s, and as a percentage of the unshaped run's), the move-time
//! penalty, and the
//! robustness curve (residual against the error of the shaper's frequency, −40 % … +40 %)
//! simulated next to the shaper's analytic V(ω, ζ) → `shaping.md`, `shaping.csv` and one figure
//! per model; plus what limits shaping on this robot (the mode's drift along the move, the
//! nonlinear coupling measured by the move's size).

use crate::Result;
use cdpr_bench::ModelKind;
use cdpr_bench::core::scenario::{Designed, Scenario};
use cdpr_bench::core::shaper::{Impulses, ShaperKind};
use std::fmt::Write as _;

/// Frequency errors of the robustness curve [fraction of the design frequency].
const ERRORS: [f64; 17] = [
    -0.4, -0.35, -0.3, -0.25, -0.2, -0.15, -0.1, -0.05, 0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35,
    0.4,
];
/// Sample period of the study's runs [s] (the z peak-to-peak's resolution at 20 rad/s: 2e-7).
const SAMPLE_PERIOD: f64 = 1e-4;

/// One run of the study.
#[derive(Debug, Clone)]
pub struct Point {
    pub model: ModelKind,
    pub shaper: ShaperKind,
    /// Design frequency's relative error against the auto-designed one.
    pub error: f64,
    pub omega: f64,
    pub zeta: f64,
    pub z_p2p: f64,
    pub move_end_s: f64,
    pub path_err: f64,
    /// V at the true mode (the auto design's) for this design, [0, 1].
    pub analytic: f64,
}

/// The study's scenario for one model: the paper's, samples every 1e-4 s, the implicit path on
/// the massive-cable models (DOPRI5 on the elastic one), no end-of-run modal analysis.
fn base_for(base: &Scenario, model: ModelKind) -> Result<Scenario> {
    let mut s = cdpr_bench::with_model_kind(base, model)?;
    s.simulation.sample_period = SAMPLE_PERIOD;
    s.simulation.integrator = crate::control::fast_integrator(model);
    s.analysis.modes = cdpr_bench::core::scenario::ModesChoice::Off;
    Ok(s)
}

/// Runs `s` with `shaper` designed at (ω, ζ): z p2p from 0.8 s after the shaped move ends, move
/// end, path error.
fn run(s: &Scenario, shaper: ShaperKind, omega: f64, zeta: f64) -> Result<(f64, f64, f64)> {
    let mut s = s.clone();
    s.trajectory.shaper = shaper;
    s.trajectory.shaper_frequency = Designed::Value(omega);
    s.trajectory.shaper_damping = Designed::Value(zeta);
    s.validate()?;
    let run = cdpr_bench::simulate(&s, &mut |_| {})?;
    let m = cdpr_bench::metrics(&s, &run);
    Ok((
        m.z_p2p,
        m.control.move_end_s,
        m.control.path_err_max_transition,
    ))
}

/// The whole study.
pub struct Study {
    pub points: Vec<Point>,
    /// Per model: the unshaped z p2p [m] and the auto design (ω, ζ).
    pub unshaped: Vec<(ModelKind, f64, f64, f64)>,
    pub limits: String,
    pub t2: f64,
}

pub fn compute(base: &Scenario) -> Result<Study> {
    let mut unshaped = Vec::new();
    let mut jobs = Vec::new();
    for model in ModelKind::ALL {
        let s = base_for(base, model)?;
        let (omega, zeta) = cdpr_bench::least_damped_vertical_mode(&s, s.trajectory.x2)?;
        let (p2p, _, _) = run(&s, ShaperKind::None, omega, zeta)?;
        unshaped.push((model, p2p, omega, zeta));
        for shaper in ShaperKind::ALL.into_iter().skip(1) {
            for error in ERRORS {
                jobs.push((s.clone(), model, shaper, error, omega, zeta));
            }
        }
    }
    let points = crate::pool::map(&jobs, |(s, model, shaper, error, omega, zeta)| {
        let design = omega * (1.0 + error);
        let (z_p2p, move_end_s, path_err) = run(s, *shaper, design, *zeta)?;
        let analytic = Impulses::design(*shaper, design, *zeta, s.trajectory.shaper_vtol)?
            .residual(*omega, *zeta);
        Ok(Point {
            model: *model,
            shaper: *shaper,
            error: *error,
            omega: design,
            zeta: *zeta,
            z_p2p,
            move_end_s,
            path_err,
            analytic,
        })
    })?
    .into_iter()
    .collect::<Result<Vec<_>>>()?;
    let limits = limits(base)?;
    Ok(Study {
        points,
        unshaped,
        limits,
        t2: base.trajectory.t2,
    })
}

/// What limits shaping: the vertical mode's drift along the move and, for the best shapers
/// designed at x1, x2 and their mean, the residual; and the residual against the move's size
/// from x1 = 0.5 m (the symmetric point) and from 0.55 m, where a linear loop would leave V.
fn limits(base: &Scenario) -> Result<String> {
    let s = base_for(base, ModelKind::Elastic)?;
    let (w1, _) = cdpr_bench::least_damped_vertical_mode(&s, s.trajectory.x1)?;
    let (w2, z2) = cdpr_bench::least_damped_vertical_mode(&s, s.trajectory.x2)?;
    let (unshaped, _, _) = run(&s, ShaperKind::None, w2, z2)?;
    let mut md = format!(
        "The elastic model with the paper's PID. The vertical mode sweeps {w1:.4} → {w2:.4} rad/s from x1 \
         to x2 ({:+.2} %): a ZV shaper designed at x2 leaves V = {:.2} % at x1's frequency, so the drift \
         alone explains little.\n\n| shaper | designed at x1 | at x2 | at the mean |\n|---|---|---|---|\n",
        100.0 * (w1 / w2 - 1.0),
        100.0 * Impulses::design(ShaperKind::Zv, w2, z2, 0.05)?.residual(w1, z2),
    );
    for shaper in [ShaperKind::Zv, ShaperKind::Zvd, ShaperKind::TwoHumpEi] {
        let mut row = format!("| {} |", shaper.name());
        for w in [w1, w2, 0.5 * (w1 + w2)] {
            let (p2p, _, _) = run(&s, shaper, w, z2)?;
            let _ = write!(row, " {:.2} % |", 100.0 * p2p / unshaped);
        }
        let _ = writeln!(md, "{row}");
    }
    md.push_str(
        "\nResidual of the ZV shaper (auto design at x2 of each move) against the move's size: a loop \
         that were linear in the move would leave the same percentage at every size.\n\n\
         | Δx [mm] | from x1 = 0.5 m | from x1 = 0.55 m |\n|---|---|---|\n",
    );
    for dx in [1e-4, 1e-3, 1e-2, 1e-1] {
        let mut row = format!("| {} |", dx * 1e3);
        for x1 in [0.5, 0.55] {
            let mut m = s.clone();
            m.trajectory.x1 = x1;
            m.trajectory.x2 = x1 + dx;
            let (w, z) = cdpr_bench::least_damped_vertical_mode(&m, m.trajectory.x2)?;
            let (base_p2p, _, _) = run(&m, ShaperKind::None, w, z)?;
            let (p2p, _, _) = run(&m, ShaperKind::Zv, w, z)?;
            let _ = write!(row, " {:.3} % |", 100.0 * p2p / base_p2p);
        }
        let _ = writeln!(md, "{row}");
    }
    Ok(md)
}

/// The contiguous frequency-error range around 0 in which the residual stays ≤ `limit` (%).
fn band(points: &[&Point], unshaped: f64, limit: f64) -> String {
    let ok = |p: &Point| 100.0 * p.z_p2p / unshaped <= limit;
    let Some(centre) = points.iter().position(|p| p.error == 0.0) else {
        return "–".into();
    };
    if !ok(points[centre]) {
        return "none".into();
    }
    let mut lo = centre;
    while lo > 0 && ok(points[lo - 1]) {
        lo -= 1;
    }
    let mut hi = centre;
    while hi + 1 < points.len() && ok(points[hi + 1]) {
        hi += 1;
    }
    format!(
        "[{:+.0} %, {:+.0} %]",
        100.0 * points[lo].error,
        100.0 * points[hi].error
    )
}

impl Study {
    pub fn curve(&self, model: ModelKind, shaper: ShaperKind) -> Vec<&Point> {
        self.points
            .iter()
            .filter(|p| p.model == model && p.shaper == shaper)
            .collect()
    }

    pub fn unshaped(&self, model: ModelKind) -> f64 {
        self.unshaped
            .iter()
            .find(|u| u.0 == model)
            .map_or(f64::NAN, |u| u.1)
    }

    /// The shaper × model table.
    pub fn table(&self) -> String {
        let mut md = String::from(
            "| shaper | model | design ω [rad/s], ζ | residual z p2p [µm] | residual [% of unshaped] \
             | move-time penalty [s] | path error [mm] | band ≤ 5 % | band ≤ 10 % |\n\
             |---|---|---|---|---|---|---|---|---|\n",
        );
        for &(model, p2p, omega, zeta) in &self.unshaped {
            let _ = writeln!(
                md,
                "| none | {} | – | {:.3} | 100 | 0 | – | – | – |",
                model.name(),
                p2p * 1e6
            );
            for shaper in ShaperKind::ALL.into_iter().skip(1) {
                let curve = self.curve(model, shaper);
                let Some(at) = curve.iter().find(|p| p.error == 0.0) else {
                    continue;
                };
                let _ = writeln!(
                    md,
                    "| {} | {} | {omega:.4}, {zeta:.1e} | {:.3} | {:.2} | {:.3} | {:.3} | {} | {} |",
                    shaper.name(),
                    model.name(),
                    at.z_p2p * 1e6,
                    100.0 * at.z_p2p / p2p,
                    at.move_end_s - self.t2,
                    at.path_err * 1e3,
                    band(&curve, p2p, 5.0),
                    band(&curve, p2p, 10.0),
                );
            }
        }
        md
    }

    /// `shaping.csv`.
    pub fn csv(&self) -> String {
        let mut csv = String::from(
            "model,shaper,frequency_error,design_omega_rad_s,design_zeta,z_p2p_m,residual_pct,\
             analytic_v_pct,move_end_s,path_err_max_transition_m\n",
        );
        for p in &self.points {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{}",
                p.model.name(),
                p.shaper.name(),
                p.error,
                p.omega,
                p.zeta,
                p.z_p2p,
                100.0 * p.z_p2p / self.unshaped(p.model),
                100.0 * p.analytic,
                p.move_end_s,
                p.path_err
            );
        }
        csv
    }

    /// The section shared by shaping.md and REPORT.md.
    pub fn section(&self, names: &[(String, String)]) -> String {
        let mut md = String::from(
            "The paper's PID and move on every model (DOPRI5 on the elastic model, the implicit path on \
             the others, samples every 1e-4 s); each shaper designed automatically for the least-damped \
             vertical mode of the model's closed loop at x2. Residual: z peak-to-peak from 0.8 s after the (shaped) move ends to 5 s. \
             Bands: the frequency errors (5 % steps) around the design inside which the residual stays \
             below the limit.\n\n",
        );
        md.push_str(&self.table());
        md.push_str("\n### What limits shaping here\n\n");
        md.push_str(&self.limits);
        md.push('\n');
        for (name, title) in names {
            let _ = writeln!(md, "![{title}]({name}.svg)\n");
        }
        md
    }
}
