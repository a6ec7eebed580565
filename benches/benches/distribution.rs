//! Cost of one tension distribution call (MODELS.md §11) at the rest wrench of the example
//! robots' reference poses:
//!
//! - `distribution/<method>_hangprinter_m4`: Hangprinter v4's anchors, effector at (0, 0, 0.3) m,
//!   box [10, 70] N (goal for the closed form: ≤ 0.5 µs);
//! - `distribution/<method>_cogiro_m8`: CoGiRo's eight (point-reduced) anchors at (0, 0, 2) m,
//!   box [100, 5000] N (goal for the QP: ≤ 5 µs);
//! - `distribution/margin_cogiro_m8`: the largest uniform margin (bisection over QP feasibility).

use cdpr_bench::core::robot::distribution::{DistributionMethod, TensionBox, distribute, margin};
use cdpr_bench::core::scenario::Scenario;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn robot(file: &str) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/robots")
        .join(file);
    Scenario::from_file(&path).unwrap()
}

fn distribution(c: &mut Criterion) {
    let mut group = c.benchmark_group("distribution");
    for (file, name, pose) in [
        ("hangprinter.toml", "hangprinter_m4", [0.0, 0.0, 0.3]),
        ("cogiro.toml", "cogiro_m8", [0.0, 0.0, 2.0]),
    ] {
        let s = robot(file);
        let robot = s.spatial_robot().unwrap();
        let w = robot.structure_matrix(&pose.into());
        let wrench = -robot.weight();
        let limits = TensionBox {
            t_min: s.controller.t_min.unwrap(),
            t_max: s.controller.t_max.unwrap(),
        };
        for method in DistributionMethod::ALL {
            group.bench_function(format!("{}_{name}", method.name()), |b| {
                b.iter(|| distribute(method, black_box(&w), black_box(&wrench), limits).unwrap())
            });
        }
        if name == "cogiro_m8" {
            group.bench_function(format!("margin_{name}"), |b| {
                b.iter(|| margin(black_box(&w), black_box(&wrench), limits).unwrap())
            });
        }
    }
    group.finish();
}

criterion_group!(benches, distribution);
criterion_main!(benches);
