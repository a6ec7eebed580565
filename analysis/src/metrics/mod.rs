//! The metrics of MODELS.md §7 computed from a run's samples: the numbers the paper reports
//! (tension extremes and settling, error, overshoot, z oscillation, spectral peaks) and the cost.
//!
//! Every window is defined from the move [t1, its end] and the record's end t_final
//! ([`Windows`]), so that a key measures what its name says whatever the timing: the paper's
//! "after 1 s" is [move end + 0.8 s, t_final] (= [1, 5] s for its move ending at t2 = 0.2 s; a
//! shaped move ends when its shaped reference does). A metric whose window the run does not
//! reach, or is too short for, and a peak of a signal that has none, is NaN (null in
//! `metrics.json`) and [`Metrics::unavailable`] says why. [`UNITS`] and the field docs below are
//! the definitions.

mod cables;
mod spectral;

pub use cables::{CableTensions, FurtherCables};
pub use spectral::{SettledPeaks, SpectralPeaks};

use crate::control_metrics::{ControlContext, ControlMetrics};
use cdpr_core::channel::Channel;
use cdpr_core::robot::CableId;
use cdpr_core::runner::Run;
use cdpr_core::trajectory::Step5;
use spectral::Spectra;

/// The settled window starts this long after the move ends [s]: the paper's "after 1 s" for its
/// move ending at t2 = 0.2 s.
pub const SETTLE_AFTER_MOVE: f64 = 0.8;
/// The strict settled window of MODELS.md §8 (paper: [1.5, 5] s) starts this long after the
/// move ends [s].
pub const STRICT_SETTLE_AFTER_MOVE: f64 = 1.3;
/// Length of the window of the settled means at the end of the record [s] (paper: [4, 5] s).
pub const LAST_WINDOW: f64 = 1.0;
/// Shortest window a spectral peak is taken over [s]: its bins are then at most 2π rad/s apart.
pub const MIN_SPECTRAL_WINDOW: f64 = 1.0;
/// The high-frequency search starts above the physics of the effector (MODELS.md §7) [rad/s].
pub const HF_FROM: f64 = 100.0;
/// Refined peaks ignore the drift below this frequency [rad/s].
pub const REFINED_FROM: f64 = 2.0;
/// Zero-padding factor of the refined spectrum.
pub const PAD: usize = 16;
/// High-frequency local maxima kept in the metrics.
pub const HF_PEAKS: usize = 8;
/// Two events of one cable closer than this are counted as chatter [s].
pub const CHATTER_WINDOW: f64 = 1e-3;

/// The windows of a run's metrics [s], each [start, end]; a window the record does not reach is
/// None (null in `metrics.json`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Windows {
    /// The move: [t1, its end] (t2, or the end of the shaped reference where one is shaped).
    pub transition: [f64; 2],
    /// After the move has settled: [move end + [`SETTLE_AFTER_MOVE`], t_final].
    pub settled: Option<[f64; 2]>,
    /// [move end + [`STRICT_SETTLE_AFTER_MOVE`], t_final].
    pub settled_strict: Option<[f64; 2]>,
    /// The record's last [`LAST_WINDOW`]: [t_final − 1 s, t_final].
    pub last: Option<[f64; 2]>,
    /// The whole record: [0, t_final].
    pub record: [f64; 2],
}

impl Windows {
    /// The windows of a move over [`move_start`, `move_end`] recorded until `t_end` [s].
    pub fn new(move_start: f64, move_end: f64, t_end: f64) -> Self {
        let reached = |start: f64| (start < t_end).then_some([start, t_end]);
        Self {
            transition: [move_start, move_end],
            settled: reached(move_end + SETTLE_AFTER_MOVE),
            settled_strict: reached(move_end + STRICT_SETTLE_AFTER_MOVE),
            last: reached((t_end - LAST_WINDOW).max(0.0)),
            record: [0.0, t_end],
        }
    }

    /// Where the settled window starts (whether or not the record reaches it) [s].
    pub fn settled_start(&self) -> f64 {
        self.transition[1] + SETTLE_AFTER_MOVE
    }
}

/// MODELS.md §7 metrics of one run. Keys are those of `metrics.json`; NaN is null there.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Metrics {
    pub model: String,
    /// The windows the metrics below are measured over.
    pub windows: Windows,
    /// Each metric that is NaN because the run does not reach or fill its window, and why.
    pub unavailable: std::collections::BTreeMap<String, String>,
    /// Minimum of the commanded T1 [N] and when [s].
    pub t1_min: f64,
    pub t1_min_time: f64,
    pub t1_max: f64,
    pub t1_max_time: f64,
    pub t2_min: f64,
    pub t2_min_time: f64,
    pub t2_max: f64,
    pub t2_max_time: f64,
    /// Commanded tensions at t_final [N].
    pub t1_final: f64,
    pub t2_final: f64,
    /// Means of the commanded tensions over the `last` window, which must lie in the settled
    /// one [N].
    pub t1_mean_last_1s: f64,
    pub t2_mean_last_1s: f64,
    /// The same six keys for cables 3…m (`t3_min`, `t3_min_time`, …, `t3_mean_last_1s`, …):
    /// present only for a robot of more than two cables.
    #[serde(flatten)]
    pub further_cables: FurtherCables,
    /// max |x_ref − x| over the `transition` window [m].
    pub err_max_transition: f64,
    /// max |x_ref − x| over the `settled` window [m].
    pub err_max_settled: f64,
    /// max |x_ref − x| over the `settled_strict` window [m].
    pub err_max_settled_strict: f64,
    /// max over the run of (x − x2)·sign(x2 − x1) [m] (negative: no overshoot).
    pub overshoot: f64,
    /// Mean and peak-to-peak of z over the `settled` window [m].
    pub z_mean: f64,
    pub z_p2p: f64,
    /// The spectral peaks of z and of the error.
    #[serde(flatten)]
    pub spectral: SpectralPeaks,
    /// Effector z and PID force at the initial equilibrium [m, N].
    pub z0: f64,
    pub f0: f64,
    /// Largest |E − E0 − W + D − ΣΔE| over the run [J] (energy balance residual).
    pub energy_residual_max: f64,
    /// Model events (lumped: nodes passing a pulley).
    pub pulley_events: usize,
    /// Energy removed by the events, −ΣΔE [J] (positive: lost).
    pub pulley_energy_loss: f64,
    /// Events less than [`CHATTER_WINDOW`] after the previous event of the same cable (a node
    /// hovering at the pulley).
    pub pulley_chatter: usize,
    /// Integrator cost.
    pub rhs_evals: u64,
    pub steps_accepted: u64,
    pub steps_rejected: u64,
    /// Implicit path only (0 for DOPRI5): Newton iterations, iteration-matrix evaluations,
    /// numeric LU factorisations and those of them that pivoted afresh.
    pub newton_iterations: u64,
    pub jacobian_evals: u64,
    pub factorisations: u64,
    pub pivotings: u64,
    pub wall_s: f64,
    /// The vibration-control metrics.
    #[serde(flatten)]
    pub control: ControlMetrics,
}

/// The unit of every key of [`Metrics`] as `metrics.json` writes it ("" for counts and names;
/// `err_hf_peaks` holds [rad/s, dB] pairs).
pub const UNITS: &[(&str, &str)] = &[
    ("model", ""),
    ("windows", "s"),
    ("unavailable", ""),
    ("t1_min", "N"),
    ("t1_min_time", "s"),
    ("t1_max", "N"),
    ("t1_max_time", "s"),
    ("t2_min", "N"),
    ("t2_min_time", "s"),
    ("t2_max", "N"),
    ("t2_max_time", "s"),
    ("t1_final", "N"),
    ("t2_final", "N"),
    ("t1_mean_last_1s", "N"),
    ("t2_mean_last_1s", "N"),
    ("err_max_transition", "m"),
    ("err_max_settled", "m"),
    ("err_max_settled_strict", "m"),
    ("overshoot", "m"),
    ("z_mean", "m"),
    ("z_p2p", "m"),
    ("z_peak_rad_s", "rad/s"),
    ("err_peak_rad_s", "rad/s"),
    ("z_plain_peak_rad_s", "rad/s"),
    ("err_plain_peak_rad_s", "rad/s"),
    ("z_fft_record_rad_s", "rad/s"),
    ("z_fft_record_bin", ""),
    ("err_hf_peak_rad_s", "rad/s"),
    ("err_hf_peak_db", "dB"),
    ("err_hf_peaks", "[rad/s, dB]"),
    ("z0", "m"),
    ("f0", "N"),
    ("energy_residual_max", "J"),
    ("pulley_events", ""),
    ("pulley_energy_loss", "J"),
    ("pulley_chatter", ""),
    ("rhs_evals", ""),
    ("steps_accepted", ""),
    ("steps_rejected", ""),
    ("newton_iterations", ""),
    ("jacobian_evals", ""),
    ("factorisations", ""),
    ("pivotings", ""),
    ("wall_s", "s"),
    ("controller", ""),
    ("path_err_max_transition", "m"),
    ("ex_max_transition", "m"),
    ("ez_max_transition", "m"),
    ("x_settle_s", "s"),
    ("z_settle_s", "s"),
    ("tension_min", "N"),
    ("tension_max", "N"),
    ("saturated_s", "s"),
    ("least_stable_growth", "1/s"),
    ("least_stable_omega_rad_s", "rad/s"),
    ("least_stable_kind", ""),
    ("shaper", ""),
    ("shaper_frequency_rad_s", "rad/s"),
    ("shaper_damping", ""),
    ("move_end_s", "s"),
    ("controller_gains", "SI"),
];

/// Peak memory [B] of a run of `samples` samples × `channels` channels and its metrics: the
/// samples themselves (8 B each) and the spectra of a window as long as the record, two at a
/// time (each ~56 B a sample: the FFT's input and output, the coefficients kept and their
/// amplitudes). 2e7 samples of 22 channels need ~6 GB.
pub fn memory_estimate(samples: f64, channels: usize) -> f64 {
    let series = samples * channels as f64 * 8.0;
    let spectra = 2.0 * 56.0 * samples;
    series + spectra
}

/// The channels of a run the metrics read.
pub struct Columns<'a> {
    pub t: &'a [f64],
    pub x: &'a [f64],
    pub z: &'a [f64],
    pub err: &'a [f64],
    /// Every cable's commanded tension, cable 1 first.
    pub tensions: Vec<&'a [f64]>,
    pub e_residual: &'a [f64],
}

impl<'a> Columns<'a> {
    /// The run's channels (empty where the run has none).
    pub fn of(run: &'a Run) -> Self {
        let s = &run.series;
        let col = |channel: Channel| s.channel(channel).unwrap_or_default();
        Self {
            t: col(Channel::Time),
            x: col(Channel::X),
            z: col(Channel::Z),
            err: col(Channel::Error),
            tensions: (0..)
                .map_while(|i| s.channel(Channel::Tension(CableId(i))))
                .collect(),
            e_residual: col(Channel::EResidual),
        }
    }
}

/// Index range of the samples with t in [a, b] (`include_end`) or [a, b), on a grid of period dt.
fn window(t: &[f64], a: f64, b: f64, include_end: bool, dt: f64) -> std::ops::Range<usize> {
    let half = 0.5 * dt;
    let start = t.partition_point(|&v| v < a - half);
    let end = if include_end {
        t.partition_point(|&v| v <= b + half)
    } else {
        t.partition_point(|&v| v < b - half)
    };
    start..end.max(start)
}

fn extreme(t: &[f64], v: &[f64], better: impl Fn(f64, f64) -> bool) -> (f64, f64) {
    let mut best = (f64::NAN, f64::NAN);
    for (&ti, &vi) in t.iter().zip(v) {
        if best.1.is_nan() || better(vi, best.1) {
            best = (ti, vi);
        }
    }
    best
}

fn max_abs(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.iter().sum::<f64>() / v.len() as f64
}

fn peak_to_peak(v: &[f64]) -> f64 {
    v.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
        - v.iter().fold(f64::INFINITY, |m, &x| m.min(x))
}

/// Events less than [`CHATTER_WINDOW`] after the previous event of the same cable.
fn chatter(events: &[cdpr_core::model::ModelEvent]) -> usize {
    let mut last: Vec<f64> = Vec::new();
    let mut count = 0;
    for e in events {
        let slot = e.cable.saturating_sub(1);
        if last.len() <= slot {
            last.resize(slot + 1, f64::NEG_INFINITY);
        }
        if e.t - last[slot] < CHATTER_WINDOW {
            count += 1;
        }
        last[slot] = e.t;
    }
    count
}

/// max over the run of (x − x2)·sign(x2 − x1) [m] (negative: no overshoot).
fn overshoot(x: &[f64], step5: &Step5) -> f64 {
    let direction = (step5.x2 - step5.x1).signum();
    x.iter()
        .fold(f64::NEG_INFINITY, |m, &v| m.max((v - step5.x2) * direction))
}

impl Metrics {
    /// Computes every metric of `run` sampled every `dt` [s] on the trajectory `step5`, with
    /// the controller's `context` (whose move end is the shaped reference's where one is shaped).
    pub fn from_run(run: &Run, step5: &Step5, dt: f64, context: &ControlContext) -> Self {
        let c = Columns::of(run);
        let (t, x, z, err) = (c.t, c.x, c.z, c.err);
        let cable = |i: usize| c.tensions.get(i).copied().unwrap_or_default();
        let (t1, t2) = (cable(0), cable(1));
        let t_end = t.last().copied().unwrap_or(0.0);
        let windows = Windows::new(context.move_start, context.move_end, t_end);

        let [(t1_min_time, t1_min), (t2_min_time, t2_min)] =
            [t1, t2].map(|v| extreme(t, v, |a, b| a < b));
        let [(t1_max_time, t1_max), (t2_max_time, t2_max)] =
            [t1, t2].map(|v| extreme(t, v, |a, b| a > b));
        let settled_start = windows.settled_start();
        let strict_start = context.move_end + STRICT_SETTLE_AFTER_MOVE;
        let last = window(t, t_end - LAST_WINDOW, t_end, true, dt);
        let transition = window(t, context.move_start, context.move_end, true, dt);
        let settled = window(t, settled_start, t_end, true, dt);
        let strict = window(t, strict_start, t_end, true, dt);
        let spectral = window(t, settled_start, t_end, false, dt);

        let zs = &z[settled.clone()];

        let long_enough = t_end - settled_start >= MIN_SPECTRAL_WINDOW;
        let spectral = SpectralPeaks::of(Spectra::of(
            z,
            err,
            spectral,
            long_enough,
            t_end,
            dt,
            context.resolution,
        ));
        let further_cables = c.tensions[c.tensions.len().min(2)..]
            .iter()
            .map(|v| CableTensions::of(t, v, last.clone()))
            .collect();
        let mut metrics = Self {
            model: run.model.to_owned(),
            windows,
            unavailable: Default::default(),
            t1_min,
            t1_min_time,
            t1_max,
            t1_max_time,
            t2_min,
            t2_min_time,
            t2_max,
            t2_max_time,
            t1_final: t1.last().copied().unwrap_or(f64::NAN),
            t2_final: t2.last().copied().unwrap_or(f64::NAN),
            t1_mean_last_1s: mean(&t1[last.clone()]),
            t2_mean_last_1s: mean(&t2[last]),
            further_cables: FurtherCables(further_cables),
            err_max_transition: max_abs(&err[transition]),
            err_max_settled: max_abs(&err[settled.clone()]),
            err_max_settled_strict: max_abs(&err[strict]),
            overshoot: overshoot(x, step5),
            z_mean: mean(zs),
            z_p2p: peak_to_peak(zs),
            spectral,
            z0: z.first().copied().unwrap_or(f64::NAN),
            f0: run.equilibrium.force(),
            energy_residual_max: max_abs(c.e_residual),
            pulley_events: run.events.len(),
            pulley_energy_loss: -run.events.iter().map(|e| e.energy_change).sum::<f64>(),
            pulley_chatter: chatter(&run.events),
            rhs_evals: run.stats.rhs_evals,
            steps_accepted: run.stats.steps_accepted,
            steps_rejected: run.stats.steps_rejected,
            newton_iterations: run.stats.newton_iterations,
            jacobian_evals: run.stats.jacobian_evals,
            factorisations: run.stats.factorisations,
            pivotings: run.stats.pivotings,
            wall_s: run.wall_s,
            control: ControlMetrics::from_columns(&c, context),
        };
        metrics.mark_unavailable(long_enough);
        metrics
    }

    /// Sets to NaN, with the reason, every metric whose window the run does not reach or fill,
    /// and says why each peak that is null has none.
    fn mark_unavailable(&mut self, spectra: bool) {
        let (t_end, move_end) = (self.windows.record[1], self.windows.transition[1]);
        let mut unavailable = self.window_reasons();
        unavailable.extend(self.spectral_reasons(spectra));
        self.control
            .mark_unavailable(move_end, t_end, &mut unavailable);
        for (key, why) in unavailable {
            if !self.set_nan(key) {
                continue;
            }
            self.unavailable.entry(key.to_owned()).or_insert(why);
        }
        if self.spectral.z_fft_record_rad_s.is_nan() {
            self.spectral.z_fft_record_bin = 0;
        }
        if self.spectral.err_hf_peak_rad_s.is_nan() {
            self.spectral.err_hf_peaks.clear();
        }
    }

    /// The metrics whose time windows the record does not reach or fill, and why (the further
    /// cables' last-second means are set NaN here).
    fn window_reasons(&mut self) -> Vec<(&'static str, String)> {
        let w = self.windows;
        let t_end = w.record[1];
        let move_end = w.transition[1];
        let mut unavailable: Vec<(&'static str, String)> = Vec::new();
        if t_end < move_end {
            let why = format!("the run ends at {t_end} s, before the move ends at {move_end} s");
            for key in [
                "err_max_transition",
                "overshoot",
                "x_settle_s",
                "z_settle_s",
            ] {
                unavailable.push((key, why.clone()));
            }
        }
        let settled = format!(
            "the run ends at {t_end} s, before the settled window starts at the move's end + {SETTLE_AFTER_MOVE} s = {} s",
            w.settled_start()
        );
        if w.settled.is_none() {
            for key in ["err_max_settled", "z_mean", "z_p2p"] {
                unavailable.push((key, settled.clone()));
            }
        }
        if w.settled_strict.is_none() {
            let why = format!(
                "the run ends at {t_end} s, before the strict settled window starts at the move's end + {STRICT_SETTLE_AFTER_MOVE} s = {} s",
                move_end + STRICT_SETTLE_AFTER_MOVE
            );
            unavailable.push(("err_max_settled_strict", why));
        }
        if t_end - LAST_WINDOW < w.settled_start() {
            let why = format!(
                "the last {LAST_WINDOW} s of the record, from {} s, begins before the settled window at {} s: t_final must be ≥ the move's end + {} s",
                t_end - LAST_WINDOW,
                w.settled_start(),
                SETTLE_AFTER_MOVE + LAST_WINDOW
            );
            for key in ["t1_mean_last_1s", "t2_mean_last_1s"] {
                unavailable.push((key, why.clone()));
            }
            for (i, cable) in self.further_cables.0.iter_mut().enumerate() {
                cable.mean_last_1s = f64::NAN;
                let key = format!("t{}_mean_last_1s", i + 3);
                self.unavailable.entry(key).or_insert_with(|| why.clone());
            }
        }
        unavailable
    }

    /// The spectral metrics the record cannot give, and why (`spectra`: the settled window is
    /// long enough to be read).
    fn spectral_reasons(&self, spectra: bool) -> Vec<(&'static str, String)> {
        let w = self.windows;
        let t_end = w.record[1];
        let mut unavailable: Vec<(&'static str, String)> = Vec::new();
        let spectral = [
            ("z_peak_rad_s", "z", "refined"),
            ("err_peak_rad_s", "the error", "refined"),
            ("z_plain_peak_rad_s", "z", "plain"),
            ("err_plain_peak_rad_s", "the error", "plain"),
        ];
        if !spectra {
            let why = format!(
                "the settled window [{}, {t_end}] s is shorter than the {MIN_SPECTRAL_WINDOW} s a spectral peak needs",
                w.settled_start()
            );
            for (key, _, _) in spectral {
                unavailable.push((key, why.clone()));
            }
            unavailable.push(("err_hf_peak_rad_s", why.clone()));
            unavailable.push(("err_hf_peak_db", why));
        } else {
            for (key, signal, kind) in spectral {
                if let Some((_, why)) = self.spectral.no_peak.iter().find(|(k, _)| *k == key) {
                    let why = format!(
                        "{signal} has no {kind} spectral peak over the settled window: {why}"
                    );
                    unavailable.push((key, why));
                }
            }
            if self.spectral.err_hf_peak_rad_s.is_nan() {
                let why = format!(
                    "the error's refined spectrum has no local maximum above {HF_FROM} rad/s"
                );
                unavailable.push(("err_hf_peak_rad_s", why.clone()));
                unavailable.push(("err_hf_peak_db", why));
            } else if self.spectral.err_peak_rad_s.is_nan() {
                let why =
                    "its level is relative to the error's refined peak, which has none".to_string();
                unavailable.push(("err_hf_peak_db", why));
            }
        }
        if t_end < MIN_SPECTRAL_WINDOW {
            let why = format!(
                "the record of {t_end} s is shorter than the {MIN_SPECTRAL_WINDOW} s a spectral peak needs"
            );
            unavailable.push(("z_fft_record_rad_s", why));
        } else if let Some((_, why)) = self
            .spectral
            .no_peak
            .iter()
            .find(|(k, _)| *k == "z_fft_record_rad_s")
        {
            let why = format!("z has no plain spectral peak over the record: {why}");
            unavailable.push(("z_fft_record_rad_s", why));
        }
        unavailable
    }

    /// Sets the metric `key` to NaN; false for a key that is none of these.
    fn set_nan(&mut self, key: &str) -> bool {
        let slot = match key {
            "err_max_transition" => &mut self.err_max_transition,
            "err_max_settled" => &mut self.err_max_settled,
            "err_max_settled_strict" => &mut self.err_max_settled_strict,
            "overshoot" => &mut self.overshoot,
            "z_mean" => &mut self.z_mean,
            "z_p2p" => &mut self.z_p2p,
            "t1_mean_last_1s" => &mut self.t1_mean_last_1s,
            "t2_mean_last_1s" => &mut self.t2_mean_last_1s,
            "z_peak_rad_s" => &mut self.spectral.z_peak_rad_s,
            "err_peak_rad_s" => &mut self.spectral.err_peak_rad_s,
            "z_plain_peak_rad_s" => &mut self.spectral.z_plain_peak_rad_s,
            "err_plain_peak_rad_s" => &mut self.spectral.err_plain_peak_rad_s,
            "z_fft_record_rad_s" => &mut self.spectral.z_fft_record_rad_s,
            "err_hf_peak_rad_s" => &mut self.spectral.err_hf_peak_rad_s,
            "err_hf_peak_db" => &mut self.spectral.err_hf_peak_db,
            other => return self.control.set_nan(other),
        };
        *slot = f64::NAN;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cable k's six metrics of a known series: extremes and their times, the last sample, the
    /// mean over the `last` range.
    #[test]
    fn a_further_cable_is_measured_like_the_first_two() {
        let t = [0.0, 0.1, 0.2, 0.3, 0.4];
        let v = [5.0, 2.0, 9.0, 4.0, 6.0];
        let c = CableTensions::of(&t, &v, 3..5);
        assert_eq!((c.min, c.min_time, c.max, c.max_time), (2.0, 0.1, 9.0, 0.2));
        assert_eq!((c.final_value, c.mean_last_1s), (6.0, 5.0));
    }

    /// Cables 3 and 4 become the keys t3_* then t4_*, NaN as null; none for the plane.
    #[test]
    fn further_cables_are_numbered_keys() {
        let c = CableTensions {
            min: 1.0,
            min_time: 2.0,
            max: 3.0,
            max_time: 4.0,
            final_value: 5.0,
            mean_last_1s: f64::NAN,
        };
        let json = serde_json::to_value(FurtherCables(vec![c, c])).unwrap();
        let keys: Vec<&String> = json.as_object().unwrap().keys().collect();
        assert_eq!(keys.len(), 12);
        assert_eq!(json["t3_min"], 1.0);
        assert_eq!(json["t4_final"], 5.0);
        assert!(json["t4_mean_last_1s"].is_null());
        let plane = serde_json::to_value(FurtherCables::default()).unwrap();
        assert!(plane.as_object().unwrap().is_empty());
    }
}
