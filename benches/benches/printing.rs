//! Cost of printing: reading and planning real slicer files (the firmware's work, in segments
//! per second), and the cube's first layer (≈ 44 s of printing at 3 000 mm/s²) printed by the
//! Hangprinter-like robot with elastic cables under computed-torque — the wrench-feasibility
//! check every millisecond and the run (sampled at the end only: integration, reference and
//! controller), and the same layer on the massive lines (lumped N = 20, FE N = 10; the printer
//! example's damped line) on the implicit path, fixed-step and (lumped) error-controlled,
//! sampled every millisecond with the contour error measured, as `cargo xtask print` runs it
//! but for the files. Steps, RHS (residual)
//! evaluations and iteration matrices of each run are printed once.

use cdpr_bench::core::closed_loop::{ClosedLoop, Path as LoopPath};
use cdpr_bench::core::runner::simulate;
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::elastic::Elastic;
use cdpr_bench::printing::{gcode, planner};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../verify/data/print")
        .join(name)
}

fn printer() -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/printing/hangprinter.toml");
    Scenario::from_file(&path).unwrap()
}

fn planning(c: &mut Criterion) {
    let mut group = c.benchmark_group("printing/plan");
    let limits = planner::Limits::new(0.3, 3.0);
    for file in ["cube.gcode", "cylinder.gcode"] {
        let text = std::fs::read_to_string(data(file)).unwrap();
        let program = gcode::read(&text, [0.0; 3]).unwrap();
        let segments = planner::plan(&program, &limits).unwrap().segments.len();
        group.throughput(Throughput::Elements(segments as u64));
        group.bench_function(format!("read_{file}"), |b| {
            b.iter(|| black_box(gcode::read(black_box(&text), [0.0; 3]).unwrap()))
        });
        group.bench_function(format!("plan_{file}"), |b| {
            b.iter(|| black_box(planner::plan(black_box(&program), &limits).unwrap()))
        });
    }
}

fn cube_first_layer(c: &mut Criterion) {
    let mut group = c.benchmark_group("printing/cube_layer1_hangprinter");
    group.sample_size(10);
    let scenario = printer();
    let text = std::fs::read_to_string(data("cube.gcode")).unwrap();
    group.bench_function("prepare_with_feasibility_check", |b| {
        b.iter(|| black_box(cdpr_bench::prepare_print(&scenario, &text, Some(1..=1)).unwrap()))
    });
    let print = cdpr_bench::prepare_print(&scenario, &text, Some(1..=1)).unwrap();
    let mut options = cdpr_bench::print_options(&scenario, &print);
    options.sample_period = options.t_final;
    let make = || {
        let robot = scenario.spatial_robot().unwrap();
        let mut sys = ClosedLoop::new(
            Elastic::new(robot, scenario.cable.axial_stiffness()),
            &scenario,
        )
        .unwrap();
        sys.path = Some(LoopPath::Print(print.path.clone()));
        sys
    };
    let run = simulate(&mut make(), &options, &mut |_| {}).unwrap();
    println!(
        "cube layer 1, elastic, computed-torque: {:.2} s printed, {} steps, {} RHS",
        print.path.plan().print_time,
        run.stats.steps_accepted,
        run.stats.rhs_evals
    );
    group.bench_function("elastic_computed_torque_integration_only", |b| {
        b.iter(|| {
            black_box(
                simulate(&mut make(), &options, &mut |_| {})
                    .unwrap()
                    .t_reached,
            )
        })
    });
}

/// The printer example on massive lines of `kind` with `elements` per line, on the implicit path
/// (its lines long enough for the build volume's corners).
fn on_massive_lines(kind: &str, elements: usize) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/printing/hangprinter.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let text = format!("{text}\n[model]\nkind = \"{kind}\"\nelements = {elements}\n");
    let mut s = Scenario::from_toml_str(&text).unwrap();
    s.cable.modelled_length = 3.2;
    s.simulation.integrator = cdpr_bench::core::scenario::IntegratorKind::Implicit;
    s
}

fn cube_first_layer_massive(c: &mut Criterion) {
    let mut group = c.benchmark_group("printing/cube_layer1_hangprinter");
    group.sample_size(10);
    let text = std::fs::read_to_string(data("cube.gcode")).unwrap();
    // The lumped lines also under error control on the effector (rtol 1e-3, atol 1e-5: the
    // printed contour of a converged run within 0.1 µm, docs/numerics.md "A printed layer").
    let mut adaptive = on_massive_lines("lumped", 20);
    adaptive.simulation.adaptive = true;
    (adaptive.simulation.rtol, adaptive.simulation.atol) = (1e-3, 1e-5);
    adaptive.simulation.error_norm = cdpr_bench::core::scenario::ErrorNorm::Effector;
    for (kind, elements, scenario) in [
        ("lumped", 20, on_massive_lines("lumped", 20)),
        ("fe", 10, on_massive_lines("fe", 10)),
        ("lumped_adaptive_effector_", 20, adaptive),
    ] {
        let print = cdpr_bench::prepare_print(&scenario, &text, Some(1..=1)).unwrap();
        let go = || {
            let mut quiet = |_: f64| {};
            let mut observer = cdpr_bench::core::runner::Observer::progress(&mut quiet);
            cdpr_bench::simulate_print(&scenario, &print, &mut observer).unwrap()
        };
        let once = go();
        println!(
            "cube layer 1, {kind} N = {elements}, computed-torque, implicit: {} steps, {} residuals, {} matrices, contour max {:.1} µm",
            once.run.stats.steps_accepted,
            once.run.stats.rhs_evals,
            once.run.stats.jacobian_evals,
            once.contour.printing.max * 1e6
        );
        group.bench_function(
            format!("{kind}{elements}_computed_torque_implicit_with_contour"),
            |b| b.iter(|| black_box(go().run.t_reached)),
        );
    }
}

criterion_group!(
    benches,
    planning,
    cube_first_layer,
    cube_first_layer_massive
);
criterion_main!(benches);
