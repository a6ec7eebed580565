//! Cost of a spatial robot's run against the planar paper's: one closed-loop RHS evaluation and a
//! 5 s run (integration only, DOPRI5 at the paper's tolerances) of the Hangprinter example's move
//! with the elastic model, under the paper's PID per axis and under computed-torque, both through
//! the exact QP distribution. Steps and RHS evaluations of each run are printed once: the cost
//! per RHS and the number of RHS are the two factors of the ratio.

use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::runner::{RunOptions, simulate};
use cdpr_bench::core::scenario::{ControllerKind, Scenario};
use cdpr_bench::elastic::Elastic;
use cdpr_bench::numerics::OdeSystem;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn hangprinter(kind: ControllerKind) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/hangprinter.toml");
    let mut s = Scenario::from_file(&path).unwrap();
    s.controller.kind = kind;
    s.simulation.t_final = 5.0;
    s.simulation.sample_period = s.simulation.t_final;
    s
}

fn spatial_loop(s: &Scenario) -> ClosedLoop<Elastic<3>, 3> {
    let robot = s.spatial_robot().unwrap();
    ClosedLoop::new(Elastic::new(robot, s.cable.axial_stiffness()), s).unwrap()
}

fn rhs(c: &mut Criterion) {
    let mut group = c.benchmark_group("spatial/rhs");
    let paper = Scenario::paper();
    let mut planar = ClosedLoop::new(Elastic::from_scenario(&paper), &paper).unwrap();
    let (y, _) = planar.initial_state().unwrap();
    let mut dy = vec![0.0; y.len()];
    group.bench_function("planar_paper_pid", |b| {
        b.iter(|| {
            planar.rhs(black_box(0.1), black_box(&y), &mut dy);
            black_box(&dy);
        })
    });
    for kind in [ControllerKind::Pid, ControllerKind::ComputedTorque] {
        let s = hangprinter(kind);
        let mut sys = spatial_loop(&s);
        let (y, _) = sys.initial_state().unwrap();
        let mut dy = vec![0.0; y.len()];
        group.bench_function(format!("hangprinter_{}_qp", kind.name()), |b| {
            b.iter(|| {
                sys.rhs(black_box(0.1), black_box(&y), &mut dy);
                black_box(&dy);
            })
        });
    }
}

fn run_5s(c: &mut Criterion) {
    let mut group = c.benchmark_group("spatial/run_5s_integration_only");
    group.sample_size(10);
    let mut paper = Scenario::paper();
    paper.simulation.sample_period = paper.simulation.t_final;
    let opts = RunOptions::from(&paper);
    let mut sys = ClosedLoop::new(Elastic::from_scenario(&paper), &paper).unwrap();
    let run = simulate(&mut sys, &opts, &mut |_| {}).unwrap();
    eprintln!(
        "planar paper pid: {} steps, {} RHS",
        run.stats.steps_accepted, run.stats.rhs_evals
    );
    group.bench_function("planar_paper_pid", |b| {
        b.iter(|| {
            let mut sys = ClosedLoop::new(Elastic::from_scenario(&paper), &paper).unwrap();
            black_box(simulate(&mut sys, &opts, &mut |_| {}).unwrap().t_reached)
        })
    });
    for kind in [ControllerKind::Pid, ControllerKind::ComputedTorque] {
        let s = hangprinter(kind);
        let opts = RunOptions::from(&s);
        let run = simulate(&mut spatial_loop(&s), &opts, &mut |_| {}).unwrap();
        eprintln!(
            "hangprinter {} qp: {} steps, {} RHS",
            kind.name(),
            run.stats.steps_accepted,
            run.stats.rhs_evals
        );
        group.bench_function(format!("hangprinter_{}_qp", kind.name()), |b| {
            b.iter(|| {
                let mut sys = spatial_loop(&s);
                black_box(simulate(&mut sys, &opts, &mut |_| {}).unwrap().t_reached)
            })
        });
    }
}

criterion_group!(benches, rhs, run_5s);
criterion_main!(benches);
