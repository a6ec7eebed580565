//! REPORT.md's text (`cargo xtask report`): the MODELS.md §8 table, the vertical frequency, the
//! modes, the static equilibria, the solver's counts, the control leaderboard, the figures and
//! the software, one function per section. The command line draws the figures and writes the
//! file; what the report says is written here, where a library user can make it too.

use cdpr_bench::Assessed;
use cdpr_bench::analysis::linearise::EndState;
use cdpr_bench::core::scenario::Scenario;
use cdpr_verify::acceptance::Check;
use std::io::{Result, Write};

/// What REPORT.md is made of.
pub struct ReportInputs<'a> {
    pub base: &'a Scenario,
    /// Each model's paper run, with the end state of its modal analysis.
    pub outcomes: &'a [Assessed],
    pub ends: &'a [EndState],
    pub checks: &'a [Check],
    /// Paper eq. 15 at x2 [rad/s].
    pub eq15: f64,
    /// (file name without extension, caption) of each figure.
    pub figures: &'a [(String, String)],
    pub modes: &'a crate::modes::ModesReport,
    /// The control study's section, as Markdown.
    pub control: &'a str,
    /// The software lines ("cdpr-bench … at git revision …", the compiler).
    pub software: &'a [String],
}

/// The whole REPORT.md.
pub fn write(w: &mut dyn Write, r: &ReportInputs) -> Result<()> {
    intro(w, r)?;
    checks_table(w, r.checks)?;
    vertical_frequency(w, r)?;
    writeln!(w, "\n## Modes of every model\n")?;
    let peaks: Vec<(&str, f64, f64)> = r
        .outcomes
        .iter()
        .map(|o| {
            (
                o.kind.name(),
                o.metrics.spectral.z_peak_rad_s,
                o.metrics.spectral.z_fft_record_rad_s,
            )
        })
        .collect();
    r.modes.write_section(w, &peaks)?;
    equilibria(w, r)?;
    solver_statistics(w, r.outcomes)?;
    writeln!(
        w,
        "\n## Vibration control: every controller on every cable model\n\n\
         Beyond the paper: its PID and three controllers that act on z (`cargo xtask control`; \
         control.csv has every number).\n"
    )?;
    w.write_all(r.control.as_bytes())?;
    figures(w, r.figures)?;
    software(w, r)
}

fn intro(w: &mut dyn Write, r: &ReportInputs) -> Result<()> {
    let sim = &r.base.simulation;
    let passed = r.checks.iter().filter(|c| c.pass).count();
    writeln!(w, "# cdpr-bench reproduction report\n")?;
    writeln!(
        w,
        "The paper's scenario (MODELS.md §1) with every available cable model: DOPRI5, rtol {:e}, atol {:e}, \
         samples every {:e} s over {} s. Regenerate with `cargo xtask report`.\n",
        sim.rtol, sim.atol, sim.sample_period, sim.t_final
    )?;
    writeln!(
        w,
        "**{passed} of {} checks of MODELS.md §8 pass.**",
        r.checks.len()
    )?;
    writeln!(w)
}

fn checks_table(w: &mut dyn Write, checks: &[Check]) -> Result<()> {
    writeln!(
        w,
        "## MODELS.md §8: the paper's results, ours, the tolerance\n"
    )?;
    writeln!(w, "| quantity | model | paper | ours | accept | pass |")?;
    writeln!(w, "|---|---|---|---|---|---|")?;
    for c in checks {
        let mark = if c.pass { "✅" } else { "❌" };
        let cells = [&c.quantity, &c.model, &c.paper, &c.ours, &c.accept].map(|s| cell(s));
        writeln!(w, "| {} | {mark} |", cells.join(" | "))?;
    }
    Ok(())
}

fn vertical_frequency(w: &mut dyn Write, r: &ReportInputs) -> Result<()> {
    writeln!(w, "\n## Vertical frequency of the effector\n")?;
    writeln!(
        w,
        "Eq. 15 (two strings and a mass, tension ΣT/2) at x = {}: **{:.4} rad/s** (paper: 20.41). The \
         closed-loop eigenfrequency comes from the finite-difference Jacobian of model + PID + tension \
         distribution at the static equilibrium at x2; the refined peaks from the Hann-windowed, 16× padded \
         spectrum over [1, 5] s; the plain peak is the FFT bin of the 5 s record that the paper reports \
         (20.11 rad/s = bin 16, 2π·16/5).\n",
        r.base.trajectory.x2, r.eq15
    )?;
    writeln!(
        w,
        "| model | closed-loop mode [rad/s] | damping ratio | refined peak z / error [rad/s] | plain FFT peak of z over [0, 5] s [rad/s] |"
    )?;
    writeln!(w, "|---|---|---|---|---|")?;
    for (o, end) in r.outcomes.iter().zip(r.ends) {
        let m = &o.metrics;
        writeln!(
            w,
            "| {} | {:.4} | {:.2e} | {:.4} / {:.4} | {:.4} (bin {}) |",
            o.kind,
            end.mode.omega,
            end.mode.damping_ratio(),
            m.spectral.z_peak_rad_s,
            m.spectral.err_peak_rad_s,
            m.spectral.z_fft_record_rad_s,
            m.spectral.z_fft_record_bin
        )?;
    }
    Ok(())
}

fn equilibria(w: &mut dyn Write, r: &ReportInputs) -> Result<()> {
    writeln!(
        w,
        "\n## Static equilibria (MODELS.md §2 rule: effector x held, F0 unknown)\n"
    )?;
    writeln!(
        w,
        "| model | z at x1 [m] | F0 at x1 [N] | z at x2 [m] | F0 at x2 [N] |"
    )?;
    writeln!(w, "|---|---|---|---|---|")?;
    for (o, end) in r.outcomes.iter().zip(r.ends) {
        writeln!(
            w,
            "| {} | {} | {} | {} | {} |",
            o.kind,
            fixed(o.metrics.z0, 7),
            fixed(o.metrics.f0, 6),
            fixed(end.effector_height(), 7),
            fixed(end.equilibrium.force(), 6)
        )?;
    }
    Ok(())
}

fn solver_statistics(w: &mut dyn Write, outcomes: &[Assessed]) -> Result<()> {
    writeln!(w, "\n## Solver statistics\n")?;
    writeln!(
        w,
        "| model | RHS evaluations | accepted steps | rejected steps | pulley events | energy balance residual [J] |"
    )?;
    writeln!(w, "|---|---|---|---|---|---|")?;
    for o in outcomes {
        let m = &o.metrics;
        writeln!(
            w,
            "| {} | {} | {} | {} | {} | {:.2e} |",
            o.kind,
            m.rhs_evals,
            m.steps_accepted,
            m.steps_rejected,
            m.pulley_events,
            m.energy_residual_max
        )?;
    }
    writeln!(
        w,
        "\nWall times (this machine; the only numbers of this report that change between runs):\n"
    )?;
    writeln!(w, "| model | wall time [s] |")?;
    writeln!(w, "|---|---|")?;
    for o in outcomes {
        writeln!(w, "| {} | {:.2} |", o.kind, o.run.wall_s)?;
    }
    Ok(())
}

fn figures(w: &mut dyn Write, figures: &[(String, String)]) -> Result<()> {
    writeln!(w, "\n## Figures\n")?;
    for (name, caption) in figures {
        writeln!(
            w,
            "### {caption}\n\n![{caption}]({name}.svg)\n\nPNG: [{name}.png]({name}.png)\n"
        )?;
    }
    Ok(())
}

fn software(w: &mut dyn Write, r: &ReportInputs) -> Result<()> {
    writeln!(w, "## Software\n")?;
    for line in r.software {
        writeln!(w, "- {line}")?;
    }
    writeln!(
        w,
        "- integrator: our DOPRI5 (Hairer's dopri5.f, β = {})",
        r.base.simulation.dopri_beta
    )
}

/// A Markdown table cell: `|` (as in "max |error|") would end the cell.
pub fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// `v` with `decimals` decimals, without the sign of a value that rounds to zero (the static
/// F0 at the symmetric x = 0.5 is ±1e-12 N of round-off, which would print as "-0.000000").
pub fn fixed(v: f64, decimals: usize) -> String {
    let text = format!("{v:.decimals$}");
    match text.strip_prefix('-') {
        Some(magnitude) if magnitude.chars().all(|c| c == '0' || c == '.') => magnitude.to_string(),
        _ => text,
    }
}

#[cfg(test)]
mod tests {
    use super::fixed;

    #[test]
    fn fixed_drops_the_sign_of_a_rounded_zero_only() {
        assert_eq!(fixed(-1e-12, 6), "0.000000");
        assert_eq!(fixed(-0.0, 3), "0.000");
        assert_eq!(fixed(-0.0237291, 7), "-0.0237291");
        assert_eq!(fixed(0.097531, 6), "0.097531");
        assert_eq!(fixed(-4e-7, 6), "0.000000");
        assert_eq!(fixed(-6e-7, 6), "-0.000001");
    }
}
