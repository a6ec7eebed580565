//! The robot's static equilibrium on the FE and lumped models against Irvine's elastic catenary
//! per free span
//! (Irvine 1981), which uses none of the model's force code. From the model's commanded tensions
//! and free unstrained lengths alone, the two catenaries that start at the pulleys with those
//! tensions (frictionless pulleys, MODELS.md §4–5) and hold the effector's weight between them
//! (one horizontal tension H, found by bisection on the vertical balance) end at one point: it
//! must be the model's effector. Forces → positions is the well-conditioned direction (a
//! position error of δ costs EA/L δ of force the other way: 3e5 N/m here).

use cdpr_bench::core::Vector2;
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::controller::split_tensions;
use cdpr_bench::core::model::{CableModel, SplitRule};
use cdpr_bench::core::robot::CableId;
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::{ModelConfig, ModelKind, build};
use cdpr_verify::irvine::Catenary;
use proptest::prelude::*;

/// The robot's parameters swept.
#[derive(Debug, Clone, Copy)]
struct Case {
    kind: ModelKind,
    elements: i64,
    x: f64,
    tension_sum: f64,
    youngs: f64,
    density: f64,
    mass: f64,
    length: f64,
}

/// (largest distance from the two catenaries' end points to the model's effector [m], the
/// effector's depth below the pulleys [m], the cable's weight over the smaller tension
/// w L0 / min T_i: the scale of the spans' slope change from their own weight).
fn mismatch(c: Case) -> (f64, f64, f64) {
    let mut s = Scenario::paper();
    s.model = ModelConfig {
        elements: Some(c.elements),
        ..ModelConfig::of_kind(c.kind)
    }
    .into();
    s.cable.youngs_modulus = c.youngs;
    s.cable.density = c.density;
    s.cable.modelled_length = c.length;
    s.robot.effector_mass = c.mass;
    s.controller.tension_sum = c.tension_sum;
    let mut m = build(&s).unwrap();
    let eq = m.equilibrium(&SplitRule::new(c.x, c.tension_sum)).unwrap();
    let p = m.effector(&eq.state).position;
    let names = m.channel_names();
    let mut values = vec![0.0; names.len()];
    let commanded = split_tensions(c.tension_sum, eq.force());
    m.channels(&eq.state, &commanded, &mut values);
    let free = |cable: usize| {
        let name = Channel::LFree(CableId(cable)).name();
        values[names.iter().position(|n| *n == name).unwrap()]
    };
    let (l1, l2) = (free(0), free(1));
    let (w, ea) = (
        s.cable.mass_per_length() * s.robot.gravity,
        s.cable.axial_stiffness(),
    );
    let weight = c.mass * s.robot.gravity;
    // Vertical balance at the effector: √(T1² − H²) + √(T2² − H²) = w (L1 + L2) + M g.
    let [t1, t2] = commanded;
    let balance =
        |h: f64| (t1 * t1 - h * h).sqrt() + (t2 * t2 - h * h).sqrt() - w * (l1 + l2) - weight;
    let (mut lo, mut hi) = (0.0, t1.min(t2));
    assert!(
        balance(lo) > 0.0 && balance(hi) < 0.0,
        "{c:?}: no H balances the weight"
    );
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if balance(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    let h = 0.5 * (lo + hi);
    let end = |t: f64, l: f64| {
        Catenary {
            horizontal: h,
            vertical: -(t * t - h * h).sqrt(),
            weight: w,
            axial_stiffness: ea,
        }
        .position(l)
    };
    let e1 = end(t1, l1);
    let e2 = end(t2, l2);
    let p1 = Vector2::new(e1[0], e1[1]);
    let p2 = Vector2::new(s.robot.anchor_distance - e2[0], e2[1]);
    (
        (p1 - p).norm().max((p2 - p).norm()),
        -p.y,
        w * c.length / t1.min(t2),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Over the effector's x and ΣT, the cable's EA, μ and length, the effector's mass and the
    /// element count: the FE model is second order, so halving the elements divides the distance
    /// between the catenaries' end and the model's effector by 3–5 (the error constant depends
    /// on the sag, so the order is asserted wherever the distance is above 1e-10 m; a defect
    /// that does not vanish with the mesh, such as a cable 1 % too heavy, sends the ratio to 1),
    /// and at 2N the distance is below 1e-5 of the effector's depth.
    #[test]
    fn fe_equilibria_are_irvine_catenaries(
        elements in 8i64..24,
        x in 0.3f64..0.7,
        tension_sum in 120.0f64..400.0,
        youngs in 30e9f64..200e9,
        density in 2000.0f64..15000.0,
        mass in 0.3f64..3.0,
        length in 1.0f64..1.5,
    ) {
        let c = Case { kind: ModelKind::Fe, elements, x, tension_sum, youngs, density, mass, length };
        let (coarse, depth, _) = mismatch(c);
        let (fine, _, _) = mismatch(Case { elements: 2 * elements, ..c });
        // A taut, light cable's discretisation error can fall to the Newton stop's position
        // error, ~1e-7 N over EA/L ≈ 4e4 N/m, 2.4e-12 m (a case at 3.3e-12 → 1.3e-12 m): the order
        // is asserted where the error stands 40× above that.
        if coarse > 1e-10 {
            let ratio = coarse / fine;
            prop_assert!((3.0..=5.0).contains(&ratio), "{c:?}: distance {coarse:e} → {fine:e} m");
        }
        prop_assert!(fine <= 1e-5 * depth, "{c:?}: distance {fine:e} m, depth {depth} m");
    }

    /// The lumped model converges too, at first order: MODELS.md §4 puts element j's weight at
    /// its start node, l0/2 off the continuum's centroid, which tilts the spans by ~ (w L0/T)
    /// and moves their end by ~ l0 · w L0/T (measured 0.6–0.9 of that, from the paper's robot
    /// to a heavy cable on a light effector). The ratio between N and 2N is not asserted: the
    /// straddling spring's share of the free length jumps with N (measured 1.18 … 1.96); the
    /// envelope ≤ 2 l0 w L0/T at both N and 2N is. It does not see a cable 1 % too heavy (the
    /// reference given 1 % more weight still passes); the FE test above does (its ratio falls
    /// to 1.00).
    #[test]
    fn lumped_equilibria_converge_to_irvine_catenaries(
        elements in 20i64..60,
        x in 0.3f64..0.7,
        tension_sum in 120.0f64..400.0,
        youngs in 30e9f64..200e9,
        density in 2000.0f64..15000.0,
        mass in 0.3f64..3.0,
        length in 1.0f64..1.5,
    ) {
        let c = Case { kind: ModelKind::Lumped, elements, x, tension_sum, youngs, density, mass, length };
        let (coarse, _, slope) = mismatch(c);
        let (fine, _, _) = mismatch(Case { elements: 2 * elements, ..c });
        let l0 = length / elements as f64;
        prop_assert!(coarse <= 2.0 * l0 * slope, "{c:?}: distance {coarse:e} m, l0 w L0/T {:e} m", l0 * slope);
        prop_assert!(fine <= l0 * slope, "{c:?}: distance {fine:e} m at 2N");
    }
}
