//! Property tests of the elastic model against references it did not produce: the force balance
//! written out independently, eq. 15 in the small-sag limit, and the first integral of MODELS.md §3.

use cdpr_core::channel::Channel;
use cdpr_core::closed_loop::{Actuation, ClosedLoop};
use cdpr_core::model::{CableModel, SplitRule};
use cdpr_core::robot::Tensions;
use cdpr_core::runner::{RunOptions, simulate_from};
use cdpr_core::scenario::Scenario;
use cdpr_elastic::{Elastic, eq15_frequency};
use cdpr_numerics::Dopri5Options;
use nalgebra::Vector2;
use proptest::prelude::*;

fn model(d: f64, mass: f64, g: f64) -> Elastic<2> {
    let mut s = Scenario::paper();
    s.robot.anchor_distance = d;
    s.robot.effector_mass = mass;
    s.robot.gravity = g;
    Elastic::from_scenario(&s)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Eq. 14 holds at the Newton solution for any position and pretension: the force balance,
    /// written here from eq. 2–3 directly, vanishes to 1e-7 N (the solver's stopping criterion;
    /// the round-off floor is ~1e-13 N for forces of ~100 N).
    #[test]
    fn equilibrium_balances_forces(
        d in 0.5f64..3.0,
        frac in 0.05f64..0.95,
        mass in 0.1f64..5.0,
        margin in 1.2f64..20.0,
    ) {
        let g = 9.81;
        let tension_sum = margin * mass * g;
        let mut m = model(d, mass, g);
        let x = frac * d;
        let eq = m.equilibrium(&SplitRule::new(x, tension_sum)).unwrap();
        let z = eq.state[1];
        prop_assert!(z < 0.0, "the effector hangs below the pulleys");
        let (t1, t2) = (0.5 * (tension_sum - eq.force()), 0.5 * (tension_sum + eq.force()));
        let (l1, l2) = (x.hypot(z), (d - x).hypot(z));
        let fx = t1 * (-x) / l1 + t2 * (d - x) / l2;
        let fz = t1 * (-z) / l1 + t2 * (-z) / l2 - mass * g;
        prop_assert!(fx.abs() < 1e-7 && fz.abs() < 1e-7, "residual ({fx:e}, {fz:e}) N");
        // Symmetry: the mirrored position needs the mirrored force.
        let mirror = m.equilibrium(&SplitRule::new(d - x, tension_sum)).unwrap();
        prop_assert!((mirror.force() + eq.force()).abs() < 1e-9 * tension_sum);
        prop_assert!((mirror.state[1] - z).abs() < 1e-12);
    }

    /// In the small-sag limit the geometric vertical frequency tends to eq. 15. With the sag angle
    /// θ ≤ M g/(2 T) ≤ 5e-4 the two differ by O(θ²) ≤ 1e-6 relative; 1e-5 leaves room for the
    /// O(θ²) tension difference T1 ≠ T2 off-centre.
    #[test]
    fn vertical_frequency_tends_to_eq15(
        frac in 0.1f64..0.9,
        mass in 0.1f64..3.0,
        tension_sum in 50.0f64..500.0,
        sag_ratio in 1e-6f64..1e-3,
    ) {
        let d = 1.0;
        let g = sag_ratio * tension_sum / mass;
        let mut m = model(d, mass, g);
        let x = frac * d;
        let eq = m.equilibrium(&SplitRule::new(x, tension_sum)).unwrap();
        let tensions = Tensions::pair([0.5 * (tension_sum - eq.force()), 0.5 * (tension_sum + eq.force())]);
        let geometric = m.vertical_frequency(&Vector2::new(x, eq.state[1]), &tensions);
        let eq15 = eq15_frequency(0.5 * tension_sum, mass, x, d);
        prop_assert!((geometric / eq15 - 1.0).abs() < 1e-5, "{geometric} vs {eq15}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// At finite sag (the paper's 2.3° to 10° at mid-span) the geometric vertical frequency is
    /// √(Σ T_i cos²θ_i / (M l_i)), θ_i each cable's angle below the horizontal, written here from
    /// the equilibrium's geometry (MODELS.md §3), not from the model's unit vectors: 1e-12
    /// relative (round-off of two angles). Dropping cos²θ errs by θ² ≥ 1.6e-3 here. As the sag
    /// vanishes it is eq. 15 (the test above).
    #[test]
    fn vertical_frequency_at_finite_sag_has_cos2(
        frac in 0.15f64..0.85,
        mass in 0.3f64..3.0,
        tension_sum in 60.0f64..600.0,
        sag_degrees in 2.3f64..10.0,
    ) {
        let d = 1.0;
        // M g = ΣT sin θ at mid-span sets the sag angle.
        let g = tension_sum * sag_degrees.to_radians().sin() / mass;
        let mut m = model(d, mass, g);
        let x = frac * d;
        let eq = m.equilibrium(&SplitRule::new(x, tension_sum)).unwrap();
        let z = eq.state[1];
        let tensions = Tensions::pair([0.5 * (tension_sum - eq.force()), 0.5 * (tension_sum + eq.force())]);
        let stiffness: f64 = [x, d - x]
            .into_iter()
            .zip(tensions.iter())
            .map(|(horizontal, t)| {
                let theta = (-z).atan2(horizontal);
                t * theta.cos().powi(2) / horizontal.hypot(z)
            })
            .sum();
        let expected = (stiffness / mass).sqrt();
        let geometric = m.vertical_frequency(&Vector2::new(x, z), &tensions);
        prop_assert!((geometric / expected - 1.0).abs() < 1e-12, "{geometric} vs {expected}");
        prop_assert!(-z / x.min(d - x) > 0.035, "the sag is finite: z = {z}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// PID off, constant tensions: E = ½M|v|² + M g z + T1 l1 + T2 l2 is a first integral
    /// (MODELS.md §3). Random tensions (the equilibrium set of a random position and pretension)
    /// and random disturbed initial states, 1 s of motion at rtol 1e-10: the drift is bounded by
    /// the integrator's global error, ~1e-10 relative of E ≈ ΣT·l ≈ 100 J; we allow 1e-7 J.
    #[test]
    fn energy_is_a_first_integral_with_constant_tensions(
        frac in 0.3f64..0.7,
        tension_sum in 50.0f64..400.0,
        dx in -5e-3f64..5e-3,
        dz in -5e-3f64..5e-3,
        vx in -0.05f64..0.05,
        vz in -0.05f64..0.05,
    ) {
        let scenario = Scenario::paper();
        let mut m = Elastic::from_scenario(&scenario);
        let x = frac * scenario.robot.anchor_distance;
        let eq = m.equilibrium(&SplitRule::new(x, tension_sum)).unwrap();
        let tensions = Tensions::pair([0.5 * (tension_sum - eq.force()), 0.5 * (tension_sum + eq.force())]);
        let mut sys = ClosedLoop::new(m, &scenario).unwrap();
        sys.actuation = Actuation::Prescribed(Box::new(move |_| tensions));
        let y0 = vec![x + dx, eq.state[1] + dz, vx, vz, 0.0, 0.0, 0.0, 0.0];
        let opts = RunOptions::dopri5(1.0, 1e-3, Dopri5Options { rtol: 1e-10, atol: 1e-12, ..Dopri5Options::default() });
        let run = simulate_from(&mut sys, y0, eq, &opts, &mut |_| {}).unwrap();
        let s = &run.series;
        let col = |c: Channel| s.column(c).unwrap();
        let own = |name: &str| s.column_named(name).unwrap();
        let (ek, eg, l1, l2, resid) = (
            col(Channel::EKinetic),
            col(Channel::EGravity),
            own("l1"),
            own("l2"),
            col(Channel::EResidual),
        );
        let energy: Vec<f64> = (0..s.len())
            .map(|i| ek[i] + eg[i] + tensions[0] * l1[i] + tensions[1] * l2[i])
            .collect();
        let drift = energy.iter().map(|e| (e - energy[0]).abs()).fold(0.0, f64::max);
        prop_assert!(drift < 1e-7, "first integral drifted by {drift:e} J");
        // The runner's own audit (reel work integrated alongside) says the same.
        let audit = resid.iter().map(|r| r.abs()).fold(0.0, f64::max);
        prop_assert!(audit < 1e-7, "energy audit residual {audit:e} J");
        // And the motion was not trivial: the disturbance moved energy between its forms.
        let swing = ek.iter().fold(0.0f64, |m, &v| m.max(v));
        prop_assert!(swing > 0.0);
    }
}

/// The model's reel speeds are the rates at which the strained lengths shrink: −dl_i/dt by
/// central differences along a uniform motion, to 1e-8 m/s (difference step 1e-6 s, O(h²) error).
#[test]
fn reel_speeds_are_the_shortening_rates() {
    let m = Elastic::from_scenario(&Scenario::paper());
    let y = [0.37, -0.08, 0.4, -0.3];
    let h = 1e-6;
    let lengths = |t: f64| {
        let p = Vector2::new(y[0] + y[2] * t, y[1] + y[3] * t);
        [0, 1].map(|i| m.robot.chord(i, &p).length)
    };
    let (lp, lm) = (lengths(h), lengths(-h));
    let v = m.reel_speeds(&y);
    for i in 0..2 {
        let rate = -(lp[i] - lm[i]) / (2.0 * h);
        assert!(
            (v[i] - rate).abs() < 1e-8,
            "cable {}: {} vs {}",
            i + 1,
            v[i],
            rate
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Eq. 1 inverted: the unstrained lengths the model reports (`unstrained_lengths` and the
    /// `l0_1`, `l0_2` channels) give back each tension by Hooke's law, T = EA (l − l0)/l0, with
    /// l = |P − A_i| written here from the geometry. Relative tolerance 1e-12 · EA/T: the
    /// subtraction l − l0 ≈ l T/EA turns the ~2e-16 rounding of l0 into ~2e-16 · EA/T of T
    /// (up to 4e-11 here); a wrong eq. 1 errs by O(1).
    #[test]
    fn unstrained_lengths_invert_hookes_law(
        x in 0.05f64..0.95,
        z in -0.5f64..-0.001,
        t1 in 1.0f64..500.0,
        t2 in 1.0f64..500.0,
    ) {
        let m = model(1.0, 1.0, 9.81);
        let ea = m.axial_stiffness;
        let p = Vector2::new(x, z);
        let lengths = [p.norm(), (p - Vector2::new(1.0, 0.0)).norm()];
        let reported = m.unstrained_lengths(&p, &[t1, t2]);
        let mut channels = vec![0.0; 4];
        let y = [x, z, 0.0, 0.0];
        m.channels(&y, &[t1, t2], &mut channels);
        for (k, t) in [t1, t2].into_iter().enumerate() {
            prop_assert!((channels[k] / lengths[k] - 1.0).abs() < 1e-15, "l{}", k + 1);
            for l0 in [reported[k], channels[2 + k]] {
                let back = ea * (lengths[k] - l0) / l0;
                prop_assert!((back / t - 1.0).abs() < 1e-12 * ea / t, "T{} = {t} N, back {back} N", k + 1);
            }
        }
    }
}
