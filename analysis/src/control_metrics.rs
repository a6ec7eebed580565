//! The vibration-control metrics of a run: how closely the effector holds the printing path
//! during the move, how soon x and z settle, what the tensions did and how long they were
//! clamped. Errors in z are measured from the start height z0 (the held reference where z is
//! held, the start where z is free), so every controller is judged against the same straight
//! line.

use crate::metrics::Columns;
use cdpr_core::controller::TensionLimits;
use cdpr_core::runner::Run;
use std::collections::BTreeMap;

/// The transition window ends this long after the move (or the shaped reference) ends [s].
pub const TRANSITION_TAIL: f64 = 0.05;
/// The settling band of x and z [m] (10 µm: a tenth of the thinnest printed layer).
pub const SETTLE_BAND: f64 = 1e-5;
/// The window of the settled mean of z at the record's end [s].
pub const Z_MEAN_WINDOW: f64 = 0.5;

/// What the control metrics need to know of the run besides its samples.
#[derive(Debug, Clone, Copy)]
pub struct ControlContext<'a> {
    /// The controller's scenario name.
    pub controller: &'a str,
    /// The move's start and end [s] (the end of the shaped reference where one is shaped).
    pub move_start: f64,
    pub move_end: f64,
    pub limits: TensionLimits,
    /// Sample period [s].
    pub sample_period: f64,
    /// The smallest variation of a position the run resolves [m] (the integrator's absolute
    /// tolerance): a signal that varies less over a window has no spectral peak there.
    pub resolution: f64,
    /// The input shaper: its name, design frequency [rad/s] and damping ratio (NaN unshaped).
    pub shaper: &'a str,
    pub shaper_frequency: f64,
    pub shaper_damping: f64,
}

/// Keys of `metrics.json` (SI units, in [`crate::metrics::UNITS`]; NaN is null).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ControlMetrics {
    pub controller: String,
    /// max √(e_x² + e_z²) over [move start, move end + 0.05 s] [m].
    pub path_err_max_transition: f64,
    /// max |e_x|, max |e_z| over the same window [m].
    pub ex_max_transition: f64,
    pub ez_max_transition: f64,
    /// The time after which |e_x| stays below 10 µm [s] (null if it never does).
    pub x_settle_s: f64,
    /// The time after which |z − mean z over the last 0.5 s| stays below 10 µm [s].
    pub z_settle_s: f64,
    /// Extremes of both commanded tensions over the record [N].
    pub tension_min: f64,
    pub tension_max: f64,
    /// Time with a commanded tension at a limit [s] (each sample standing for the sample period
    /// around it, clipped to the record).
    pub saturated_s: f64,
    /// Largest growth rate of the closed loop's modes at the end of the move [1/s] (from the
    /// modal analysis; null where it was not done).
    pub least_stable_growth: f64,
    /// That mode's frequency [rad/s] and kind ("axial cable 2", …; empty where not done).
    pub least_stable_omega_rad_s: f64,
    pub least_stable_kind: String,
    /// The input shaper ("none", "zv", …), the mode it was designed for (natural frequency
    /// [rad/s], damping ratio; null unshaped) and when the shaped reference reaches x2 [s].
    pub shaper: String,
    pub shaper_frequency_rad_s: f64,
    pub shaper_damping: f64,
    pub move_end_s: f64,
    /// The controller's designed gains (the LQR's K, row-major 2 × 6, …).
    pub controller_gains: BTreeMap<String, Vec<f64>>,
}

impl ControlMetrics {
    /// Computes the metrics of `run`'s samples.
    pub fn from_run(run: &Run, context: &ControlContext) -> Self {
        Self::from_columns(&Columns::of(run), context)
    }

    /// Computes the metrics of a run's channels.
    pub fn from_columns(c: &Columns, context: &ControlContext) -> Self {
        let (t, z, err) = (c.t, c.z, c.err);
        let z0 = z.first().copied().unwrap_or(f64::NAN);
        let half = 0.5 * context.sample_period;
        let transition = t.partition_point(|&v| v < context.move_start - half)
            ..t.partition_point(|&v| v <= context.move_end + TRANSITION_TAIL + half);
        // Maxima over the window; NaN where the record does not reach it.
        let (mut path, mut ex, mut ez) = (f64::NAN, f64::NAN, f64::NAN);
        if !transition.is_empty() {
            (path, ex, ez) = (0.0, 0.0, 0.0);
        }
        for i in transition {
            let (e_x, e_z) = (err[i], z[i] - z0);
            path = path.max(e_x.hypot(e_z));
            ex = ex.max(e_x.abs());
            ez = ez.max(e_z.abs());
        }
        let t_end = t.last().copied().unwrap_or(0.0);
        let last = t.partition_point(|&v| v < t_end - Z_MEAN_WINDOW - half);
        let z_end = mean(&z[last..]);
        let tensions = c.tensions.iter().flat_map(|v| v.iter());
        let at_limit = |v: f64| v <= context.limits.t_min || v >= context.limits.t_max;
        let saturated: Vec<bool> = (0..t.len())
            .map(|i| c.tensions.iter().any(|v| at_limit(v[i])))
            .collect();
        Self {
            controller: context.controller.to_owned(),
            path_err_max_transition: path,
            ex_max_transition: ex,
            ez_max_transition: ez,
            x_settle_s: settle_time(t, err.iter().map(|e| e.abs())),
            z_settle_s: settle_time(t, z.iter().map(|v| (v - z_end).abs())),
            tension_min: tensions.clone().fold(f64::NAN, |m, &v| v.min(m)),
            tension_max: tensions.fold(f64::NAN, |m, &v| v.max(m)),
            saturated_s: saturated_time(&saturated, context.sample_period),
            least_stable_growth: f64::NAN,
            least_stable_omega_rad_s: f64::NAN,
            least_stable_kind: String::new(),
            shaper: context.shaper.to_owned(),
            shaper_frequency_rad_s: context.shaper_frequency,
            shaper_damping: context.shaper_damping,
            move_end_s: context.move_end,
            controller_gains: BTreeMap::new(),
        }
    }

    /// Adds to `unavailable` the metrics whose windows a record ending at `t_end` does not
    /// reach, for a move ending at `move_end` [s] (the caller sets them NaN).
    pub(crate) fn mark_unavailable(
        &self,
        move_end: f64,
        t_end: f64,
        unavailable: &mut Vec<(&'static str, String)>,
    ) {
        let transition_end = move_end + TRANSITION_TAIL;
        if t_end < transition_end {
            let why = format!(
                "the run ends at {t_end} s, before the transition window ends at the move's end + {TRANSITION_TAIL} s = {transition_end} s"
            );
            for key in [
                "path_err_max_transition",
                "ex_max_transition",
                "ez_max_transition",
            ] {
                unavailable.push((key, why.clone()));
            }
        }
        if t_end - Z_MEAN_WINDOW < move_end {
            let why = format!(
                "z's settled level is its mean over the record's last {Z_MEAN_WINDOW} s, from {} s, which begins before the move ends at {move_end} s",
                t_end - Z_MEAN_WINDOW
            );
            unavailable.push(("z_settle_s", why));
        }
        for (key, value) in [
            ("x_settle_s", self.x_settle_s),
            ("z_settle_s", self.z_settle_s),
        ] {
            if value.is_nan() {
                let why = format!(
                    "the deviation is still ≥ {SETTLE_BAND} m at the record's end, {t_end} s"
                );
                unavailable.push((key, why));
            }
        }
    }

    /// Sets the metric `key` to NaN; false for a key that is none of these.
    pub(crate) fn set_nan(&mut self, key: &str) -> bool {
        let slot = match key {
            "path_err_max_transition" => &mut self.path_err_max_transition,
            "ex_max_transition" => &mut self.ex_max_transition,
            "ez_max_transition" => &mut self.ez_max_transition,
            "x_settle_s" => &mut self.x_settle_s,
            "z_settle_s" => &mut self.z_settle_s,
            _ => return false,
        };
        *slot = f64::NAN;
        true
    }
}

/// Time at a limit [s]: each sample stands for the sample period centred on it, clipped to the
/// record (so a record at a limit throughout counts its length, (n − 1)·Δt, no more).
fn saturated_time(saturated: &[bool], sample_period: f64) -> f64 {
    let count = saturated.iter().filter(|&&s| s).count() as f64;
    let ends = [saturated.first(), saturated.last()]
        .into_iter()
        .filter(|s| s.copied() == Some(true))
        .count() as f64;
    (count - 0.5 * ends) * sample_period
}

/// The first sample time after the last sample whose deviation is ≥ [`SETTLE_BAND`]; the
/// record's start if none is; NaN if the last sample is outside the band.
fn settle_time(t: &[f64], deviation: impl Iterator<Item = f64>) -> f64 {
    let mut last_out = None;
    for (i, d) in deviation.enumerate() {
        if d >= SETTLE_BAND || d.is_nan() {
            last_out = Some(i);
        }
    }
    match last_out {
        None => t.first().copied().unwrap_or(f64::NAN),
        Some(i) if i + 1 < t.len() => t[i + 1],
        Some(_) => f64::NAN,
    }
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.iter().sum::<f64>() / v.len() as f64
}
