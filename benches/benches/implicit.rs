//! Cost of the implicit path (generalised-α, ρ∞ = 0.9, h = 1e-4 s, faer sparse LU; MODELS.md
//! FE.9.3) on both massive-cable models:
//!
//! - `implicit/{lumped,fe}_paper_run_5s`: the paper's 5 s run as the scenario defines it (samples
//!   every 1e-5 s into a reused buffer), and `…_5s_coarse_samples` with samples every 1e-4 s (one
//!   per step), which isolates the integrator from the 500 001-row output;
//! - `implicit_adaptive/{lumped,lumped_effector_norm,fe}_paper_run_5s`: the same runs under
//!   error control at the tolerances that reach the fixed step's accuracy, and
//!   `…/lumped_n1000_effector_norm_rho_inf_0.5_paper_run_5s` at N = 1000;
//! - `implicit_cost_vs_n/{lumped,fe}/N`, N = 10 … 1000: 0.02 s of the paper's run from its
//!   static equilibrium (200 steps, one sample per step; the equilibrium is solved once, outside
//!   the timing). Criterion's time × 50 is the cost per simulated second.
//!
//! Knobs for looking into one case (environment): `CDPR_BENCH_ONLY=lumped|fe`, `CDPR_BENCH_N=300`,
//! `CDPR_BENCH_T=0.002` (simulated time of the cost-vs-N runs [s]) and `CDPR_BENCH_STATS=1`
//! (print each case's solver counters before timing it).

use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::model::CableModel;
use cdpr_bench::core::runner::{RunOptions, simulate_from, simulate_reusing};
use cdpr_bench::core::scenario::{ErrorNorm, IntegratorKind, Scenario};
use cdpr_bench::core::series::{SeriesBuffer, TimeSeries};
use cdpr_bench::{ModelConfig, ModelKind, ModelVisitor, build, with_model};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

fn scenario(kind: ModelKind, elements: Option<i64>) -> Scenario {
    let mut s = Scenario::paper();
    s.model = ModelConfig {
        elements,
        ..ModelConfig::of_kind(kind)
    }
    .into();
    s.simulation.integrator = IntegratorKind::Implicit;
    s
}

/// One 5 s run of `s` per iteration, its samples in a reused buffer (the solver's counters
/// printed first with `CDPR_BENCH_STATS`).
fn bench_paper_run(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    s: &Scenario,
) {
    let opts = RunOptions::from(s);
    let mut buffer = SeriesBuffer::default();
    let run_once = |buffer: SeriesBuffer| {
        let mut sys = ClosedLoop::new(build(s).unwrap(), s).unwrap();
        simulate_reusing(&mut sys, &opts, buffer, &mut |_| {}).unwrap()
    };
    if std::env::var_os("CDPR_BENCH_STATS").is_some() {
        eprintln!("{name}: {:?}", run_once(SeriesBuffer::default()).stats);
    }
    group.bench_function(name, |b| {
        b.iter(|| {
            let run = run_once(std::mem::take(&mut buffer));
            let steps = run.stats.steps_accepted;
            buffer = run.series.into_buffer();
            black_box(steps)
        })
    });
}

fn paper_runs(c: &mut Criterion) {
    let mut group = c.benchmark_group("implicit");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    for kind in ModelKind::MASSIVE {
        for (label, sample_period) in [("", 1e-5), ("_coarse_samples", 1e-4)] {
            let mut s = scenario(kind, None);
            s.simulation.sample_period = sample_period;
            bench_paper_run(&mut group, &format!("{kind}_paper_run_5s{label}"), &s);
        }
    }
    group.finish();
}

/// The paper's 5 s runs under error control (`adaptive = true`, samples every 1e-4 s as in
/// `…_coarse_samples`), at the loosest tolerances measured to reach the accuracy of the fixed
/// h = 1e-4 s run (T1 min within 1e-3 N, z p2p within 1e-3 relative, the settled error within
/// 1e-7 m, docs/numerics.md): FE at the defaults (rtol 1e-5, atol 1e-9), lumped at atol 1e-6
/// (its nodes by the pulleys make atol 1e-9 cost 2 M steps), and lumped with the error measured
/// on the effector (`error_norm = "effector"`: the nodes' ringing no longer sets the step);
/// and lumped N = 1000 on the effector's norm with ρ∞ = 0.5, whose stronger damping of the
/// unresolved line modes lets Newton take longer steps by the pulleys (at ρ∞ = 0.9 it costs
/// 8.1 s, docs/numerics.md).
fn adaptive_runs(c: &mut Criterion) {
    let mut group = c.benchmark_group("implicit_adaptive");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    let lumped = |elements, norm, rho_inf| (ModelKind::Lumped, elements, 1e-6, norm, rho_inf);
    for (name, (kind, elements, atol, norm, rho_inf)) in [
        ("lumped", lumped(None, ErrorNorm::All, 0.9)),
        (
            "lumped_effector_norm",
            lumped(None, ErrorNorm::Effector, 0.9),
        ),
        (
            "lumped_n1000_effector_norm_rho_inf_0.5",
            lumped(Some(1000), ErrorNorm::Effector, 0.5),
        ),
        ("fe", (ModelKind::Fe, None, 1e-9, ErrorNorm::All, 0.9)),
    ] {
        let mut s = scenario(kind, elements);
        s.simulation.sample_period = 1e-4;
        s.simulation.adaptive = true;
        s.simulation.atol = atol;
        s.simulation.error_norm = norm;
        s.simulation.rho_inf = rho_inf;
        bench_paper_run(&mut group, &format!("{name}_paper_run_5s"), &s);
    }
    group.finish();
}

/// 0.02 s of the paper's run from the static equilibrium at x_ref(0) (solved once, outside the
/// timing), with a fresh copy of the model per iteration (the lumped model's stored counts change
/// at pulley events).
fn bench_from<M: CableModel<2> + Clone>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    s: &Scenario,
    kind: ModelKind,
    n: i64,
    model: M,
) {
    let opts = RunOptions::from(s);
    let mut sys = ClosedLoop::new(model, s).unwrap();
    let (y0, eq) = sys.initial_state().unwrap();
    let start = sys.model.clone();
    if std::env::var_os("CDPR_BENCH_STATS").is_some() {
        let run = simulate_from(&mut sys, y0.clone(), eq.clone(), &opts, &mut |_| {}).unwrap();
        eprintln!(
            "{kind} N = {n}: {:?}, {} events, {:.4} s",
            run.stats,
            run.events.len(),
            run.wall_s
        );
    }
    group.bench_with_input(BenchmarkId::new(kind.name(), n), &n, |b, _| {
        b.iter(|| {
            sys.model = start.clone();
            let run = simulate_from(&mut sys, y0.clone(), eq.clone(), &opts, &mut |_| {}).unwrap();
            black_box(TimeSeries::len(&run.series))
        })
    });
}

/// [`bench_from`] on the scenario's model, whichever it is.
struct BenchFrom<'a, 'g> {
    group: &'a mut criterion::BenchmarkGroup<'g, criterion::measurement::WallTime>,
    s: &'a Scenario,
    kind: ModelKind,
    n: i64,
}

impl ModelVisitor for BenchFrom<'_, '_> {
    type Output = ();
    fn visit<M: CableModel<2> + Clone + Send + 'static>(self, model: M) {
        bench_from(self.group, self.s, self.kind, self.n, model)
    }
}

fn cost_vs_n(c: &mut Criterion) {
    let mut group = c.benchmark_group("implicit_cost_vs_n");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    for kind in ModelKind::MASSIVE {
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
            let bench = BenchFrom {
                group: &mut group,
                s: &s,
                kind,
                n,
            };
            with_model(&s, bench).unwrap();
        }
    }
    group.finish();
}

criterion_group!(benches, paper_runs, adaptive_runs, cost_vs_n);
criterion_main!(benches);
