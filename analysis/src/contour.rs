//! What a print's quality is: the **contour error**, the nozzle's distance to the commanded
//! path (the polyline of the firmware's segments), not to where the reference is at that
//! instant — a nozzle late on its line draws the right part; one beside it does not.
//!
//! Each sample is measured against the segments commanded within [`WINDOW`] of its plan time:
//! far more than any tracking lag or shaper (≤ 0.1 s), short enough that a neighbouring line of
//! the same layer, commanded seconds before, does not count as the path (infill lines lie
//! 0.45 mm apart: against the whole layer no error could exceed ~0.2 mm). A sample is
//! attributed to the move its plan time falls in (at rest: travel), and counted when that move's
//! layer is among the printed ones.

use cdpr_core::print_path::PrintPath;
use cdpr_core::robot::Vector;
use cdpr_printing::gcode::MoveKind;
use std::collections::BTreeMap;

/// Half-width of the plan-time window of segments a sample is measured against [s].
pub const WINDOW: f64 = 0.25;

/// Largest, root-mean-square and 99th-percentile error over a set of samples [m].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ErrorStats {
    pub max: f64,
    pub rms: f64,
    pub p99: f64,
    pub samples: usize,
}

impl ErrorStats {
    /// Of `errors` (NaN for none).
    pub fn of(errors: &mut [f64]) -> Self {
        if errors.is_empty() {
            return ErrorStats {
                max: f64::NAN,
                rms: f64::NAN,
                p99: f64::NAN,
                samples: 0,
            };
        }
        let n = errors.len();
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
        errors.sort_unstable_by(f64::total_cmp);
        // Nearest rank: the smallest error at or above 99 % of the samples.
        let rank = ((0.99 * n as f64).ceil() as usize).clamp(1, n) - 1;
        ErrorStats {
            max: errors[n - 1],
            rms,
            p99: errors[rank],
            samples: n,
        }
    }
}

/// The point of the segment [a, b] nearest to `p`.
pub fn nearest_on_segment<const D: usize>(
    p: &Vector<D>,
    a: &Vector<D>,
    b: &Vector<D>,
) -> Vector<D> {
    let ab = b - a;
    let length2 = ab.norm_squared();
    let s = if length2 > 0.0 {
        ((p - a).dot(&ab) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + ab * s
}

/// One sample's contour error [m], the path's point nearest the nozzle and the move it belongs
/// to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContourSample<const D: usize> {
    pub error: f64,
    pub nearest: Vector<D>,
    pub kind: MoveKind,
    pub layer: usize,
}

/// The contour error of the nozzle at `p` at the loop's time `t` [s].
pub fn contour_sample<const D: usize>(
    path: &PrintPath<D>,
    t: f64,
    p: &Vector<D>,
) -> ContourSample<D> {
    let plan = path.plan();
    let s = t - path.lead();
    let segments = &plan.segments;
    // Segments end in time order; a sample after the last one's window meets the last one.
    let first = segments
        .partition_point(|g| g.t_start + g.duration() < s - WINDOW)
        .min(segments.len() - 1);
    let last = segments.partition_point(|g| g.t_start <= s + WINDOW);
    let (mut error, mut nearest) = (f64::INFINITY, *p);
    for i in first..last.max(first + 1).min(segments.len()) {
        let (a, b) = path.segment_ends(i);
        let q = nearest_on_segment(p, &a, &b);
        let d = (p - q).norm();
        if d < error {
            (error, nearest) = (d, q);
        }
    }
    let (kind, layer) = match plan.segment_at(s) {
        Some(i) if s - segments[i].t_start < segments[i].duration() => {
            (segments[i].kind, segments[i].layer)
        }
        Some(i) => (MoveKind::Travel, segments[i].layer),
        None => (MoveKind::Travel, segments[0].layer),
    };
    ContourSample {
        error,
        nearest,
        kind,
        layer,
    }
}

/// The contour-error statistics of a print, overall and per move kind (the printed layers'
/// samples only), and of the tracking error |p_ref(t) − p(t)|.
#[derive(Debug, Clone, PartialEq)]
pub struct ContourMetrics {
    pub overall: ErrorStats,
    /// Over the moves that extrude (every kind but travel): the printed part's error.
    pub printing: ErrorStats,
    pub by_kind: BTreeMap<MoveKind, ErrorStats>,
    pub tracking: ErrorStats,
}

impl ContourMetrics {
    /// Of the samples `(t, p)` of a run along `path`, counting the layers `layers`.
    pub fn of<const D: usize>(
        path: &PrintPath<D>,
        samples: impl Iterator<Item = (f64, Vector<D>)>,
        layers: std::ops::RangeInclusive<usize>,
    ) -> Self {
        let mut all = Vec::new();
        let mut printing = Vec::new();
        let mut tracking = Vec::new();
        let mut by_kind: BTreeMap<MoveKind, Vec<f64>> = BTreeMap::new();
        for (t, p) in samples {
            let c = contour_sample(path, t, &p);
            if !layers.contains(&c.layer) {
                continue;
            }
            all.push(c.error);
            if c.kind != MoveKind::Travel {
                printing.push(c.error);
            }
            by_kind.entry(c.kind).or_default().push(c.error);
            tracking.push((path.reference(t, false)[0] - p).norm());
        }
        ContourMetrics {
            overall: ErrorStats::of(&mut all),
            printing: ErrorStats::of(&mut printing),
            by_kind: by_kind
                .into_iter()
                .map(|(k, mut v)| (k, ErrorStats::of(&mut v)))
                .collect(),
            tracking: ErrorStats::of(&mut tracking),
        }
    }
}
