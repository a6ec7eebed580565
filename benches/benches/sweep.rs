//! Cost of one sweep point, metrics-only (`cdpr_sweep::evaluate`: scenario read and checked,
//! run, every metric of metrics.json, the samples dropped): the paper run on each model, with
//! the paper's 0.01 ms samples and with the 1 ms a metrics-only elastic study needs (its
//! spectra read peaks below 3 142 rad/s), and the implicit lumped and FE runs at 0.1 ms.
//!
//! `sweep/spectral_floor`: the transforms MODELS.md §7 asks of every point at the paper's 0.01 ms
//! samples, alone, each planned once beforehand — the floor under an elastic point's cost
//! whatever the rest of the metrics do. The record's [0, 5] s spectrum has 500 001 samples
//! (3 × 166 667, a prime: no fast mixed-radix split), each settled window 400 000.

use cdpr_bench::analysis::spectrum::{Spectrum, Window};
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

/// A settled-looking z [m]: a 20 rad/s ring decaying on a 0.4 m offset, sampled every 1e-5 s.
fn ringing(samples: usize) -> Vec<f64> {
    (0..samples)
        .map(|k| {
            let t = k as f64 * 1e-5;
            0.4 + 1e-4 * (-0.3 * t).exp() * (20.37 * t).sin()
        })
        .collect()
}

fn spectral_floor(c: &mut Criterion) {
    let mut group = c.benchmark_group("sweep/spectral_floor");
    group.sample_size(20);
    for (name, samples, window) in [
        ("record_500001_rectangular", 500_001, Window::Rectangular),
        ("settled_400000_rectangular", 400_000, Window::Rectangular),
        ("settled_400000_hann", 400_000, Window::Hann),
    ] {
        let z = ringing(samples);
        // Planned here, so that the bench times the transform and not the plan.
        black_box(Spectrum::new(&z, 1e-5, window).max_bin(0.0));
        group.bench_function(name, |b| {
            b.iter(|| black_box(Spectrum::new(black_box(&z), 1e-5, window).max_bin(0.0)))
        });
    }
}

criterion_group!(benches, points, spectral_floor);
criterion_main!(benches);
