//! Cost of the FE model (N = 10 per cable, 86 closed-loop states): one closed-loop RHS
//! evaluation, the assembly of M and F alone and with the O(N) block solve of MODELS.md FE.5.5, and
//! the 5 s paper run with DOPRI5 (about 1.6 M accepted steps and 11.7 M RHS evaluations).

use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::runner::{RunOptions, simulate};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::fe::{Fe, Params};
use cdpr_bench::numerics::OdeSystem;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

fn rhs(c: &mut Criterion) {
    let scenario = Scenario::paper();
    let mut sys =
        ClosedLoop::new(Fe::new(&scenario, Params::default()).unwrap(), &scenario).unwrap();
    let (mut y, _) = sys.initial_state().unwrap();
    // Moving cable: every velocity term of the assembly is exercised.
    let np = sys.model.positions_len();
    for (i, v) in y[np..2 * np].iter_mut().enumerate() {
        *v = 0.01 * (i as f64).sin();
    }
    let mut dy = vec![0.0; y.len()];
    c.bench_function("fe/rhs", |b| {
        b.iter(|| {
            sys.rhs(black_box(0.1), black_box(&y), &mut dy);
            black_box(&dy);
        })
    });
    let mut model = Fe::new(&scenario, Params::default()).unwrap();
    let mut qdd = vec![0.0; np];
    c.bench_function("fe/assemble", |b| {
        b.iter(|| {
            model.assemble_only(black_box(&y[..2 * np]), black_box([100.0, 100.0]));
        })
    });
    // Assembly plus the O(N) solve (the solve consumes its right-hand sides, so it is timed
    // together with the assembly that refills them; its cost is the difference to fe/assemble).
    c.bench_function("fe/assemble_and_solve", |b| {
        b.iter(|| {
            black_box(model.accelerations(black_box(&y[..2 * np]), [100.0, 100.0], &mut qdd));
            black_box(&qdd);
        })
    });
}

fn paper_run(c: &mut Criterion) {
    let scenario = Scenario::paper();
    let opts = RunOptions::from(&scenario);
    let mut group = c.benchmark_group("fe");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(240));
    group.bench_function("paper_run_5s", |b| {
        b.iter(|| {
            let mut sys =
                ClosedLoop::new(Fe::new(&scenario, Params::default()).unwrap(), &scenario).unwrap();
            let run = simulate(&mut sys, &opts, &mut |_| {}).unwrap();
            black_box(run.stats.rhs_evals)
        })
    });
    group.finish();
}

criterion_group!(benches, rhs, paper_run);
criterion_main!(benches);
