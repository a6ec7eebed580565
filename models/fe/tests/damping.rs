//! MODELS.md FE.5.7: the Kelvin–Voigt axial damping. Its terms are derived, not checked like
//! FE.5.3, so FE.5.7 demands the dissipation identity dE/dt = Σ T_i ρ_i' − D before relying on
//! them: a wrong sign, a missing l-row term or the wrong (1 + ε) factor breaks the balance by an
//! amount of the order of D itself.

use crate::common;

use cdpr_core::channel::Channel;
use cdpr_core::model::{CableModel, SplitRule};
use cdpr_core::scenario::Scenario;
use cdpr_fe::{Fe, FeMass, FeStored, Params};
use common::*;

/// Prescribed tensions (FE.10.3's) and a kick of both reel ends (ρ_i' = ∓0.5 m/s, with the free
/// span's l_i' to match), so that the axial modes ring and the damping (C = 1 N s, ζ ≈ C ω/(2 EA)
/// ≈ 1.6 % at the lowest axial mode) dissipates ~1e-4 J within the 0.3 s run. Bounds on
/// max |E − E0 − W + D|: 1e-8 J at rtol 1e-8 (the undamped identity reaches 1.5e-10 J there,
/// FE.10.3) and 1e-6 J at rtol 1e-5; both at least 100× below the energy dissipated, which the
/// test also asserts, so a wrong damping term cannot hide under the bound. Measured: 4e-9 and
/// 6e-11 J (consistent mass), 5e-9 and 3.5e-10 J (lumped mass) against D = 2.3e-3 J.
#[test]
fn damped_energy_balance_holds() {
    for mass in [FeMass::Consistent, FeMass::Lumped] {
        for (rtol, atol, bound) in [(1e-5, 1e-8, 1e-6), (1e-8, 1e-11, 1e-8)] {
            let mut scenario = Scenario::paper();
            scenario.cable.axial_damping = 1.0;
            let mut m = Fe::new(&scenario, params(10, mass, FeStored::Elastic)).unwrap();
            assert_eq!(m.axial_damping, 1.0);
            let eq = m.equilibrium(&SplitRule::new(0.5, 200.0)).unwrap();
            let np = m.positions_len();
            let mut y = eq.state.clone();
            for cable in 0..2 {
                let sign = if cable == 0 { -1.0 } else { 1.0 };
                y[np + m.rho_index(cable).unwrap()] = 0.5 * sign;
                y[np + m.l_index(cable)] = -0.5 * sign;
            }
            let d0 = m.dissipation(&y);
            assert!(d0 >= 0.0, "D = {d0} W must not be negative");
            let (run, worst) = wobbling_run(m, &scenario, eq, y, 0.3, (rtol, atol));
            let dissipated = *run
                .series
                .column(Channel::EDissipated)
                .unwrap()
                .last()
                .unwrap();
            eprintln!(
                "{mass:?} rtol {rtol:e}: max |E − E0 − W + D| = {worst:e} J, D = {dissipated:e} J, \
                 {} RHS",
                run.stats.rhs_evals
            );
            assert!(
                worst < bound,
                "{mass:?} rtol {rtol:e}: residual {worst:e} J"
            );
            assert!(
                dissipated > 100.0 * bound,
                "{mass:?}: only {dissipated:e} J dissipated: the check would be vacuous"
            );
        }
    }
}

/// The damping is Kelvin–Voigt: it adds nothing at rest (the static equilibrium and its
/// right-hand side are those of the undamped model, bit for bit), and a negative or NaN
/// coefficient is refused with the key's name.
#[test]
fn damping_vanishes_at_rest_and_is_validated() {
    let mut damped_scenario = Scenario::paper();
    damped_scenario.cable.axial_damping = 3.0;
    let mut damped = Fe::new(&damped_scenario, Params::default()).unwrap();
    let mut plain = model(10, FeMass::Consistent, FeStored::Elastic);
    let eq = plain.equilibrium(&SplitRule::new(0.6, 200.0)).unwrap();
    let eq_damped = damped.equilibrium(&SplitRule::new(0.6, 200.0)).unwrap();
    assert_eq!(eq.state, eq_damped.state);
    let n = plain.state_len();
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    let t = tensions(200.0, eq.force());
    plain.rhs(0.0, &eq.state, &t, &mut a);
    damped.rhs(0.0, &eq.state, &t, &mut b);
    assert_eq!(a, b);
    assert_eq!(damped.dissipation(&eq.state), 0.0);
    for bad in [-1.0, f64::NAN] {
        let mut s = Scenario::paper();
        s.cable.axial_damping = bad;
        let err = Fe::new(&s, Params::default()).unwrap_err();
        assert!(err.to_string().contains("cable.axial_damping"), "{err}");
    }
}

/// FE.5.7's law element by element, written here from the kinematics: N = max(0, EA ε + C ε')
/// with ε = |r_b − r_a|/h − 1 and ε' = (t·(v_b − v_a) − (1 + ε) h' l')/h; the damped part the
/// model returns is N − EA ε. Over stretching and shortening rates that cross the clip (a fast
/// shortening taut element cannot push) and slack elements: 1e-9 N (round-off of ~1e3 N terms).
#[test]
fn damping_tension_is_the_clipped_kelvin_voigt_law() {
    use cdpr_fe::element::{ElementState, Material, damping_tension};
    use nalgebra::Vector2;
    let mat = Material {
        ea: 179_520.0,
        mu: 0.013816,
        gravity: 9.81,
    };
    let mut checked = [0usize; 3];
    for i in 0..200 {
        let f = i as f64 / 199.0;
        let (h, damping) = (0.05, 0.5 + 2.0 * f);
        let strain = -2e-4 + 1.2e-3 * ((7.0 * f).sin() * 0.5 + 0.5);
        let dir = Vector2::new((3.0 * f).cos(), (3.0 * f).sin());
        let ra = Vector2::new(0.1, -0.2);
        let rb = ra + dir * h * (1.0 + strain);
        let speed = 20.0 * ((11.0 * f).cos());
        let (va, vb) = (
            Vector2::zeros(),
            dir * speed + Vector2::new(-dir.y, dir.x) * 0.3,
        );
        let (l_rate, h_prime) = (0.4 * (5.0 * f).sin(), 0.1);
        let s = ElementState::new((ra, va), (rb, vb), l_rate, h, h_prime);
        let (extra, _) = damping_tension(&mat, &s, damping);
        let eps = (rb - ra).norm() / h - 1.0;
        let t = (rb - ra) / (rb - ra).norm();
        let eps_rate = (t.dot(&(vb - va)) - (1.0 + eps) * h_prime * l_rate) / h;
        let (elastic, expected) = if eps > 0.0 {
            let e = mat.ea * eps;
            (e, (e + damping * eps_rate).max(0.0))
        } else {
            (0.0, 0.0)
        };
        assert!(
            (elastic + extra - expected).abs() < 1e-9,
            "ε = {eps:e}, ε' = {eps_rate:e}: N = {} against {expected}",
            elastic + extra
        );
        checked[if eps <= 0.0 {
            0
        } else if expected == 0.0 {
            1
        } else {
            2
        }] += 1;
    }
    assert!(
        checked.iter().all(|&n| n > 5),
        "slack, clipped, taut cases: {checked:?}"
    );
}
