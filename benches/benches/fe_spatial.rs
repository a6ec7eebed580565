//! Cost of the variable-length FE cables in space (MODELS.md §5 along each cable, §11): one
//! right-hand side of the Hangprinter example at rest on FE cables of N = 10 … 1000 elements
//! (the star solve is O(N m): the cost per element should stay flat), the example's 1.2 s move
//! on DOPRI5 and 5 s on the implicit path at N = 10, and the implicit path's cost against N
//! (10 … 1000, 0.5 s) to show it O(N m) (integration only; steps and RHS printed once).

use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::model::CableModel;
use cdpr_bench::core::runner::{RunOptions, simulate};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::fe::Params;
use cdpr_bench::fe::spatial::FeSpatial;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn hangprinter(elements: usize) -> Scenario {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/hangprinter-lumped.toml");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("kind = \"lumped\"", "kind = \"fe\"")
        .replace("elements = 20", &format!("elements = {elements}"));
    let mut s = Scenario::from_toml_str(&text).unwrap();
    s.simulation.sample_period = s.simulation.t_final;
    s
}

fn model(s: &Scenario, elements: usize) -> FeSpatial {
    let params = Params {
        elements,
        ..Params::default()
    };
    FeSpatial::from_scenario(s, params).unwrap()
}

fn rhs(c: &mut Criterion) {
    let mut group = c.benchmark_group("fe_spatial/rhs");
    for n in [10, 20, 40, 60, 1000] {
        let s = hangprinter(n);
        let mut sys = ClosedLoop::new(model(&s, n), &s).unwrap();
        let (y, _) = sys.initial_state().unwrap();
        let len = sys.model.state_len();
        let tensions = [15.0, 15.0, 12.0, 14.0];
        let mut rate = vec![0.0; len];
        group.bench_function(format!("n{n}"), |b| {
            b.iter(|| {
                sys.model
                    .rhs(0.0, black_box(&y[..len]), &tensions, &mut rate);
                black_box(rate[0])
            })
        });
    }
    group.finish();
}

fn run(c: &mut Criterion) {
    let mut group = c.benchmark_group("fe_spatial/move");
    group.sample_size(10);
    let s = hangprinter(10);
    let go = || {
        let mut sys = ClosedLoop::new(model(&s, 10), &s).unwrap();
        simulate(&mut sys, &RunOptions::from(&s), &mut |_| {}).unwrap()
    };
    let once = go();
    println!(
        "fe_spatial/move n10_dopri5_1.2s: {} steps, {} RHS",
        once.stats.steps_accepted, once.stats.rhs_evals
    );
    group.bench_function("n10_dopri5_1.2s", |b| b.iter(|| black_box(go().t_reached)));
    // The goal row: 5 s on the implicit path at its default step (1e-4 s).
    let mut s = hangprinter(10);
    s.simulation.integrator = cdpr_bench::core::scenario::IntegratorKind::Implicit;
    s.simulation.t_final = 5.0;
    s.simulation.sample_period = 5.0;
    let go = || {
        let mut sys = ClosedLoop::new(model(&s, 10), &s).unwrap();
        simulate(&mut sys, &RunOptions::from(&s), &mut |_| {}).unwrap()
    };
    let once = go();
    println!(
        "fe_spatial/move n10_implicit_5s: {} steps, {} RHS, {} factorisations",
        once.stats.steps_accepted, once.stats.rhs_evals, once.stats.factorisations
    );
    group.bench_function("n10_implicit_5s", |b| b.iter(|| black_box(go().t_reached)));
    group.finish();
}

fn scaling(c: &mut Criterion) {
    let mut group = c.benchmark_group("fe_spatial/implicit_0.5s_vs_n");
    group.sample_size(10);
    for n in [10, 100, 1000] {
        let mut s = hangprinter(n);
        s.simulation.integrator = cdpr_bench::core::scenario::IntegratorKind::Implicit;
        s.simulation.t_final = 0.5;
        s.simulation.sample_period = 0.5;
        let go = || {
            let mut sys = ClosedLoop::new(model(&s, n), &s).unwrap();
            simulate(&mut sys, &RunOptions::from(&s), &mut |_| {}).unwrap()
        };
        let once = go();
        println!(
            "fe_spatial/implicit_0.5s_vs_n n{n}: {} steps, {} residuals, {} factorisations",
            once.stats.steps_accepted, once.stats.rhs_evals, once.stats.factorisations
        );
        group.bench_function(format!("n{n}"), |b| b.iter(|| black_box(go().t_reached)));
    }
    group.finish();
}

criterion_group!(benches, rhs, run, scaling);
criterion_main!(benches);
