//! Samples of a run thinned for drawing: min/max envelopes per bucket, so an oscillation keeps
//! its amplitude; spectra with the maximum per logarithmic frequency bucket, so a peak keeps its
//! height; the `step5` reference sampled. What a figure shows is data a user can read here.

use cdpr_bench::analysis::metrics::PAD;
use cdpr_bench::analysis::spectrum::{DenseSpectrum, Window};
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::runner::Run;
use cdpr_bench::core::trajectory::Step5;

/// Points kept per line (two per pixel column of a 960 px figure).
pub const MAX_POINTS: usize = 1920;

/// Keeps at most [`MAX_POINTS`] points: per bucket of equal x width, the minimum and maximum in
/// their time order, so an oscillation keeps its envelope.
pub fn envelope(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    if points.len() <= MAX_POINTS {
        return points.to_vec();
    }
    let buckets = MAX_POINTS / 2;
    let per = points.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(2 * buckets);
    for chunk in points.chunks(per) {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = i;
            }
            if p.1 > chunk[hi].1 {
                hi = i;
            }
        }
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push(chunk[a]);
        if b != a {
            out.push(chunk[b]);
        }
    }
    out
}

/// `channel` of `run` against time, over [t0, t1] s, scaled by `scale`, thinned.
pub fn channel(run: &Run, channel: Channel, t0: f64, t1: f64, scale: f64) -> Vec<(f64, f64)> {
    let s = &run.series;
    let (Some(it), Some(iv)) = (s.index(Channel::Time), s.index(channel)) else {
        return Vec::new();
    };
    let points: Vec<(f64, f64)> = (0..s.len())
        .map(|i| s.row(i))
        .filter(|r| r[it] >= t0 && r[it] <= t1)
        .map(|r| (r[it], r[iv] * scale))
        .collect();
    envelope(&points)
}

/// The refined amplitude spectrum (Hann, 16× padding) of `channel` over [`from`, t_final) (the
/// metrics' settled window), as (ω, amplitude) with the maximum kept per logarithmic bucket
/// between `w0` and `w1` rad/s.
pub fn spectrum(
    run: &Run,
    channel: Channel,
    from: f64,
    dt: f64,
    (w0, w1): (f64, f64),
) -> Vec<(f64, f64)> {
    let (Some(t), Some(v)) = (run.series.column(Channel::Time), run.series.column(channel)) else {
        return Vec::new();
    };
    let t_end = t.last().copied().unwrap_or(0.0);
    let start = t.partition_point(|&x| x < from - 0.5 * dt);
    let end = t.partition_point(|&x| x < t_end - 0.5 * dt);
    if end <= start + 2 {
        return Vec::new();
    }
    let spec = DenseSpectrum::new(&v[start..end], dt, Window::Hann, PAD);
    let buckets = MAX_POINTS;
    let (l0, l1) = (w0.ln(), w1.ln());
    let mut best = vec![(0.0f64, 0.0f64); buckets];
    for (k, &a) in spec.amplitude.iter().enumerate().skip(1) {
        let w = spec.omega(k);
        if w < w0 || w > w1 {
            continue;
        }
        let b = (((w.ln() - l0) / (l1 - l0)) * buckets as f64) as usize;
        let slot = &mut best[b.min(buckets - 1)];
        if a > slot.1 {
            *slot = (w, a);
        }
    }
    best.into_iter().filter(|p| p.1 > 0.0).collect()
}

/// The `step5` reference over [t1 − 0.05, t2 + 0.05] s as position, velocity and acceleration.
pub fn step5_lines(step5: &Step5) -> [Vec<(f64, f64)>; 3] {
    let span = step5.t2 - step5.t1;
    let (a, b) = (step5.t1 - 0.25 * span, step5.t2 + 0.25 * span);
    let ts: Vec<f64> = (0..=MAX_POINTS)
        .map(|k| a + (b - a) * k as f64 / MAX_POINTS as f64)
        .collect();
    [
        ts.iter().map(|&t| (t, step5.position(t))).collect(),
        ts.iter().map(|&t| (t, step5.velocity(t))).collect(),
        ts.iter().map(|&t| (t, step5.acceleration(t))).collect(),
    ]
}
