//! The locked robot's modes: named, against their closed forms and the massless lines' locked
//! stiffness, and the effector's modes at any N by the shift-invert eigen-solve.

use super::*;

/// The Hangprinter example on lumped lines of `elements` springs at rest at the origin under
/// the QP's tensions, its reels then locked.
fn locked_at_origin(elements: usize) -> (LumpedSpatial, Vec<f64>) {
    let mut model = robot(elements, 970.0, [[0.0; 3]; 4]);
    let p = Vector3::zeros();
    let rest = model
        .equilibrium(&PoseRule::new(&p, holding(&model, &p)))
        .unwrap()
        .state;
    model.lock_reels(true);
    (model, rest)
}

/// The effector's three modes [rad/s], ascending, on massless elastic lines locked at the
/// lumped lines' lengths (MODELS.md §11: K = Σ (EA/L_i) u_i u_iᵀ + (T_i/l_i)(I − u_i u_iᵀ),
/// L_i = (N − r_i + 1) l0 the springs in series from the held stored node behind the pulley to
/// the effector, T_i the lumped line's tension at the effector).
fn elastic_locked_modes(model: &LumpedSpatial, rest: &[f64]) -> Vec<f64> {
    let n = model.elements;
    let p = model.effector(rest).position;
    let mut stiffness = nalgebra::Matrix3::<f64>::zeros();
    for cable in 0..4 {
        let d = model.pulley(cable) - p;
        let (l, u) = (d.norm(), d.normalize());
        let t = model.spring_force(rest, cable, n - 1);
        let locked = (n - model.stored()[cable] + 1) as f64 * model.segment;
        let ea = model.stiffness * model.segment;
        stiffness += u * u.transpose() * (ea / locked)
            + (nalgebra::Matrix3::identity() - u * u.transpose()) * (t / l);
    }
    cdpr_verify::spatial::point_mass_modes(&stiffness, model.robot().effector_mass)
}

/// The Hangprinter example on lumped lines at rest at its start pose, reels locked (the
/// firmware's robot between moves), every mode named (`cdpr_analysis::rest_modes`):
/// - K is symmetric to 1e-9 (conservative springs; the locked stored lines held).
/// - The effector's x, y and vertical modes are the massless elastic lines' with the same
///   locked lengths (MODELS.md §11: K = Σ (EA/L_i) u_i u_iᵀ + (T_i/l_i)(I − u_i u_iᵀ), L_i =
///   (N − r_i + 1) l0 the springs in series from the held stored node behind the pulley to the
///   effector) within 0.5 % (the lines' 3 g each against the 1 kg effector; 0.12–0.17 % with
///   one stored node, moordyn_spatial.rs), each ≥ 90 % effector motion.
/// - Every cable's lowest out-of-plane string mode is ≥ 90 % motion across its vertical plane,
///   and within 0.2 % of the lowest mode of its free nodes alone with the effector held, across
///   the plane every spring j pulls with its geometric stiffness T_j/λ_j only (exact at first
///   order for a chain in a plane, sagging or not): what differs is the effector's motion,
///   which at ~200 rad/s against its own ~120 rad/s answers the string's ~200 N/m with ~−3e4
///   N/m of inertia (≲ 0.1 %). Its in-plane partner exists; the plumb line under the ceiling
///   anchor has two in-plane families instead.
#[test]
fn the_locked_robots_modes_are_named_and_match_their_closed_forms() {
    use cdpr_bench::analysis::modes::ModeKind;
    let (mut model, rest) = locked_at_origin(20);
    let p = Vector3::zeros();
    let named = cdpr_bench::analysis::rest_modes::rest_modes(&mut model, &rest, &[0.0; 4]).unwrap();
    let asymmetry = named.asymmetry.unwrap();
    assert!(asymmetry <= 1e-9, "asymmetry {asymmetry:e}");
    let find = |kind: ModeKind| {
        named
            .modes
            .iter()
            .find(|m| m.kind == kind && m.order == 1)
            .unwrap_or_else(|| panic!("no {kind} mode"))
    };
    let n = model.elements;
    let elastic = elastic_locked_modes(&model, &rest);
    let mut effector: Vec<f64> = [ModeKind::EffectorX, ModeKind::EffectorY, ModeKind::Vertical]
        .into_iter()
        .map(|kind| {
            let mode = find(kind);
            assert!(mode.purity >= 0.9, "{kind}: purity {}", mode.purity);
            mode.mode.omega
        })
        .collect();
    effector.sort_by(f64::total_cmp);
    eprintln!("effector modes {effector:?}, elastic lines {elastic:?} rad/s");
    for (lumped, elastic) in effector.iter().zip(&elastic) {
        assert!(
            (lumped - elastic).abs() <= 5e-3 * elastic,
            "effector modes {effector:?} against the elastic lines' {elastic:?} rad/s"
        );
    }
    for cable in 0..4 {
        // A plumb line (the ceiling anchor's, straight above the effector) has no vertical plane
        // of its own: its two transverse families are both named in-plane.
        let chord = model.pulley(cable) - p;
        let plumb = chord.x.hypot(chord.y) < 1e-9 * chord.norm();
        let out = if plumb {
            assert!(
                named
                    .modes
                    .iter()
                    .any(|m| m.kind == ModeKind::InPlane(cable) && m.order == 2),
                "cable {}: one transverse family only",
                cable + 1
            );
            find(ModeKind::InPlane(cable))
        } else {
            find(ModeKind::InPlane(cable));
            find(ModeKind::OutOfPlane(cable))
        };
        assert!(
            out.purity >= 0.9,
            "cable {}: purity {}",
            cable + 1,
            out.purity
        );
        // The chain across its plane with the effector held: springs pull a node out of the
        // plane with T_j/λ_j each (the straddling spring's free part with T/|A − P_r|).
        let r = model.stored()[cable];
        let pull = |j: usize| {
            let t = model.spring_force(&rest, cable, j);
            if j + 1 == r {
                t / (model.pulley(cable) - model.node(&rest, cable, r)).norm()
            } else {
                t / model.spring_length(&rest, cable, j)
            }
        };
        let free = n - r;
        let chain = nalgebra::DMatrix::from_fn(free, free, |a, b| {
            let (j, k) = (r + a, r + b);
            if j == k {
                (pull(j - 1) + pull(j)) / model.node_mass
            } else if j + 1 == k {
                -pull(j) / model.node_mass
            } else if k + 1 == j {
                -pull(k) / model.node_mass
            } else {
                0.0
            }
        });
        let string = chain
            .symmetric_eigenvalues()
            .iter()
            .fold(f64::INFINITY, |m, &v| m.min(v))
            .sqrt();
        eprintln!(
            "cable {}: string {} rad/s, held chain {string} rad/s",
            cable + 1,
            out.mode.omega
        );
        assert!(
            (out.mode.omega - string).abs() <= 2e-3 * string,
            "cable {}: out-of-plane {} rad/s against the held chain's {string} rad/s",
            cable + 1,
            out.mode.omega
        );
    }
}

/// The effector's modes at any N, by shift-invert Lanczos on the sparse K − ω²M
/// (`rest_modes_near`, 60 steps): at N = 20 the six modes nearest 120 rad/s are the dense
/// solve's to 1e-9 relative (the Lanczos residuals' order); at N = 1000 — 12 000 coordinates,
/// six times the dense solve's limit — the effector's x, y and vertical modes are among the six
/// and within 0.5 % of the elastic lines' with the same locked lengths, as at N = 20.
#[test]
fn the_effectors_modes_at_any_n_by_shift_invert() {
    use cdpr_bench::analysis::rest_modes::{rest_modes, rest_modes_near};
    use cdpr_verify::spatial::{effector_modes, nearest};
    let (mut model, rest) = locked_at_origin(20);
    let dense = rest_modes(&mut model, &rest, &[0.0; 4]).unwrap();
    let (near, _) = rest_modes_near(&mut model, &rest, &[0.0; 4], (120.0, 6, 60)).unwrap();
    for (found, expected) in near.modes.iter().zip(&nearest(&dense, 120.0, 6)) {
        let omega = found.mode.omega;
        assert!(
            (omega - expected).abs() <= 1e-9 * expected,
            "{omega} rad/s against the dense {expected} rad/s"
        );
    }
    let (mut fine, fine_rest) = locked_at_origin(1000);
    let (near, residuals) =
        rest_modes_near(&mut fine, &fine_rest, &[0.0; 4], (120.0, 6, 60)).unwrap();
    let elastic = elastic_locked_modes(&fine, &fine_rest);
    let effector = effector_modes(&near);
    eprintln!(
        "N = 1000: effector {effector:?}, elastic {elastic:?} rad/s, residuals {residuals:?}"
    );
    for (lumped, elastic) in effector.iter().zip(&elastic) {
        assert!(
            (lumped - elastic).abs() <= 5e-3 * elastic,
            "effector modes {effector:?} against the elastic lines' {elastic:?} rad/s"
        );
    }
}
