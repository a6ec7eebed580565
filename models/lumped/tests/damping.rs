//! MODELS.md §4's optional Kelvin–Voigt axial damping of the lumped model: the dissipation
//! D = Σ_taut (T − k0(λ − l0)) λ̇ (= (C/l0) λ̇² unclipped) must close the energy balance
//! E − E0 − W + D − ΣΔE = 0 that the runner audits as `e_residual`, with D itself large, so that a
//! damping force without its dissipation (or the reverse) fails.

use cdpr_core::channel::Channel;
use cdpr_core::closed_loop::{Actuation, ClosedLoop};
use cdpr_core::model::{CableModel, SplitRule};
use cdpr_core::robot::Tensions;
use cdpr_core::runner::{RunOptions, simulate_from};
use cdpr_core::scenario::Scenario;
use cdpr_lumped::{Lumped, Params};
use cdpr_numerics::Dopri5Options;

/// From the x = 0.5 equilibrium, the reel end of each cable is kicked (ẋ = ∓0.5 m/s, towards the
/// reel) and the effector too (ż = 0.05 m/s), under prescribed tensions (the FE test's),
/// C = 1 N s, 0.2 s of DP45 at rtol 1e-8: the axial ringing is dissipated (~1e-4 J and more)
/// while max |residual| stays below 1e-8 J (the undamped lumped balance reaches ~1e-10 J at this
/// tolerance) and at least 100× below D. Measured: 1.6e-10 J against D = 1.5e-4 J, through 5
/// pulley events.
#[test]
fn damped_energy_balance_holds() {
    let mut s = Scenario::paper();
    s.cable.axial_damping = 1.0;
    let mut m = Lumped::new(&s, Params::default()).unwrap();
    let eq = m.equilibrium(&SplitRule::new(0.5, 200.0)).unwrap();
    let np = m.positions_len();
    let mut y = eq.state.clone();
    y[np + m.x_index(0, 0)] = -0.5;
    y[np + m.x_index(1, 0)] = 0.5;
    y[np + m.z_index(0, m.elements)] = 0.05;
    assert!(m.dissipation(&y) >= 0.0);
    y.extend_from_slice(&[0.0; 4]);
    let mut sys = ClosedLoop::new(m, &s).unwrap();
    let pi = std::f64::consts::PI;
    sys.actuation = Actuation::Prescribed(Box::new(move |t| {
        Tensions::pair([
            100.0 + 10.0 * (6.0 * pi * t).sin(),
            100.0 + 10.0 * (6.0 * pi * t + 0.5).sin() + 3.0 * (14.0 * pi * t).sin(),
        ])
    }));
    let opts = RunOptions::dopri5(
        0.2,
        1e-4,
        Dopri5Options {
            rtol: 1e-8,
            atol: 1e-11,
            beta: 0.0,
            ..Dopri5Options::default()
        },
    );
    let run = simulate_from(&mut sys, y, eq, &opts, &mut |_| {}).unwrap();
    let worst = run
        .series
        .column(Channel::EResidual)
        .unwrap()
        .iter()
        .fold(0.0f64, |a, r| a.max(r.abs()));
    let dissipated = *run
        .series
        .column(Channel::EDissipated)
        .unwrap()
        .last()
        .unwrap();
    eprintln!(
        "max |E − E0 − W + D − ΣΔE| = {worst:e} J, D = {dissipated:e} J, {} events, {} RHS",
        run.events.len(),
        run.stats.rhs_evals
    );
    assert!(worst < 1e-8, "residual {worst:e} J");
    assert!(
        dissipated > 100.0 * 1e-8,
        "only {dissipated:e} J dissipated"
    );
}
