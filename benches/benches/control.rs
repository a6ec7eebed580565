//! Cost of each controller (the vibration-control leaderboard's scenario: limits [10, 400] N,
//! samples every 1e-4 s):
//!
//! - `control_rhs/<controller>`: one closed-loop RHS evaluation on the elastic model, where the
//!   controller's share of the cost is largest (the model itself is 4 states);
//! - `control_implicit/<controller>_<model>_5s`: the 5 s implicit run on the lumped and FE
//!   models, against the paper PID's (the goal: ≤ 1.5× its cost).

use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::runner::{RunOptions, simulate_reusing};
use cdpr_bench::core::scenario::{ControllerKind, IntegratorKind, Scenario};
use cdpr_bench::core::series::SeriesBuffer;
use cdpr_bench::elastic::Elastic;
use cdpr_bench::numerics::OdeSystem;
use cdpr_bench::{ModelKind, build, with_model_kind};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

fn benchmark(kind: ControllerKind, model: ModelKind) -> Scenario {
    let mut s = with_model_kind(&Scenario::paper(), model).unwrap();
    s.controller.kind = kind;
    s.controller.t_min = Some(10.0);
    s.controller.t_max = Some(400.0);
    s.simulation.sample_period = 1e-4;
    s.simulation.integrator = IntegratorKind::Implicit;
    s
}

fn rhs(c: &mut Criterion) {
    let mut group = c.benchmark_group("control_rhs");
    for kind in ControllerKind::ALL {
        let s = benchmark(kind, ModelKind::Elastic);
        let mut sys = ClosedLoop::new(Elastic::from_scenario(&s), &s).unwrap();
        let (y, _) = sys.initial_state().unwrap();
        let mut dy = vec![0.0; y.len()];
        group.bench_function(kind.name(), |b| {
            b.iter(|| {
                sys.rhs(black_box(0.1), black_box(&y), &mut dy);
                black_box(&dy);
            })
        });
    }
    group.finish();
}

fn implicit_runs(c: &mut Criterion) {
    let mut group = c.benchmark_group("control_implicit");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    for model in ModelKind::MASSIVE {
        for kind in ControllerKind::ALL {
            let s = benchmark(kind, model);
            let opts = RunOptions::from(&s);
            let mut buffer = SeriesBuffer::default();
            group.bench_function(format!("{}_{}_5s", kind.name(), model.name()), |b| {
                b.iter(|| {
                    let mut sys = ClosedLoop::new(build(&s).unwrap(), &s).unwrap();
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

criterion_group!(benches, rhs, implicit_runs);
criterion_main!(benches);
