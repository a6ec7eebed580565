//! The metrics of a spatial robot's run (MODELS.md §11): the 3-D path error during and after the
//! move, each cable's tension range, the time the tension limits clamped the command, and each
//! reel's largest speed — from the run's samples and the reference they were asked to follow.

use crate::control_metrics::TRANSITION_TAIL;
use cdpr_core::channel::Channel;
use cdpr_core::robot::{CableId, Vector};
use cdpr_core::runner::Run;
use cdpr_core::shaper::Impulses;
use cdpr_core::trajectory::Segment;

/// What the metrics compare the run with.
#[derive(Debug, Clone)]
pub struct SpatialContext {
    /// The move (None: two cables in space, the plane's move x1 → x2 in the `x_ref` channel
    /// with y and z held at the start).
    pub path: Option<Segment<3>>,
    /// The input shaper's impulses (None: unshaped).
    pub shaper: Option<Impulses>,
    /// When the (shaped) reference reaches the end [s].
    pub move_start: f64,
    pub move_end: f64,
    pub controller: &'static str,
    pub distribution: &'static str,
}

/// The metrics ([`SpatialMetrics::UNITS`]); NaN (null in JSON) where the record does not reach
/// a metric's window.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SpatialMetrics {
    pub controller: &'static str,
    pub distribution: &'static str,
    pub cables: usize,
    /// max |p_ref − p| over [t1, move end] [m].
    pub path_err_max_move: f64,
    /// max |p_ref − p| over [t1, move end + 0.05 s] [m] (MODELS.md §7's transition window).
    pub path_err_max_transition: f64,
    /// max |p_ref − p| from 1 s after the move's end to the run's end [m].
    pub path_err_max_after_1s: f64,
    /// Per cable, cable 1 first [N].
    pub cable_tension_min: Vec<f64>,
    pub cable_tension_max: Vec<f64>,
    pub tension_min: f64,
    pub tension_max: f64,
    /// Time the tension limits clamped the controller's tensions [s].
    pub saturated_s: f64,
    /// Per cable, the largest |dl0_i/dt|: the unstrained length the reel winds per second
    /// [m/s] (central differences of the samples).
    pub reel_speed_max: Vec<f64>,
    /// The tensions at rest at the start [N].
    pub rest_tensions: Vec<f64>,
    pub move_end_s: f64,
    /// Largest |E − E0 − W + D − ΣΔE| over the run [J]: the energy balance's residual, with the
    /// reels' work W and the model's events (MODELS.md §4's audit).
    pub energy_residual_max: f64,
    /// Model events (massive lines: nodes passing a pulley; 0 for the elastic cables).
    pub pulley_events: usize,
}

impl SpatialMetrics {
    /// The unit of each key that has one.
    pub const UNITS: [(&'static str, &'static str); 11] = [
        ("path_err_max_move", "m"),
        ("path_err_max_transition", "m"),
        ("path_err_max_after_1s", "m"),
        ("cable_tension_min", "N"),
        ("cable_tension_max", "N"),
        ("tension_min", "N"),
        ("tension_max", "N"),
        ("saturated_s", "s"),
        ("reel_speed_max", "m/s"),
        ("rest_tensions", "N"),
        ("energy_residual_max", "J"),
    ];

    /// The metrics of `run` (a spatial robot's: channels x, y, z, T1 … Tm, l0_1 … l0_m,
    /// saturated).
    pub fn from_run(run: &Run, context: &SpatialContext) -> Self {
        let s = &run.series;
        let column = |c: Channel| s.channel(c).unwrap_or(&[]);
        let t = column(Channel::Time);
        let m = run.equilibrium.tensions.len();
        let error = path_errors(run, context, column(Channel::XRef));
        let window_max = |from: f64, to: f64| max_error_in(t, &error, from, to);
        let t_end = t.last().copied().unwrap_or(0.0);
        let tensions: Vec<&[f64]> = CableId::all(m)
            .map(|c| column(Channel::Tension(c)))
            .collect();
        let range = |v: &[f64], f: fn(f64, f64) -> f64, init: f64| v.iter().copied().fold(init, f);
        let cable_tension_min: Vec<f64> = tensions
            .iter()
            .map(|v| range(v, f64::min, f64::INFINITY))
            .collect();
        let cable_tension_max: Vec<f64> = tensions
            .iter()
            .map(|v| range(v, f64::max, f64::NEG_INFINITY))
            .collect();
        let saturated = column(Channel::Saturated);
        let saturated_s = saturated.iter().filter(|&&v| v != 0.0).count() as f64
            * t.get(1).map_or(0.0, |t1| t1 - t[0]);
        let reel_speed_max = reel_speeds(run, t, m);
        let after = context.move_end + 1.0;
        Self {
            controller: context.controller,
            distribution: context.distribution,
            cables: m,
            path_err_max_move: window_max(context.move_start, context.move_end),
            path_err_max_transition: window_max(
                context.move_start,
                context.move_end + TRANSITION_TAIL,
            ),
            path_err_max_after_1s: if t_end >= after {
                window_max(after, t_end)
            } else {
                f64::NAN
            },
            tension_min: range(&cable_tension_min, f64::min, f64::INFINITY),
            tension_max: range(&cable_tension_max, f64::max, f64::NEG_INFINITY),
            cable_tension_min,
            cable_tension_max,
            saturated_s,
            reel_speed_max,
            rest_tensions: run.equilibrium.tensions.to_vec(),
            move_end_s: context.move_end,
            energy_residual_max: column(Channel::EResidual)
                .iter()
                .fold(0.0, |m: f64, v| m.max(v.abs())),
            pulley_events: run.events.len(),
        }
    }
}

/// The path error |p_ref − p| [m] at each sample, against the (shaped) move or the plane's x_ref.
fn path_errors(run: &Run, context: &SpatialContext, x_ref: &[f64]) -> Vec<f64> {
    let start = positions(run)
        .next()
        .map_or(Vector::<3>::repeat(f64::NAN), |(_, p)| p);
    positions(run)
        .enumerate()
        .map(|(i, (ti, p))| {
            let reference = match &context.path {
                Some(path) => path.shaped(context.shaper.as_ref(), ti, false)[0],
                None => Vector::<3>::new(x_ref[i], start[1], start[2]),
            };
            (reference - p).norm()
        })
        .collect()
}

/// The largest path error over [from, to] [s]; NaN where the record does not reach the window.
fn max_error_in(t: &[f64], error: &[f64], from: f64, to: f64) -> f64 {
    // The whole window recorded (to a picosecond of the sample grid).
    let reached = t.last().is_some_and(|&end| end >= to - 1e-12);
    let r = t.partition_point(|&v| v < from)..t.partition_point(|&v| v <= to);
    if !reached || r.is_empty() {
        return f64::NAN;
    }
    error[r].iter().copied().fold(0.0, f64::max)
}

/// Each reel's largest paying-out speed [m/s] over the run, cable 1 first.
fn reel_speeds(run: &Run, t: &[f64], m: usize) -> Vec<f64> {
    let s = &run.series;
    // The paid-out unstrained length: the elastic model's l0_i, a massive model's free
    // unstrained length l_free_i (its rate is the cable's passage over the pulley).
    (1..=m)
        .map(|i| {
            let paid_out = s
                .channel_named(&format!("l0_{i}"))
                .or_else(|| s.channel_named(&format!("l_free_{i}")));
            max_rate(t, paid_out.unwrap_or(&[]))
        })
        .collect()
}

/// max |dv/dt| of samples `v` at times `t`, by central differences (one-sided at the ends).
fn max_rate(t: &[f64], v: &[f64]) -> f64 {
    if v.len() < 2 || t.len() != v.len() {
        return f64::NAN;
    }
    let n = v.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            ((v[b] - v[a]) / (t[b] - t[a])).abs()
        })
        .fold(0.0, f64::max)
}

/// A spatial run's samples: time [s] and effector position [m].
pub fn positions(run: &Run) -> impl Iterator<Item = (f64, Vector<3>)> + '_ {
    let s = &run.series;
    let column = |c: Channel| s.channel(c).unwrap_or(&[]);
    let (t, x, y, z) = (
        column(Channel::Time),
        column(Channel::X),
        column(Channel::Y),
        column(Channel::Z),
    );
    (0..t.len()).map(move |i| (t[i], Vector::<3>::new(x[i], y[i], z[i])))
}
