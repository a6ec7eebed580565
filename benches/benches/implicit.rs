//! Cost of the implicit path (generalised-α, ρ∞ = 0.9, h = 1e-4 s, faer sparse LU; MODELS.md
//! FE.9.3) on both massive-cable models:
//!
//! - `implicit/{lumped,fe}_paper_run_5s`: the paper's 5 s run as the scenario defines it (samples
//!   every 1e-5 s into a reused buffer), and `…_5s_coarse_samples` with samples every 1e-4 s (one
//!   per step), which isolates the integrator from the 500 001-row output;
//! - `implicit_cost_vs_n/{lumped,fe}/N`, N = 10 … 1000: 0.02 s of the paper's run from rest
//!   (200 steps, one sample per step). Criterion's time × 50 is the cost per simulated second.
//!   The start state is the N = 10 static equilibrium prolonged to N (cable nodes placed on a
//!   parabola fitted to the coarse free cable, at their unstrained arc length): the dense static Newton of the models costs
//!   O(n³) and takes minutes at N = 1000, while the prolonged state is within the coarse model's
//!   discretisation error of equilibrium, which only adds small vibrations. Every N is started the
//!   same way, so the table measures how a step's cost grows with N.
//!
//! Knobs for looking into one case (environment): `CDPR_BENCH_ONLY=lumped|fe`, `CDPR_BENCH_N=300`,
//! `CDPR_BENCH_T=0.002` (simulated time of the cost-vs-N runs [s]) and `CDPR_BENCH_STATS=1`
//! (print each case's solver counters before timing it).

use cdpr_core::closed_loop::{ClosedLoop, RunOptions, simulate_from, simulate_reusing};
use cdpr_core::model::{CableModel, Equilibrium};
use cdpr_core::scenario::{IntegratorKind, ModelKind, Scenario};
use cdpr_core::series::TimeSeries;
use cdpr_fe::Fe;
use cdpr_lumped::{E_OUT as LUMPED_E_OUT, Lumped};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector2;
use std::hint::black_box;
use std::time::Duration;

fn scenario(kind: ModelKind, elements: Option<i64>) -> Scenario {
    let mut s = Scenario::paper();
    s.model.kind = kind;
    s.model.elements = elements;
    s.simulation.integrator = IntegratorKind::Implicit;
    s
}

fn paper_runs(c: &mut Criterion) {
    let mut group = c.benchmark_group("implicit");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    for kind in [ModelKind::Lumped, ModelKind::Fe] {
        for (label, sample_period) in [("", 1e-5), ("_coarse_samples", 1e-4)] {
            let mut s = scenario(kind, None);
            s.simulation.sample_period = sample_period;
            let opts = RunOptions::from(&s);
            let mut buffer = Vec::new();
            group.bench_function(format!("{kind}_paper_run_5s{label}"), |b| {
                b.iter(|| {
                    let model = boxed_model(&s);
                    let mut sys = ClosedLoop::new(model, &s);
                    let run =
                        simulate_reusing(&mut sys, &opts, std::mem::take(&mut buffer), &mut |_| {})
                            .unwrap();
                    let evals = run.stats.rhs_evals;
                    buffer = run.series.into_buffer();
                    black_box(evals)
                })
            });
        }
    }
    group.finish();
}

/// The scenario's massive-cable model, boxed (the benches crate does not depend on cdpr-verify).
fn boxed_model(s: &Scenario) -> Box<dyn CableModel + Send> {
    match s.model.kind {
        ModelKind::Lumped => Box::new(Lumped::new(s).unwrap()),
        _ => Box::new(Fe::new(s).unwrap()),
    }
}

/// The free span as a smooth curve: the parabola z(ξ) = z_A + ξ (z_P − z_A) + 4 a ξ (1 − ξ) over
/// the chord's horizontal fraction ξ, its sag a fitted to the coarse nodes by least squares (a
/// tensioned cable under its weight is a parabola to O(sag²)). Placing the fine nodes on a
/// smooth curve matters: on the coarse polyline each corner would put a force T·angle on a node of
/// mass μL0/N, a violent start at large N.
struct Span {
    a: Vector2<f64>,
    p: Vector2<f64>,
    sag: f64,
    /// Arc length at ξ = k/RESOLUTION.
    arc: Vec<f64>,
}

const RESOLUTION: usize = 4096;

impl Span {
    fn fit(nodes: &[Vector2<f64>]) -> Self {
        let (a, p) = (nodes[0], nodes[nodes.len() - 1]);
        let (mut num, mut den) = (0.0, 0.0);
        for q in nodes {
            let xi = (q.x - a.x) / (p.x - a.x);
            let phi = 4.0 * xi * (1.0 - xi);
            num += (q.y - a.y - xi * (p.y - a.y)) * phi;
            den += phi * phi;
        }
        let mut span = Self {
            a,
            p,
            sag: if den > 0.0 { num / den } else { 0.0 },
            arc: vec![0.0; RESOLUTION + 1],
        };
        for k in 1..=RESOLUTION {
            let (q0, q1) = (
                span.point((k - 1) as f64 / RESOLUTION as f64),
                span.point(k as f64 / RESOLUTION as f64),
            );
            span.arc[k] = span.arc[k - 1] + (q1 - q0).norm();
        }
        span
    }

    fn point(&self, xi: f64) -> Vector2<f64> {
        Vector2::new(
            self.a.x + xi * (self.p.x - self.a.x),
            self.a.y + xi * (self.p.y - self.a.y) + 4.0 * self.sag * xi * (1.0 - xi),
        )
    }

    /// The point at `fraction` of the arc length from the pulley end (uniform strain).
    fn at(&self, fraction: f64) -> Vector2<f64> {
        let target = fraction.clamp(0.0, 1.0) * self.arc[RESOLUTION];
        let k = self
            .arc
            .partition_point(|&s| s < target)
            .clamp(1, RESOLUTION);
        let f = (target - self.arc[k - 1]) / (self.arc[k] - self.arc[k - 1]);
        self.point((k as f64 - 1.0 + f) / RESOLUTION as f64)
    }
}

/// FE: nodes k/N of each span on the fitted span (nodes of a span sit at fixed fractions of its
/// unstrained length), lengths l_i and ρ_i as in the coarse state.
fn fe_start(n: i64) -> (Fe, Vec<f64>, f64) {
    let coarse_s = scenario(ModelKind::Fe, Some(10));
    let mut coarse = Fe::new(&coarse_s).unwrap();
    let eq = coarse.equilibrium(0.5, 200.0).unwrap();
    let fine = Fe::new(&scenario(ModelKind::Fe, Some(n))).unwrap();
    let mut y = vec![0.0; fine.state_len()];
    let nc = coarse.elements;
    for cable in 0..2 {
        let points: Vec<_> = (0..=nc)
            .map(|k| coarse.node(&eq.state, cable, k).0)
            .collect();
        let span = Span::fit(&points);
        for k in 1..=fine.elements {
            let p = span.at(k as f64 / fine.elements as f64);
            let j = fine.chain_index(cable, k).unwrap();
            y[fine.node_coordinate(j, 0)] = p.x;
            y[fine.node_coordinate(j, 1)] = p.y;
        }
        y[fine.l_index(cable)] = eq.state[coarse.l_index(cable)];
        if let (Some(r), Some(rc)) = (fine.rho_index(cable), coarse.rho_index(cable)) {
            y[r] = eq.state[rc];
        }
    }
    (fine, y, eq.force)
}

/// Lumped: the same free unstrained length per cable as the coarse state; free nodes at their
/// unstrained distance from the effector along the fitted free span, stored nodes on z = 0 at
/// the strained spacing l0 (1 + T/EA).
fn lumped_start(n: i64) -> (Lumped, Vec<f64>, f64) {
    let coarse_s = scenario(ModelKind::Lumped, Some(10));
    let mut coarse = Lumped::new(&coarse_s).unwrap();
    let eq = coarse.equilibrium(0.5, 200.0).unwrap();
    let s = scenario(ModelKind::Lumped, Some(n));
    let mut fine = Lumped::new(&s).unwrap();
    let strain = 100.0 / s.cable.axial_stiffness();
    let mut y = vec![0.0; fine.state_len()];
    let (nc, nf) = (coarse.elements, fine.elements);
    let effector = coarse.node(&eq.state, 0, nc);
    let mut stored = [0; 2];
    for cable in 0..2 {
        let free = coarse.free_length(&eq.state, cable);
        // The free cable from the pulley to the effector through the coarse free nodes.
        let rc = coarse.stored()[cable];
        let mut points = vec![coarse.pulley(cable)];
        points.extend((rc..nc).map(|j| coarse.node(&eq.state, cable, j)));
        points.push(effector);
        let span = Span::fit(&points);
        let l0 = fine.segment;
        let free_springs = (free / l0).floor() as usize;
        let r = nf - free_springs;
        stored[cable] = r;
        for j in r..nf {
            let p = span.at(1.0 - (nf - j) as f64 * l0 / free);
            y[fine.xi(cable, j)] = p.x;
            y[fine.zi(cable, j)] = p.y;
        }
        // The straddling spring's stored share, then full springs outward.
        let share = l0 - (free - free_springs as f64 * l0);
        for j in 0..r {
            let distance = (share + (r - 1 - j) as f64 * l0) * (1.0 + strain);
            y[fine.xi(cable, j)] = fine.pulley(cable).x + LUMPED_E_OUT[cable] * distance;
        }
    }
    y[fine.xi(0, nf)] = effector.x;
    y[fine.zi(0, nf)] = effector.y;
    fine.set_stored(stored);
    (fine, y, eq.force)
}

/// 0.02 s of the paper's run from `y` (model part) with a fresh copy of `model` per iteration.
fn bench_from<M: CableModel + Clone>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    s: &Scenario,
    model: M,
    y: Vec<f64>,
    force: f64,
) {
    let opts = RunOptions::from(s);
    let mut sys = ClosedLoop::new(model.clone(), s);
    let pid = sys.pid.state_holding(force).unwrap_or_default();
    let mut y0 = y.clone();
    y0.extend_from_slice(&[pid.integral, pid.filter, 0.0, 0.0]);
    let eq = Equilibrium {
        state: y,
        force,
        iterations: 0,
        residual: f64::NAN,
    };
    let n = s.model.elements();
    if std::env::var_os("CDPR_BENCH_STATS").is_some() {
        let run = simulate_from(&mut sys, y0.clone(), eq.clone(), &opts, &mut |_| {}).unwrap();
        eprintln!(
            "{} N = {n}: {:?}, {} events, {:.4} s",
            s.model.kind,
            run.stats,
            run.events.len(),
            run.wall_s
        );
    }
    group.bench_with_input(BenchmarkId::new(s.model.kind.name(), n), &n, |b, _| {
        b.iter(|| {
            // The lumped model's stored counts change at pulley events: start each run afresh.
            sys.model = model.clone();
            let run = simulate_from(&mut sys, y0.clone(), eq.clone(), &opts, &mut |_| {}).unwrap();
            black_box(TimeSeries::len(&run.series))
        })
    });
}

fn cost_vs_n(c: &mut Criterion) {
    let mut group = c.benchmark_group("implicit_cost_vs_n");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    for kind in [ModelKind::Lumped, ModelKind::Fe] {
        if std::env::var("CDPR_BENCH_ONLY").is_ok_and(|only| only != kind.name()) {
            continue;
        }
        for n in [10i64, 30, 100, 300, 1000] {
            if std::env::var("CDPR_BENCH_N").is_ok_and(|only| only != n.to_string()) {
                continue;
            }
            let mut s = scenario(kind, Some(n));
            s.simulation.t_final = std::env::var("CDPR_BENCH_T")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(0.02);
            s.simulation.sample_period = 1e-4;
            match kind {
                ModelKind::Lumped => {
                    let (m, y, f) = lumped_start(n);
                    bench_from(&mut group, &s, m, y, f);
                }
                _ => {
                    let (m, y, f) = fe_start(n);
                    bench_from(&mut group, &s, m, y, f);
                }
            }
        }
    }
    group.finish();
}

criterion_group!(benches, paper_runs, cost_vs_n);
criterion_main!(benches);
