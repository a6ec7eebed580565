//! Cost of the elastic model: one closed-loop RHS evaluation, and the 5 s paper run with its
//! 500 001 output samples (and without them, to show what integration alone costs).

use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::runner::{RunOptions, simulate, simulate_reusing};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::core::series::SeriesBuffer;
use cdpr_bench::elastic::Elastic;
use cdpr_bench::numerics::OdeSystem;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn rhs(c: &mut Criterion) {
    let scenario = Scenario::paper();
    let mut sys = ClosedLoop::new(Elastic::from_scenario(&scenario), &scenario).unwrap();
    let (y, _) = sys.initial_state().unwrap();
    let mut dy = vec![0.0; y.len()];
    c.bench_function("elastic/rhs", |b| {
        b.iter(|| {
            sys.rhs(black_box(0.1), black_box(&y), &mut dy);
            black_box(&dy);
        })
    });
}

/// The 5 s paper run three ways: with its 500 001 × 18-channel output (72 MB) in fresh memory
/// (what one `cargo xtask simulate` pays, page faults included), reusing the previous run's
/// output memory (what each run of a sweep pays), and with output only at the ends (the
/// integration alone).
fn paper_run(c: &mut Criterion) {
    let mut group = c.benchmark_group("elastic/paper_run_5s");
    group.sample_size(20);
    let scenario = Scenario::paper();
    let opts = RunOptions::from(&scenario);
    group.bench_function("sampled_1e-5_fresh_memory", |b| {
        b.iter(|| {
            let mut sys = ClosedLoop::new(Elastic::from_scenario(&scenario), &scenario).unwrap();
            let run = simulate(&mut sys, &opts, &mut |_| {}).unwrap();
            black_box(run.series.len())
        })
    });
    let mut buffer = SeriesBuffer::default();
    group.bench_function("sampled_1e-5_reused_memory", |b| {
        b.iter(|| {
            let mut sys = ClosedLoop::new(Elastic::from_scenario(&scenario), &scenario).unwrap();
            let run = simulate_reusing(&mut sys, &opts, std::mem::take(&mut buffer), &mut |_| {})
                .unwrap();
            let n = run.series.len();
            buffer = run.series.into_buffer();
            black_box(n)
        })
    });
    let mut ends_only = scenario.clone();
    ends_only.simulation.sample_period = ends_only.simulation.t_final;
    let opts = RunOptions::from(&ends_only);
    group.bench_function("integration_only", |b| {
        b.iter(|| {
            let mut sys = ClosedLoop::new(Elastic::from_scenario(&ends_only), &ends_only).unwrap();
            let run = simulate(&mut sys, &opts, &mut |_| {}).unwrap();
            black_box(run.series.len())
        })
    });
    group.finish();
}

criterion_group!(benches, rhs, paper_run);
criterion_main!(benches);
