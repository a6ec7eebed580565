//! The lumped cable in space (MODELS.md §4 along each cable's path, §11) checked from outside:
//! its statics against its own right-hand side (which the shooting does not use) and against
//! Irvine's elastic catenary per span; its dynamics against the planar lumped model, an
//! independent implementation, on a robot whose cables lie in the x–z plane. This module holds
//! what the files beside it share: the Hangprinter example's robot and move.

use cdpr_bench::core::model::{CableModel, PoseRule};
use cdpr_bench::core::robot::distribution::{DistributionMethod, TensionBox, distribute};
use cdpr_bench::core::robot::{Robot, Vector};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::lumped::spatial::{CableProperties, LumpedSpatial, default_reel_directions, hang};
use cdpr_bench::lumped::{Lumped, Params};
use cdpr_verify::irvine::Catenary;
use nalgebra::Vector3;
use proptest::prelude::*;

mod modes;
mod passages;
mod planar;
mod reels;
mod runs;
mod statics;
mod tangent;

/// The Hangprinter example's anchors [m] (examples/robots/hangprinter.toml).
const HANGPRINTER: [[f64; 3]; 4] = [
    [0.0, -1.61098, -0.13153],
    [1.31422, 1.26814, -0.12128],
    [-1.41573, 0.70761, -0.12182],
    [0.0, 0.0, 2.29983],
];

/// A Hangprinter-like robot with lumped lines of `elements` springs and density ρ [kg/m³]
/// (the example's line: 970), the anchors moved by `shift` [m].
fn robot(elements: usize, density: f64, shift: [[f64; 3]; 4]) -> LumpedSpatial {
    let anchors: Vec<Vector3<f64>> = HANGPRINTER
        .iter()
        .zip(shift)
        .map(|(a, s)| Vector3::from(*a) + Vector3::from(s))
        .collect();
    let robot = Robot::new(&anchors, 1.0, 9.81).unwrap();
    let cable = CableProperties {
        elements,
        modelled_length: 3.2,
        mass_per_length: density * 9.503e-7,
        axial_stiffness: 2.105e10 * 9.503e-7,
        axial_damping: 0.0,
    };
    LumpedSpatial::new(robot, cable, &default_reel_directions(&anchors)).unwrap()
}

/// The QP's tensions in [10, 70] N holding the weight at `p`, if the box holds it there.
fn holding_if_feasible(
    model: &LumpedSpatial,
    p: &Vector3<f64>,
) -> Option<cdpr_bench::core::robot::Tensions> {
    let w = model.robot().structure_matrix(p);
    let box_ = TensionBox {
        t_min: 10.0,
        t_max: 70.0,
    };
    let d = distribute(
        DistributionMethod::Qp,
        &w,
        &Vector::<3>::new(0.0, 0.0, 9.81),
        box_,
    )
    .ok()?;
    d.feasible.then_some(d.tensions)
}

/// The QP's tensions in [10, 70] N holding the weight at `p` (a pose where the box holds it).
fn holding(model: &LumpedSpatial, p: &Vector3<f64>) -> cdpr_bench::core::robot::Tensions {
    holding_if_feasible(model, p).expect("a pose whose weight the box holds")
}

/// The Hangprinter example's move on lumped lines of `elements` springs and density ρ.
fn hangprinter_move(kind: &str, elements: usize, density: f64) -> cdpr_bench::SpatialRun {
    hangprinter_move_on(kind, elements, density, None)
}

/// [`hangprinter_move`] on the implicit path with a fixed `step` [s] (None: DOPRI5 at the
/// default tolerance; 0: DOPRI5 at rtol 1e-10).
fn hangprinter_move_on(
    kind: &str,
    elements: usize,
    density: f64,
    step: Option<f64>,
) -> cdpr_bench::SpatialRun {
    run(&hangprinter_scenario(kind, elements, density, step))
}

/// The scenario of [`hangprinter_move_on`].
fn hangprinter_scenario(kind: &str, elements: usize, density: f64, step: Option<f64>) -> Scenario {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/robots/hangprinter.toml"
    ))
    .unwrap();
    let mut s: Scenario = cdpr_bench::scenario_from_toml_str(&text).unwrap();
    s.cable.density = density;
    s.cable.modelled_length = 3.2;
    s.simulation.t_final = 0.4;
    s.simulation.sample_period = 1e-3;
    let mut table = toml::Table::new();
    table.insert("kind".into(), kind.into());
    if kind == "lumped" {
        table.insert("elements".into(), (elements as i64).into());
    }
    s.model = cdpr_bench::core::scenario::ModelSection(table);
    match step {
        // Step 0: DOPRI5 at rtol 1e-10, far below the implicit path's error (the reference).
        Some(0.0) => {
            s.simulation.rtol = 1e-10;
            s.simulation.atol = 1e-13;
        }
        Some(h) => {
            s.simulation.integrator = cdpr_bench::core::scenario::IntegratorKind::Implicit;
            s.simulation.step = h;
        }
        None => {}
    }
    s
}

/// Runs a spatial scenario to its end.
fn run(s: &Scenario) -> cdpr_bench::SpatialRun {
    cdpr_bench::simulate_spatial(
        s,
        &mut cdpr_bench::core::runner::Observer::progress(&mut |_| {}),
    )
    .unwrap()
}

/// Largest distance between the effector paths of two runs [m].
fn path_gap(a: &cdpr_bench::SpatialRun, b: &cdpr_bench::SpatialRun) -> f64 {
    let axis = |r: &cdpr_bench::SpatialRun, name: &str| r.run.series.column_named(name).unwrap();
    let mut gap = 0.0f64;
    for name in ["x", "y", "z"] {
        let (a, b) = (axis(a, name), axis(b, name));
        gap = a.iter().zip(&b).fold(gap, |m, (a, b)| m.max((a - b).abs()));
    }
    gap
}

/// Largest distance between the effector paths of two runs up to `until` [s].
fn path_gap_until(a: &cdpr_bench::SpatialRun, b: &cdpr_bench::SpatialRun, until: f64) -> f64 {
    let t = a.run.series.column_named("t").unwrap();
    let axis = |r: &cdpr_bench::SpatialRun, name: &str| r.run.series.column_named(name).unwrap();
    let mut gap = 0.0f64;
    for name in ["x", "y", "z"] {
        let (a, b) = (axis(a, name), axis(b, name));
        for k in (0..t.len()).take_while(|&k| t[k] <= until) {
            gap = gap.max((a[k] - b[k]).abs());
        }
    }
    gap
}
