//! The modes study (`cargo xtask modes`): every closed- and open-loop mode of the three models at given effector
//! positions, classified, as CSV and Markdown tables and a figure of the spectrum of modes
//! (frequency vs damping ratio); and the axial-damping sweep: the smallest Kelvin–Voigt
//! coefficient C (MODELS.md §4, FE.5.7) that makes every closed-loop mode of the lumped and FE
//! models decay. The report (`cargo xtask report`) reuses [`ModesReport`] for its modes section.

use crate::{Result, StudyError};
use cdpr_bench::ModelKind;
use cdpr_bench::analysis::AnalysisError;
use cdpr_bench::analysis::damping::Sweep;
use cdpr_bench::analysis::modes::{self, Analysis, ClassifiedMode, Loop, ModeKind};
use cdpr_bench::core::Vector2;
use cdpr_bench::core::scenario::Scenario;
use std::io::Write;

/// Growth rate [1/s] at or below which a mode counts as decaying in the damping sweep
/// (justification at [`cdpr_bench::analysis::damping::damping_sweep`]).
pub const SWEEP_THRESHOLD: f64 = 1e-2;
/// Damping range of the sweep [N s] and its scan points (log-spaced, then bisection).
const SWEEP_RANGE: (f64, f64) = (1e-5, 1.0);
const SWEEP_SCAN: usize = 11;

/// Everything the modes command computes.
pub struct ModesReport {
    pub analyses: Vec<Analysis>,
    /// The analyses the dense eigen-solver's bound skipped (a scenario's `model.elements`
    /// applies to both massive models: N = 400 fits FE, not lumped), each with why.
    pub skipped: Vec<String>,
    pub sweeps: Vec<Sweep>,
    /// μ [kg/m] and EA [N] for the taut-string column.
    pub mu: f64,
    pub ea: f64,
    pub anchor_distance: f64,
    /// Effector mass M [kg] for eq. 15.
    pub effector_mass: f64,
}

/// The three models' closed- and open-loop modes at each x, and the damping sweep at `sweep_at`.
pub fn compute(base: &Scenario, xs: &[f64], sweep_at: f64) -> Result<ModesReport> {
    let mut analyses = Vec::new();
    let mut skipped = Vec::new();
    let mut too_large = Vec::new();
    for &x in xs {
        for kind in ModelKind::ALL {
            let s = cdpr_bench::with_model_kind(base, kind)?;
            for feedback in [Loop::Closed, Loop::Open] {
                match cdpr_bench::analyse(&s, x, feedback) {
                    Ok(a) => analyses.push(a),
                    Err(cdpr_bench::Error::Analysis(e @ AnalysisError::TooLarge { .. })) => {
                        skipped.push(format!("{kind} at x = {x} ({feedback:?} loop): {e}"));
                        too_large.push(kind);
                    }
                    Err(e) => {
                        return Err(StudyError::Failed(format!("{kind} model at x = {x}: {e}")));
                    }
                }
            }
        }
    }
    let sweeps = ModelKind::MASSIVE
        .into_iter()
        .filter(|kind| !too_large.contains(kind))
        .map(|kind| {
            let s = cdpr_bench::with_model_kind(base, kind)?;
            cdpr_bench::damping_sweep(&s, sweep_at, SWEEP_RANGE, SWEEP_SCAN, SWEEP_THRESHOLD)
                .map_err(|e| StudyError::Failed(format!("{kind} damping sweep: {e}")))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(ModesReport {
        analyses,
        skipped,
        sweeps,
        mu: base.cable.mass_per_length(),
        ea: base.cable.axial_stiffness(),
        anchor_distance: base.robot.anchor_distance,
        effector_mass: base.robot.effector_mass,
    })
}

fn loop_name(l: Loop) -> &'static str {
    match l {
        Loop::Closed => "closed",
        Loop::Open => "open",
    }
}

impl ModesReport {
    /// The effector positions analysed, in order (each has a closed- and an open-loop analysis
    /// per model).
    pub fn positions(&self) -> Vec<f64> {
        let mut xs: Vec<f64> = self.analyses.iter().map(|a| a.x).collect();
        xs.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        xs
    }

    /// The taut-string harmonic ω_k = (kπ/l)√(T/μ_s) of either cable nearest a transverse mode's
    /// frequency, as (cable, k, ω_k); None for other kinds. Nearest rather than "the mode's own
    /// cable and rank": at mirror-symmetric positions (x = d/2) the two spans' string modes pair
    /// into symmetric and antisymmetric combinations (purity 0.5 per cable), so the cable label
    /// and hence the rank of such a mode are arbitrary.
    fn taut_string(&self, a: &Analysis, m: &ClassifiedMode) -> Option<(usize, usize, f64)> {
        if !matches!(m.kind, ModeKind::Transverse(_)) {
            return None;
        }
        let mut best: Option<(usize, usize, f64)> = None;
        for cable in 0..2 {
            let pulley = Vector2::new(cable as f64 * self.anchor_distance, 0.0);
            let chord = (pulley - Vector2::new(a.x, a.z)).norm();
            let w1 = modes::taut_string(1, chord, a.tensions[cable], self.mu, self.ea);
            let k = ((m.mode.omega / w1).round() as usize).max(1);
            let wk = k as f64 * w1;
            if best.is_none_or(|(_, _, b)| (wk - m.mode.omega).abs() < (b - m.mode.omega).abs()) {
                best = Some((cable, k, wk));
            }
        }
        best
    }

    /// `modes.csv`: every mode of every analysis.
    pub fn write_modes_csv(&self, w: &mut dyn Write) -> std::io::Result<()> {
        {
            writeln!(
                w,
                "model,loop,x_m,z_m,kind,order,omega_rad_s,growth_1_s,damping_ratio,purity,taut_string_rad_s"
            )?;
            for a in &self.analyses {
                for m in &a.modes {
                    let taut = self
                        .taut_string(a, m)
                        .map_or(String::new(), |(_, _, v)| v.to_string());
                    writeln!(
                        w,
                        "{},{},{},{},{},{},{},{},{},{},{}",
                        a.model,
                        loop_name(a.feedback),
                        a.x,
                        a.z,
                        m.kind,
                        m.order,
                        m.mode.omega,
                        m.mode.growth,
                        m.mode.damping_ratio(),
                        m.purity,
                        taut
                    )?;
                }
            }
            Ok::<(), std::io::Error>(())
        }
    }

    /// `damping_sweep.csv`: every point of the axial-damping sweeps.
    pub fn write_damping_sweep_csv(&self, w: &mut dyn Write) -> std::io::Result<()> {
        {
            writeln!(
                w,
                "model,x_m,axial_damping_N_s,least_stable_kind,least_stable_order,omega_rad_s,growth_1_s,stable"
            )?;
            for s in &self.sweeps {
                for p in &s.points {
                    let m = &p.least_stable;
                    writeln!(
                        w,
                        "{},{},{},{},{},{},{},{}",
                        s.model,
                        s.x,
                        p.damping,
                        m.kind,
                        m.order,
                        m.mode.omega,
                        m.mode.growth,
                        m.mode.growth <= s.threshold
                    )?;
                }
            }
            Ok(())
        }
    }

    /// The closed-loop analyses at position `x`, one per model.
    pub fn closed_at(&self, x: f64) -> Vec<&Analysis> {
        self.analyses
            .iter()
            .filter(|a| a.feedback == Loop::Closed && (a.x - x).abs() < 1e-12)
            .collect()
    }

    /// The Markdown section: key modes per model, position and loop, the FFT peaks (`peaks`:
    /// model, refined peak of z over [1, 5] s, plain FFT bin over [0, 5] s, from the report's runs;
    /// empty for the standalone command), the taut-string formula, the damping sweep.
    pub fn write_section(
        &self,
        w: &mut dyn Write,
        peaks: &[(&str, f64, f64)],
    ) -> std::io::Result<()> {
        self.write_intro(w, peaks)?;
        self.write_key_modes(w)?;
        self.write_figure_links(w)?;
        self.write_damping(w)
    }

    /// What the table holds and how it was made; the runs' FFT peaks.
    fn write_intro(&self, w: &mut dyn Write, peaks: &[(&str, f64, f64)]) -> std::io::Result<()> {
        writeln!(
            w,
            "Every eigenvalue λ = σ + iω of the linearised loop (model + PID + tension distribution, \
             finite-difference Jacobian, constrained lumped stored-node coordinates removed) at the \
             static equilibrium at x, classified from its eigenvector by the largest share of \
             mass-weighted displacement (`purity`). Closed = the paper's PID; open = PID off, \
             tensions fixed at the equilibrium's. ζ = −σ/|λ|. Taut string: ω_k = (kπ/l)√(T/μ_s) \
             with the chord l, the commanded tension T and μ_s = μ/(1 + T/EA). All modes: \
             `modes.csv`; figures: `modes_x*.svg`.\n"
        )?;
        for note in &self.skipped {
            writeln!(w, "Skipped: {note}.\n")?;
        }
        if !peaks.is_empty() {
            writeln!(
                w,
                "FFT peaks of the runs (for comparison with the vertical mode at x2): {}.\n",
                peaks
                    .iter()
                    .map(|(m, refined, plain)| format!(
                        "{m}: refined {refined:.4}, plain 5 s bin {plain:.4} rad/s"
                    ))
                    .collect::<Vec<_>>()
                    .join("; ")
            )?;
        }
        Ok(())
    }

    /// The key modes of every analysis, with their references.
    fn write_key_modes(&self, w: &mut dyn Write) -> std::io::Result<()> {
        writeln!(
            w,
            "| model | x [m] | loop | mode | ω [rad/s] | σ [1/s] | ζ | purity | reference [rad/s] |"
        )?;
        writeln!(w, "|---|---|---|---|---|---|---|---|---|")?;
        for a in &self.analyses {
            for (kind, m, reference) in self.key_modes(a) {
                writeln!(
                    w,
                    "| {} | {} | {} | {} | {:.4} | {:+.4e} | {:.3e} | {:.3} | {} |",
                    a.model,
                    a.x,
                    loop_name(a.feedback),
                    kind.replace('|', "\\|"),
                    m.mode.omega,
                    m.mode.growth,
                    m.mode.damping_ratio(),
                    m.purity,
                    reference
                )?;
            }
        }
        Ok(())
    }

    /// The rows of one analysis: the vertical mode against eq. 15, the horizontal, the two
    /// lowest transverse against the taut string, each cable's lowest axial, the least stable.
    fn key_modes<'a>(&self, a: &'a Analysis) -> Vec<(String, &'a ClassifiedMode, String)> {
        let eq15 = cdpr_bench::elastic::eq15_frequency(
            0.5 * (a.tensions[0] + a.tensions[1]),
            self.effector_mass,
            a.x,
            self.anchor_distance,
        );
        let mut rows: Vec<(String, &ClassifiedMode, String)> = Vec::new();
        if let Some(m) = a.vertical() {
            rows.push(("vertical".into(), m, format!("eq. 15: {eq15:.4}")));
        }
        for m in a.modes.iter().filter(|m| m.kind == ModeKind::Horizontal) {
            rows.push((m.kind.to_string(), m, String::new()));
        }
        let transverse = a
            .modes
            .iter()
            .filter(|m| matches!(m.kind, ModeKind::Transverse(_)));
        for (rank, m) in transverse.take(2).enumerate() {
            if let Some((cable, k, t)) = self.taut_string(a, m) {
                rows.push((
                    format!("transverse #{} ({})", rank + 1, m.kind),
                    m,
                    format!("taut string cable {}, k = {k}: {t:.3}", cable + 1),
                ));
            }
        }
        for cable in 0..2 {
            if let Some(m) = a.find(ModeKind::Axial(cable), 1) {
                rows.push((
                    format!("lowest axial, cable {}", cable + 1),
                    m,
                    String::new(),
                ));
            }
        }
        if let Some(m) = a.least_stable() {
            rows.push((format!("**least stable** ({})", m.kind), m, String::new()));
        }
        rows
    }

    /// Links to each position's spectrum figure.
    fn write_figure_links(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let xs = self.positions();
        writeln!(w)?;
        for x in xs {
            writeln!(
                w,
                "![Closed-loop modes at x = {x}: |λ| vs ζ](modes_x{x}.svg)\n\nPNG: [modes_x{x}.png](modes_x{x}.png)\n"
            )?;
        }
        Ok(())
    }

    /// The damping sweep's answer per model and position.
    fn write_damping(&self, w: &mut dyn Write) -> std::io::Result<()> {
        writeln!(w, "### Axial damping that makes every mode decay\n")?;
        for s in &self.sweeps {
            let at = match s.smallest {
                Some(c) => format!("**C = {c:.4e} N s**"),
                None => format!(
                    "none up to {:.0e} N s",
                    s.points.last().map_or(f64::NAN, |p| p.damping)
                ),
            };
            // How neutral the modes left above the answer are (the string modes).
            let above = s
                .points
                .iter()
                .filter(|p| s.smallest.is_some_and(|c| p.damping >= c))
                .filter(|p| matches!(p.least_stable.kind, ModeKind::Transverse(_)))
                .fold(0.0f64, |m, p| m.max(p.least_stable.mode.growth.abs()));
            writeln!(
                w,
                "- {} at x = {}: {at} is the smallest Kelvin–Voigt coefficient for which every \
                 closed-loop mode has σ ≤ {:.0e} 1/s (linearisation resolution {:.1e} 1/s; \
                 {} points in `damping_sweep.csv`). Above it the least stable modes are transverse \
                 string modes, neutral to within |σ| ≤ {above:.1e} 1/s; axial damping does not \
                 reach them.",
                s.model,
                s.x,
                s.threshold,
                s.resolution,
                s.points.len()
            )?;
        }
        Ok(())
    }
}
