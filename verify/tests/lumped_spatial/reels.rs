//! Reels driven by length on lumped lines: the paid-out unstrained length against the command,
//! on DOPRI5 and on the implicit path.

use super::*;

/// The example's move with its reels driven by length (the `length` controller, flex
/// compensation by the static load's distribution as the firmware's, here the closed form's,
/// which keeps every line taut) on `kind` lines of `elements` springs, DOPRI5 at `rtol` (None:
/// the default).
fn hangprinter_length_move(
    kind: &str,
    elements: usize,
    rtol: Option<f64>,
) -> cdpr_bench::SpatialRun {
    run(&length_scenario(kind, elements, rtol))
}

/// The scenario of [`hangprinter_length_move`].
fn length_scenario(kind: &str, elements: usize, rtol: Option<f64>) -> Scenario {
    let mut s = hangprinter_scenario(kind, elements, 970.0, None);
    s.controller.kind = cdpr_bench::core::scenario::ControllerKind::Length;
    s.controller.distribution =
        cdpr_bench::core::robot::distribution::DistributionMethod::ClosedForm;
    if let Some(rtol) = rtol {
        s.simulation.rtol = rtol;
        s.simulation.atol = rtol * 1e-3;
    }
    s
}

/// Per cable, the largest difference over the run between the change of a lumped run's free
/// unstrained length (`l_free_i`) and the change of the commanded one (the elastic run's `l0_i`,
/// which reports the command) [m].
fn feed_gaps(lumped: &cdpr_bench::SpatialRun, elastic: &cdpr_bench::SpatialRun) -> Vec<f64> {
    (1..=4)
        .map(|i| {
            let paid = lumped
                .run
                .series
                .column_named(&format!("l_free_{i}"))
                .unwrap();
            let commanded = elastic.run.series.column_named(&format!("l0_{i}")).unwrap();
            paid.iter().zip(&commanded).fold(0.0f64, |gap, (p, c)| {
                gap.max(((p - paid[0]) - (c - commanded[0])).abs())
            })
        })
        .collect()
}

/// Reels driven by length on lumped lines (MODELS.md §11): each reel moves its stored line so
/// that the line crossing the pulley pays out the commanded unstrained length.
/// - The energy balance E − E0 − W_reels + D − ΣΔE closes: the reels' work is now that of the
///   forces driving the stored lines (0.75 J here). The residual is the integration's: 7e-6 J
///   at rtol 1e-6, 1.3e-6 J at 1e-7, 4.6e-7 J at 1e-8 (this test's), 2–7e-7 J below, where the
///   pulley passages' located instants set it. 2e-6 J are allowed; leaving the stored nodes'
///   weight out of the reels' work (a term of ~1e-4 J) leaves 1.5e-4 J.
/// - The free unstrained length of every cable changes as the command does but for the one
///   compliance the lumped reel has and the elastic reel has not: the straddling spring's
///   stored node is up to a segment behind the pulley, so that spring's stored part stretches
///   with the tension and its material slides over the pulley: d Δε ≤ l0 ΔT/EA per stretch of
///   the run between the cable's pulley passages (ΔT the pulley tension's range; measured 21–79
///   µm). That is first order in l0: doubling N halves the largest gap (ratio within [0.4,
///   0.65]; measured 0.54).
///   The same compliance, ≤ l0/l of a line's, shifts the effector's length-controlled modes by
///   as much, so the effector's ringing drifts in phase against the elastic model's (docs).
#[test]
fn reels_driven_by_length_pay_out_the_command() {
    let elastic = hangprinter_length_move("elastic", 0, None);
    let coarse = hangprinter_length_move("lumped", 20, None);
    let fine = hangprinter_length_move("lumped", 40, None);
    let tight = hangprinter_length_move("lumped", 20, Some(1e-8));
    let series = &tight.run.series;
    let residual = series
        .column(cdpr_bench::core::channel::Channel::EResidual)
        .unwrap();
    let worst = residual.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let work = series.column_named("w_reel").unwrap();
    let work = work.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(!coarse.run.events.is_empty(), "no node crossed a pulley");
    assert!(
        work > 0.1,
        "the driven reels did next to no work: {work:e} J"
    );
    assert!(
        worst < 1e-6,
        "energy balance residual {worst:e} J (reel work {work:e} J)"
    );
    let ea = hangprinter_scenario("lumped", 20, 970.0, None)
        .cable
        .axial_stiffness();
    let (gaps, gaps_fine) = (feed_gaps(&coarse, &elastic), feed_gaps(&fine, &elastic));
    let segment = 3.2 / 20.0;
    for (i, gap) in gaps.iter().enumerate() {
        let tension = coarse
            .run
            .series
            .column_named(&format!("T_pulley_{}", i + 1))
            .unwrap();
        let range = tension.iter().fold(f64::NEG_INFINITY, |m, &t| m.max(t))
            - tension.iter().fold(f64::INFINITY, |m, &t| m.min(t));
        let passages = coarse
            .run
            .events
            .iter()
            .filter(|e| e.cable == i + 1)
            .count();
        let bound = (1 + passages) as f64 * segment * range / ea;
        assert!(
            *gap <= bound,
            "cable {}: paid out vs commanded {gap:e} m > {bound:e} m",
            i + 1
        );
    }
    let (worst, worst_fine) = (
        gaps.iter().fold(0.0f64, |m, &g| m.max(g)),
        gaps_fine.iter().fold(0.0f64, |m, &g| m.max(g)),
    );
    let ratio = worst_fine / worst;
    assert!(
        (0.4..=0.65).contains(&ratio),
        "feed gaps {worst:e} m (N = 20), {worst_fine:e} m (N = 40)"
    );
}

/// Reels driven by length on lumped lines on the implicit path (generalised-α, the reels'
/// velocity loop of time constant τ = 1e-4 s in the stored nodes' rows and its c_v m/τ in the
/// iteration matrix), against DOPRI5 at rtol 1e-8 (2e-11 m from rtol 1e-10's path):
/// - Before the first pulley passage (0.069 s) the paths converge at second order: halving the
///   step from 1e-4 to 5e-5 s shrinks the gap by 3.2–5 (measured 4.0, 2.8e-8 → 7e-9 m).
/// - Over the run the gap stays within 5e-7 m (measured 2.6e-7 m at 1e-4 s): from the passages
///   on, the released node's instant rides on the lines' axial ringing, as with tension reels.
/// - The energy balance closes at first order in the step: the fixed step integrates across a
///   passage's kink in the straddling spring's length before the passage is located, and the
///   reel's speed command follows that length, so the audit is off by ~h times the jump of the
///   reels' power (measured 1.3e-3 J at 1e-4 s, 5.3e-4 J at 5e-5 s, of 0.20 J of reel work):
///   within 2e-3 J, and at least 1.8 times smaller at half the step.
/// - The stiff loop is what the implicit path is for: it takes fewer residual evaluations than
///   DOPRI5 at its default tolerance takes right-hand sides by a factor above 5 (measured 13 185
///   against 229 354).
#[test]
fn length_reels_on_lumped_lines_run_on_the_implicit_path() {
    let length_run = |step: Option<f64>, rtol: Option<f64>| {
        let mut s = length_scenario("lumped", 20, rtol);
        if let Some(h) = step {
            s.simulation.integrator = cdpr_bench::core::scenario::IntegratorKind::Implicit;
            s.simulation.step = h;
        }
        run(&s)
    };
    let reference = length_run(None, Some(1e-8));
    let default = length_run(None, None);
    let coarse = length_run(Some(1e-4), None);
    let fine = length_run(Some(5e-5), None);
    let first = reference.run.events[0].t;
    assert!(first > 0.065, "first crossing at {first} s");
    let (early_coarse, early_fine) = (
        path_gap_until(&coarse, &reference, 0.065),
        path_gap_until(&fine, &reference, 0.065),
    );
    assert!(
        (3.2..=5.0).contains(&(early_coarse / early_fine)),
        "gaps before the first crossing: {early_coarse:e} m (1e-4 s), {early_fine:e} m (5e-5 s)"
    );
    let whole = path_gap(&coarse, &reference);
    assert!(whole < 5e-7, "{whole:e} m over the run");
    let residual = |r: &cdpr_bench::SpatialRun| {
        let column = r
            .run
            .series
            .column(cdpr_bench::core::channel::Channel::EResidual)
            .unwrap();
        column.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let (audit_coarse, audit_fine) = (residual(&coarse), residual(&fine));
    assert!(
        audit_coarse < 2e-3 && audit_coarse / audit_fine >= 1.8,
        "energy balance residual {audit_coarse:e} J (1e-4 s), {audit_fine:e} J (5e-5 s)"
    );
    let (implicit, explicit) = (coarse.run.stats.rhs_evals, default.run.stats.rhs_evals);
    assert!(
        5 * implicit < explicit,
        "{implicit} residual evaluations against DOPRI5's {explicit}"
    );
}
