//! Cost of the lumped model (N = 40 per cable, 328 states): one closed-loop RHS evaluation and
//! the 5 s paper run with DOPRI5 (about 2.1 M accepted steps and 13 M RHS evaluations).

use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::runner::{RunOptions, simulate};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::lumped::{Lumped, Params};
use cdpr_bench::numerics::OdeSystem;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

fn rhs(c: &mut Criterion) {
    let scenario = Scenario::paper();
    let mut sys = ClosedLoop::new(
        Lumped::new(&scenario, Params::default()).unwrap(),
        &scenario,
    )
    .unwrap();
    let (y, _) = sys.initial_state().unwrap();
    let mut dy = vec![0.0; y.len()];
    c.bench_function("lumped/rhs", |b| {
        b.iter(|| {
            sys.rhs(black_box(0.1), black_box(&y), &mut dy);
            black_box(&dy);
        })
    });
}

fn paper_run(c: &mut Criterion) {
    let scenario = Scenario::paper();
    let opts = RunOptions::from(&scenario);
    let mut group = c.benchmark_group("lumped");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(120));
    group.bench_function("paper_run_5s", |b| {
        b.iter(|| {
            let mut sys = ClosedLoop::new(
                Lumped::new(&scenario, Params::default()).unwrap(),
                &scenario,
            )
            .unwrap();
            let run = simulate(&mut sys, &opts, &mut |_| {}).unwrap();
            black_box(run.stats.rhs_evals)
        })
    });
    group.finish();
}

criterion_group!(benches, rhs, paper_run);
criterion_main!(benches);
