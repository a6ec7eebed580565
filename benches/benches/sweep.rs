//! Cost of one sweep point, metrics-only (`cdpr_sweep::evaluate`: scenario read and checked,
//! run, every metric of metrics.json, the samples dropped): the paper run on each model, with
//! the paper's 0.01 ms samples and with the 1 ms a metrics-only elastic study needs (its
//! spectra read peaks below 3 142 rad/s), and the implicit lumped and FE runs at 0.1 ms.

use cdpr_sweep::Grid;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn grid(scenario: &str) -> Grid {
    Grid::from_toml_str(
        &format!("[scenario]\n{scenario}\nanalysis = {{ modes = \"off\" }}\n[axes]\n\"robot.effector_mass\" = [1.0]\n"),
        "bench",
    )
    .unwrap()
}

fn points(c: &mut Criterion) {
    let mut group = c.benchmark_group("sweep/point");
    group.sample_size(10);
    for (name, scenario) in [
        (
            "elastic_sample_1e-3",
            "simulation = { sample_period = 1e-3 }",
        ),
        ("elastic_sample_1e-5", ""),
        (
            "lumped_implicit_sample_1e-4",
            "model = { kind = \"lumped\" }\nsimulation = { integrator = \"implicit\", sample_period = 1e-4 }",
        ),
        (
            "fe_implicit_sample_1e-4",
            "model = { kind = \"fe\" }\nsimulation = { integrator = \"implicit\", sample_period = 1e-4 }",
        ),
    ] {
        let g = grid(scenario);
        group.bench_function(name, |b| {
            b.iter(|| black_box(cdpr_sweep::evaluate(&g, 0, None).unwrap().t_reached))
        });
    }
}

criterion_group!(benches, points);
criterion_main!(benches);
