//! What the lines' mass does to a printer (`cdpr_studies::spatial_printers`), checked from
//! outside the study:
//! - the frames a run hands its observer are the run's own state: the cables' lines start at
//!   their pulleys and end at the effector the sampler recorded at the same instant;
//! - the modal shares the map reads are complete (over all modes of the lumped lines they sum
//!   to 3, one per axis, for a mass-normalised basis), and the lines' mass alone can only lower
//!   the effector's lowest mode, by less than its Rayleigh estimate allows, at any pose of the
//!   Hangprinter's build volume.

use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::scenario::Scenario;
use cdpr_studies::spatial_modes::{SpatialLoop, at_pose};
use cdpr_studies::spatial_printers::{self, Frame};
use proptest::prelude::*;

fn example(name: &str) -> Scenario {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/robots")
        .join(name);
    cdpr_bench::scenario_from_file(&path).unwrap()
}

/// The Hangprinter move cut to 0.25 s, sampled every 2⁻¹⁰ s, so that the frames every 2⁻⁶ s
/// fall on samples exactly.
fn short(name: &str) -> Scenario {
    let mut s = example(name);
    s.simulation.t_final = 0.25;
    s.simulation.sample_period = 1.0 / 1024.0;
    s.validate().unwrap();
    s
}

/// Each frame's cables start at their pulleys and end at the effector the run sampled at the
/// frame's time (the same dense output: to 1e-12 m); one frame per period from t = 0 to the end.
fn check_frames(s: &Scenario, points_per_cable: Option<usize>) {
    let period = 1.0 / 64.0;
    let (run, frames) = spatial_printers::move_frames(s, period).unwrap();
    assert_eq!(frames.len(), 17, "frames at 0, 1/64, …, 16/64 s");
    let robot = cdpr_bench::spatial_robot(s).unwrap();
    let series = &run.run.series;
    let column = |c: Channel| series.column(c).unwrap();
    let (t, x, y, z) = (
        column(Channel::Time),
        column(Channel::X),
        column(Channel::Y),
        column(Channel::Z),
    );
    for (k, Frame { t: tf, cables }) in frames.iter().enumerate() {
        assert_eq!(*tf, k as f64 * period);
        let row = t
            .iter()
            .position(|&ts| ts == *tf)
            .expect("a sample at the frame");
        assert_eq!(cables.len(), robot.cables());
        for (i, cable) in cables.iter().enumerate() {
            let a = robot.anchor(i);
            assert_eq!(
                cable[0],
                [a.x, a.y, a.z],
                "cable {} starts at its pulley",
                i + 1
            );
            if let Some(n) = points_per_cable {
                assert_eq!(cable.len(), n);
            }
            let e = cable.last().unwrap();
            let gap = ((e[0] - x[row]).powi(2) + (e[1] - y[row]).powi(2) + (e[2] - z[row]).powi(2))
                .sqrt();
            assert!(
                gap <= 1e-12,
                "frame {k}, cable {}: effector {gap:e} m off",
                i + 1
            );
        }
    }
}

#[test]
fn frames_of_massive_lines_are_the_runs_state() {
    check_frames(&short("hangprinter-lumped.toml"), None);
}

#[test]
fn frames_of_elastic_cables_are_their_chords() {
    check_frames(&short("hangprinter.toml"), Some(2));
}

/// The Hangprinter on lumped lines of `elements` springs.
fn hangprinter(elements: usize) -> Scenario {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples/robots/hangprinter-lumped.toml"),
    )
    .unwrap()
    .replace("elements = 20", &format!("elements = {elements}"));
    Scenario::from_toml_str(&text).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Anywhere in the Hangprinter's build volume (x, y ∈ ±0.3 m, z ∈ [0, 0.6] m), N = 10 and 20:
    /// - the effector shares of all the lumped lines' modes sum to 3 (to 1e-9): the shapes are
    ///   mass-normalised and complete, so the map's "share ≥ 1/4" reads real fractions;
    /// - the effector's lowest mode on the lumped lines lies at or below the massless elastic
    ///   lines' locked at the same lengths (1e-6 for round-off) and within 0.5 % of it: by
    ///   Rayleigh, a line adds about a third of its mass (≤ 1.5 g of 2.3 m of 0.92 g/m line)
    ///   to the 1 kg effector along its own direction, so the frequency falls by ≲ 0.1 %;
    /// - so does the FE cables' (N = 10, consistent masses) against the elastic lines locked at
    ///   their unstrained lengths l_i.
    #[test]
    fn shares_are_complete_and_the_mass_alone_lowers_the_effectors_mode(
        x in -0.3f64..0.3, y in -0.3f64..0.3, z in 0.0f64..0.6, fine in any::<bool>(),
    ) {
        let s = hangprinter(if fine { 20 } else { 10 });
        let pose = [x, y, z];
        let map = spatial_printers::mode_map(&s, pose, pose, 1).unwrap();
        prop_assume!(map.points.len() == 1);
        let modes = at_pose(&s, pose).unwrap().modes;
        let shares: f64 = modes
            .iter()
            .filter(|m| m.linearisation == SpatialLoop::LumpedLockedReels)
            .map(|m| m.effector_share.unwrap())
            .sum();
        prop_assert!((shares - 3.0).abs() <= 1e-9, "shares sum to {shares}");
        let p = &map.points[0];
        let ratio = p.lumped_locked_rad_s.unwrap() / p.elastic_same_length_rad_s;
        prop_assert!((0.995..=1.0 + 1e-6).contains(&ratio), "lumped / elastic {ratio} at {pose:?}");
        let fe = p.fe_locked_rad_s.unwrap() / p.fe_same_length_rad_s;
        prop_assert!((0.995..=1.0 + 1e-6).contains(&fe), "FE / elastic {fe} at {pose:?}");
    }
}
