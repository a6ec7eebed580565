//! The controller leaderboard (`cargo xtask control`): every controller on every cable model on the paper's move, with the
//! benchmark's tension limits [10, 400] N → `control.md` (the leaderboard and the goals),
//! `control.csv`, and figures of the x and z errors and of the z spectrum, one panel per model.
//! The report (`cargo xtask report`) reuses [`Leaderboard`] for its control section.

use crate::{Result, StudyError};
use cdpr_bench::analysis::metrics::Metrics;
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::scenario::{ControllerKind, IntegratorKind, Scenario};
use cdpr_bench::{Assessed, ModelKind};
use std::fmt::Write as _;

/// The benchmark's tension limits [N].
pub const T_MIN: f64 = 10.0;
pub const T_MAX: f64 = 400.0;
/// The benchmark's sample period [s] (the metrics' resolution; 50 001 samples over 5 s).
pub const SAMPLE_PERIOD: f64 = 1e-4;
/// The goals of the vibration-control benchmark.
pub const GOAL_PATH_ERROR: f64 = 1e-5;
pub const GOAL_Z_P2P: f64 = 1e-6;
pub const GOAL_SETTLE_AFTER_MOVE: f64 = 0.5;

/// One controller on one model: its metrics and the samples the figures need.
pub struct Entry {
    pub controller: ControllerKind,
    pub model: ModelKind,
    pub integrator: IntegratorKind,
    pub metrics: Metrics,
    /// (t, e_x, z − z0) every 1 ms [s, m, m].
    pub errors: Vec<[f64; 3]>,
    /// (ω, |Z|) of z over the settled window [rad/s, m].
    pub z_spectrum: Vec<(f64, f64)>,
    /// Why the run stopped early, if it did (its metrics cover what it computed).
    pub failure: Option<String>,
}

/// Every controller × model run.
pub struct Leaderboard {
    pub entries: Vec<Entry>,
    pub move_end: f64,
}

/// The benchmark scenario of `base` for one controller and model: the limits above, the
/// controller's default z reference, the implicit path for the massive-cable models (the fast one
/// there), DOPRI5 for the elastic model.
pub fn scenario(base: &Scenario, controller: ControllerKind, model: ModelKind) -> Result<Scenario> {
    let mut s = cdpr_bench::with_model_kind(base, model)?;
    s.controller.kind = controller;
    s.controller.t_min = Some(T_MIN);
    s.controller.t_max = Some(T_MAX);
    s.trajectory.z_ref = None;
    s.simulation.sample_period = SAMPLE_PERIOD;
    s.simulation.integrator = fast_integrator(model);
    s.validate()?;
    Ok(s)
}

/// The faster integrator for `model` on the paper's move: DOPRI5 for the elastic model, the
/// implicit path for the massive-cable ones (whose axial modes limit DOPRI5's step).
pub fn fast_integrator(model: ModelKind) -> IntegratorKind {
    if model.has_cable_mass() {
        IntegratorKind::Implicit
    } else {
        IntegratorKind::Dopri5
    }
}

/// Runs the leaderboard on all cores (one run per thread at a time).
pub fn compute(base: &Scenario) -> Result<Leaderboard> {
    let jobs = ModelKind::ALL
        .into_iter()
        .flat_map(|m| ControllerKind::ALL.into_iter().map(move |c| (c, m)))
        .map(|(c, m)| Ok((c, m, scenario(base, c, m)?)))
        .collect::<Result<Vec<_>>>()?;
    let entries = crate::pool::map(&jobs, |(c, m, s)| {
        let entry = run_one(s, *c, *m);
        eprintln!("control: {} on {} done", c.name(), m.name());
        entry
    })?
    .into_iter()
    .collect::<Result<Vec<_>>>()?;
    Ok(Leaderboard {
        entries,
        move_end: base.trajectory.t2,
    })
}

/// One run, measured; a run that stops early (slack, a node out of order) keeps its metrics
/// over what it computed and says why.
fn run_one(s: &Scenario, controller: ControllerKind, model: ModelKind) -> Result<Entry> {
    let (assessed, failure) = match cdpr_bench::assess(s, &mut |_| {}) {
        Ok(a) => (a, None),
        Err(cdpr_bench::Error::Run(failure)) => {
            let why = failure.error.to_string();
            let Some(run) = failure.partial else {
                return Err(StudyError::Failed(format!(
                    "{} on {}: {why}",
                    controller.name(),
                    model.name()
                )));
            };
            (Assessed::partial(s, model, run), Some(why))
        }
        Err(e) => {
            return Err(StudyError::Failed(format!(
                "{} on {}: {e}",
                controller.name(),
                model.name()
            )));
        }
    };
    let run = &assessed.run;
    let (t, err, z) = (
        run.series.column(Channel::Time).unwrap_or_default(),
        run.series.column(Channel::Error).unwrap_or_default(),
        run.series.column(Channel::Z).unwrap_or_default(),
    );
    let z0 = z.first().copied().unwrap_or(0.0);
    let every = (1e-3 / SAMPLE_PERIOD).round() as usize;
    let errors = (0..t.len())
        .step_by(every.max(1))
        .map(|i| [t[i], err[i], z[i] - z0])
        .collect();
    let settled = assessed.metrics.windows.settled_start();
    let z_spectrum = crate::samples::spectrum(run, Channel::Z, settled, SAMPLE_PERIOD, (2.0, 2e3));
    Ok(Entry {
        controller,
        model,
        integrator: s.simulation.integrator,
        metrics: assessed.metrics,
        errors,
        z_spectrum,
        failure,
    })
}

/// A length in µm: three decimals, or two significant digits below 1 nm.
fn micro(v: f64) -> String {
    let um = v * 1e6;
    if !um.is_finite() {
        "–".into()
    } else if um.abs() < 1e-3 && um != 0.0 {
        format!("{um:.1e}")
    } else {
        format!("{um:.3}")
    }
}

fn plain(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        "–".into()
    }
}

impl Leaderboard {
    /// The paper PID's entry on `model`.
    fn pid(&self, model: ModelKind) -> Option<&Entry> {
        self.entries
            .iter()
            .find(|e| e.model == model && e.controller == ControllerKind::Pid)
    }

    /// Settling time after the move's end [s]; 0 where the error never left the band after the
    /// move ended.
    fn after_move(&self, t: f64) -> f64 {
        if t.is_nan() {
            t
        } else {
            (t - self.move_end).max(0.0)
        }
    }

    /// The leaderboard as a Markdown table.
    pub fn table(&self) -> String {
        let mut md = String::from(
            "| controller | model | path err [µm] | e_x max [µm] | e_z max [µm] | z p2p [1, 5] s [µm] \
             | x settles [s after move] | z settles [s after move] | T min [N] | T max [N] \
             | saturated [s] | least-stable mode: growth [1/s], ω [rad/s], kind | RHS evals \
             | factorisations | wall [s] | cost / PID |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for e in &self.entries {
            let m = &e.metrics;
            let c = &m.control;
            let cost = self
                .pid(e.model)
                .map_or(f64::NAN, |p| m.wall_s / p.metrics.wall_s);
            let name = match &e.failure {
                Some(_) => format!("{} (stopped)", e.controller.name()),
                None => e.controller.name().to_owned(),
            };
            let mode = format!(
                "{}, {}, {}",
                plain(c.least_stable_growth, 4),
                plain(c.least_stable_omega_rad_s, 0),
                c.least_stable_kind
            );
            let _ = writeln!(
                md,
                "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {mode} | {} | {} | {} | {} |",
                e.model.name(),
                micro(c.path_err_max_transition),
                micro(c.ex_max_transition),
                micro(c.ez_max_transition),
                micro(m.z_p2p),
                plain(self.after_move(c.x_settle_s), 3),
                plain(self.after_move(c.z_settle_s), 3),
                plain(c.tension_min, 1),
                plain(c.tension_max, 1),
                plain(c.saturated_s, 4),
                m.rhs_evals,
                m.factorisations,
                plain(m.wall_s, 2),
                plain(cost, 2),
            );
        }
        md
    }

    /// Per model, the controller with the smallest path error and each goal met or not.
    pub fn goals(&self) -> String {
        let mut md = format!(
            "| model | best controller | path err ≤ {} µm | z p2p ≤ {} µm | x, z settled ≤ {} s after move \
             | tensions in [{T_MIN}, {T_MAX}] N unsaturated | no growing mode |\n|---|---|---|---|---|---|---|\n",
            GOAL_PATH_ERROR * 1e6,
            GOAL_Z_P2P * 1e6,
            GOAL_SETTLE_AFTER_MOVE
        );
        for model in ModelKind::ALL {
            let best = self
                .entries
                .iter()
                .filter(|e| e.model == model && e.failure.is_none())
                .min_by(|a, b| {
                    let key = |e: &Entry| e.metrics.control.path_err_max_transition;
                    key(a).total_cmp(&key(b))
                });
            let Some(e) = best else {
                let _ = writeln!(md, "| {} | none finished | | | | | |", model.name());
                continue;
            };
            let (m, c) = (&e.metrics, &e.metrics.control);
            let mark =
                |ok: bool, value: String| format!("{} {value}", if ok { "yes" } else { "**no**" });
            let settle = self
                .after_move(c.x_settle_s)
                .max(self.after_move(c.z_settle_s));
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} |",
                model.name(),
                e.controller.name(),
                mark(
                    c.path_err_max_transition <= GOAL_PATH_ERROR,
                    micro(c.path_err_max_transition)
                ),
                mark(m.z_p2p <= GOAL_Z_P2P, micro(m.z_p2p)),
                mark(settle <= GOAL_SETTLE_AFTER_MOVE, plain(settle, 3)),
                mark(
                    c.saturated_s == 0.0,
                    format!("{}–{}", plain(c.tension_min, 1), plain(c.tension_max, 1))
                ),
                mark(
                    c.least_stable_growth <= 0.0,
                    plain(c.least_stable_growth, 4)
                ),
            );
        }
        md
    }

    /// `control.csv`: one row per controller and model, SI units.
    pub fn csv(&self) -> String {
        let mut csv = String::from(
            "controller,model,integrator,stopped,path_err_max_transition_m,ex_max_transition_m,\
             ez_max_transition_m,z_p2p_m,x_settle_s,z_settle_s,tension_min_n,tension_max_n,\
             saturated_s,least_stable_growth_1_s,least_stable_omega_rad_s,least_stable_kind,\
             rhs_evals,steps_accepted,factorisations,wall_s\n",
        );
        for e in &self.entries {
            let (m, c) = (&e.metrics, &e.metrics.control);
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                e.controller.name(),
                e.model.name(),
                e.integrator.name(),
                e.failure.is_some(),
                c.path_err_max_transition,
                c.ex_max_transition,
                c.ez_max_transition,
                m.z_p2p,
                c.x_settle_s,
                c.z_settle_s,
                c.tension_min,
                c.tension_max,
                c.saturated_s,
                c.least_stable_growth,
                c.least_stable_omega_rad_s,
                c.least_stable_kind,
                m.rhs_evals,
                m.steps_accepted,
                m.factorisations,
                m.wall_s
            );
        }
        csv
    }

    /// What keeps the massive-cable loops from the "no growing mode" goal, from this run's
    /// least-stable modes.
    fn growing_modes(&self) -> String {
        let mut md = String::from(
            "\n### Why a mode still grows on the massive-cable models\n\n\
             The reels command tension at one end of each cable; the controllers measure the \
             effector at the other. The paper's cable has no material damping, so every closed \
             loop that feeds the effector's motion back to the reels moves the cables' undamped \
             axial modes off the imaginary axis, to either side. The least-stable modes here:\n\n",
        );
        for e in &self.entries {
            let c = &e.metrics.control;
            if e.model != ModelKind::Elastic && c.least_stable_growth > 0.0 {
                let _ = writeln!(
                    md,
                    "- {} on {}: {} at {} rad/s grows at {} 1/s (ζ = {:.1e})",
                    e.controller.name(),
                    e.model.name(),
                    c.least_stable_kind,
                    plain(c.least_stable_omega_rad_s, 0),
                    plain(c.least_stable_growth, 4),
                    -c.least_stable_growth
                        / c.least_stable_growth.hypot(c.least_stable_omega_rad_s)
                );
            }
        }
        md.push_str(
            "\nThe paper PID's derivative term (filter 540 rad/s) destabilises the first axial \
             mode. Raw velocity feedback (computed-torque, LQR without `velocity_filter`) does so \
             at ≈ 0.67 K_d: 20 1/s at K_d = 30 1/s, 55 1/s for the LQR. The second-order filter \
             on the velocity error lags 180° at the first axial mode and damps it; the second \
             axial mode, whose end-to-end phase is reversed, is left at +0.03–0.04 1/s (an \
             e-folding time of 25–33 s, against a 5 s print move). Faster feedback reaches the \
             10 µm goal sooner but pushes this mode harder (error poles at 120 rad/s: 5.6 µm and \
             +0.59 1/s). Removing it needs damping the model does not have (the modes report's \
             axial-damping sweep gives the smallest that makes every mode decay) or a controller \
             that models the cable (none of these does: they are designed on the rigid cable).\n",
        );
        md
    }

    /// The leaderboard section (tables, stops, figures) shared with REPORT.md.
    pub fn section(&self, names: &[(String, String)]) -> String {
        let mut md = format!(
            "The paper's move (x 0.5 → 0.6 m in 0.2 s), tension limits [{T_MIN}, {T_MAX}] N, samples every \
             {SAMPLE_PERIOD} s; DOPRI5 on the elastic model, the implicit path on the lumped and FE models. \
             Controllers are designed on the rigid-cable (elastic) model and run unchanged on the others. \
             Settling: |e| < 10 µm from then on (`–`: never within the record).\n\n"
        );
        md.push_str(&self.table());
        md.push_str("\n### Goals, with the best controller per model\n\n");
        md.push_str(&self.goals());
        md.push_str(&self.growing_modes());
        let stops: Vec<String> = self
            .entries
            .iter()
            .filter_map(|e| {
                e.failure
                    .as_ref()
                    .map(|why| format!("- {} on {}: {why}", e.controller.name(), e.model.name()))
            })
            .collect();
        if !stops.is_empty() {
            md.push_str("\nRuns that stopped early (their metrics cover what they computed):\n\n");
            md.push_str(&stops.join("\n"));
            md.push('\n');
        }
        md.push('\n');
        for (name, title) in names {
            let _ = writeln!(md, "![{title}]({name}.svg)\n");
        }
        md
    }
}
