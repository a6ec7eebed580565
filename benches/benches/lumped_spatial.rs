//! Cost of the lumped cables in space (MODELS.md §4 along each cable, §11): the Hangprinter
//! example's move on lumped lines (examples/robots/hangprinter-lumped.toml), 5 s, integration
//! only — on the implicit path at its default step (1e-4 s) and on DOPRI5 at the default
//! tolerances — and the implicit path's cost against N (10 … 1000 springs per line, 0.5 s) to
//! show it O(N m). Steps and RHS (or Newton iterations) of each run are printed once.

use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::runner::{RunOptions, simulate};
use cdpr_bench::core::scenario::{ControllerKind, IntegratorKind, Scenario};
use cdpr_bench::lumped::spatial::LumpedSpatial;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn hangprinter(integrator: IntegratorKind, t_final: f64) -> Scenario {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/hangprinter-lumped.toml");
    let mut s = Scenario::from_file(&path).unwrap();
    s.simulation.integrator = integrator;
    s.simulation.t_final = t_final;
    s.simulation.sample_period = t_final;
    s
}

fn run(s: &Scenario, elements: usize) -> cdpr_bench::core::runner::Run {
    let model = LumpedSpatial::from_scenario(s, elements).unwrap();
    let mut sys = ClosedLoop::new(model, s).unwrap();
    simulate(&mut sys, &RunOptions::from(s), &mut |_| {}).unwrap()
}

fn run_5s(c: &mut Criterion) {
    let mut group = c.benchmark_group("lumped_spatial/run_5s_integration_only");
    group.sample_size(10);
    for (name, integrator, length) in [
        ("hangprinter_n20_implicit", IntegratorKind::Implicit, false),
        ("hangprinter_n20_dopri5", IntegratorKind::Dopri5, false),
        (
            "hangprinter_n20_dopri5_length_reels",
            IntegratorKind::Dopri5,
            true,
        ),
    ] {
        let mut s = hangprinter(integrator, 5.0);
        if length {
            // The firmware's reels: driven by length, flex compensation by the static load.
            s.controller.kind = ControllerKind::Length;
        }
        let r = run(&s, 20);
        eprintln!(
            "{name}: {} steps, {} RHS, {} Newton iterations, {} factorisations, {} events",
            r.stats.steps_accepted,
            r.stats.rhs_evals,
            r.stats.newton_iterations,
            r.stats.factorisations,
            r.events.len()
        );
        group.bench_function(name, |b| b.iter(|| black_box(run(&s, 20).t_reached)));
    }
}

fn scaling(c: &mut Criterion) {
    let mut group = c.benchmark_group("lumped_spatial/implicit_0.5s_vs_n");
    group.sample_size(10);
    let s = hangprinter(IntegratorKind::Implicit, 0.5);
    for n in [10, 100, 1000] {
        let r = run(&s, n);
        eprintln!(
            "n = {n}: {} steps, {} Newton iterations, {} factorisations",
            r.stats.steps_accepted, r.stats.newton_iterations, r.stats.factorisations
        );
        group.bench_function(format!("n{n}"), |b| {
            b.iter(|| black_box(run(&s, n).t_reached))
        });
    }
}

criterion_group!(benches, run_5s, scaling);
criterion_main!(benches);
