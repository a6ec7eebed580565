//! A spatial robot's move under every controller and every tension distribution
//! (`cargo xtask spatial-moves`): the table of docs/spatial.md — path error during the move and
//! 1 s after it, the tension range, the time the limits clamped the command, and the reels'
//! largest speed. The firmware's `length` controller is run with each flex compensation (on
//! the elastic cables; lumped lines run the tension controllers).

use crate::Result;
use cdpr_bench::ModelKind;
use cdpr_bench::analysis::spatial::SpatialMetrics;
use cdpr_bench::core::robot::distribution::DistributionMethod;
use cdpr_bench::core::runner::Observer;
use cdpr_bench::core::scenario::{ControllerKind, FlexCompensation, IntegratorKind, Scenario};

/// One run of the table.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MoveRow {
    /// The controller, with the flex compensation for `length` ("length/static", …).
    pub controller: String,
    pub distribution: &'static str,
    pub metrics: SpatialMetrics,
    /// Accepted DOPRI5 steps and right-hand-side evaluations.
    pub steps: u64,
    pub rhs_evaluations: u64,
}

/// The controllers of the table, each a change of the scenario's `[controller]`.
fn controllers() -> Vec<(String, ControllerKind, FlexCompensation)> {
    let mut list: Vec<_> = [
        ControllerKind::Pid,
        ControllerKind::ComputedTorque,
        ControllerKind::Lqr,
    ]
    .into_iter()
    .map(|k| (k.name().to_owned(), k, FlexCompensation::Static))
    .collect();
    for flex in [
        FlexCompensation::Static,
        FlexCompensation::Dynamic,
        FlexCompensation::None,
    ] {
        let name = format!("length/{}", flex_name(flex));
        list.push((name, ControllerKind::Length, flex));
    }
    list
}

fn flex_name(flex: FlexCompensation) -> &'static str {
    match flex {
        FlexCompensation::Static => "static",
        FlexCompensation::Dynamic => "dynamic",
        FlexCompensation::None => "none",
    }
}

/// Every controller × every distribution on `scenario`'s move, on every core (rows in the
/// table's order, whatever the machine).
pub fn table(scenario: &Scenario) -> Result<Vec<MoveRow>> {
    table_with(scenario, &DistributionMethod::ALL)
}

/// Every controller × each of `methods` on `scenario`'s move (rows in that order).
pub fn table_with(scenario: &Scenario, methods: &[DistributionMethod]) -> Result<Vec<MoveRow>> {
    let mut jobs = Vec::new();
    let model = cdpr_bench::ModelConfig::from_scenario(scenario)?.kind;
    let massive = model != ModelKind::Elastic;
    for (name, kind, flex) in controllers() {
        for &method in methods {
            let mut s = scenario.clone();
            s.controller.kind = kind;
            s.controller.flex_compensation = flex;
            s.controller.distribution = method;
            if massive && kind == ControllerKind::Length {
                // Reels driven by length on massive lines run on DOPRI5 only.
                s.simulation.integrator = IntegratorKind::Dopri5;
            }
            s.validate()?;
            jobs.push((name.clone(), method, s));
        }
    }
    let rows = crate::pool::map(&jobs, |(name, method, s)| {
        let done = cdpr_bench::simulate_spatial(s, &mut Observer::progress(&mut |_| {}))?;
        Ok::<_, cdpr_bench::Error>(MoveRow {
            controller: name.clone(),
            distribution: method.name(),
            metrics: done.metrics,
            steps: done.run.stats.steps_accepted,
            rhs_evaluations: done.run.stats.rhs_evals,
        })
    })?;
    Ok(rows.into_iter().collect::<std::result::Result<_, _>>()?)
}

/// The table in Markdown.
pub fn markdown(rows: &[MoveRow]) -> String {
    let mut out = String::from(
        "| controller | distribution | path error in the move [m] | 1 s after [m] | \
         tensions [N] | saturated [s] | reel speed [m/s] | steps |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let m = &r.metrics;
        let reel = m.reel_speed_max.iter().copied().fold(0.0, f64::max);
        out += &format!(
            "| {} | {} | {} | {} | {:.1} … {:.1} | {:.3} | {:.3} | {} |\n",
            r.controller,
            r.distribution,
            metres(m.path_err_max_move),
            metres(m.path_err_max_after_1s),
            m.tension_min,
            m.tension_max,
            m.saturated_s,
            reel,
            r.steps
        );
    }
    out
}

/// A length in metres with three significant digits ("—" where not measured).
fn metres(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "—".into()
    }
}
