//! The error-controlled implicit path (generalised-α with the local error estimate of numerics
//! `alpha_error`) on the paper's massive-cable runs: the global error proportional to the
//! tolerance against references it did not produce, every MODELS.md §8 row, and its counters.

use cdpr_bench::ModelKind;
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::runner::Run;
use cdpr_bench::core::scenario::{ErrorNorm, IntegratorKind, Scenario};
use cdpr_bench::{assess, simulate};
use cdpr_verify::acceptance;

fn paper(kind: ModelKind, t_final: f64, sample_period: f64) -> Scenario {
    let mut s = Scenario::paper();
    s.model = kind.into();
    s.simulation.t_final = t_final;
    s.simulation.sample_period = sample_period;
    s.simulation.integrator = IntegratorKind::Implicit;
    s
}

fn adaptive(mut s: Scenario, tol: f64) -> Scenario {
    s.simulation.adaptive = true;
    s.simulation.rtol = tol;
    s.simulation.atol = tol;
    s.validate().unwrap();
    s
}

/// `s` on DOPRI5 at rtol 1e-11, atol 1e-13: a reference from another integrator.
fn dopri(s: &Scenario) -> Scenario {
    let mut s = s.clone();
    s.simulation.integrator = IntegratorKind::Dopri5;
    s.simulation.rtol = 1e-11;
    s.simulation.atol = 1e-13;
    s
}

/// Largest |x − x_ref| of the effector over the common samples [m].
fn x_error(run: &Run, reference: &Run) -> f64 {
    let (a, b) = (
        run.series.column(Channel::X).unwrap(),
        reference.series.column(Channel::X).unwrap(),
    );
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(&b)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()))
}

/// Global error ∝ tolerance on the paper's move, each model against a reference from another
/// integrator or another step:
/// - FE N = 10, 0.5 s (the move and its first settling), tol 1e-5 … 1e-7, against the fixed
///   step h = 2.5e-5 s. Its own error is 1/15 of its difference from the h = 1e-4 s run (the
///   method is second order: e(h) = 16 e(h/4)), measured 6.3e-9 m over 5 s: 4e-10 m, 20 times
///   below the tightest run's 8.8e-9 m.
/// - Lumped N = 40 up to its first pulley passage (0.02 s; the window is checked event-free),
///   tol 1e-6 … 1e-8, against DOPRI5 at rtol 1e-11. A passage is a discontinuity located on
///   each run's own trajectory; once a node hovers at its pulley, event times are
///   ill-conditioned and runs at different tolerances are different solutions of a
///   discontinuous model (see implicit.rs): over 0.25 s the error against a fine fixed step
///   stalls at 0.6 µm from tol 1e-5 down, so the property is checked where it is defined.
///
/// - The same lumped window with the error measured on the effector alone
///   (`error_norm = "effector"`): the cable's nodes no longer choose the step, and the
///   effector's error must still follow the tolerance.
///
/// Each decade of tolerance must divide the error by 10^(1 ± 0.25) (the band of the numerics
/// test: a step is held while its proposed growth is below 25 %). Measured: 1.03 and 1.03
/// decades (FE), 1.00 and 1.00 (lumped), 0.97 and 1.00 (lumped, effector norm).
#[test]
fn global_error_is_proportional_to_the_tolerance_on_the_paper_runs() {
    let fe = paper(ModelKind::Fe, 0.5, 1e-4);
    let lumped = paper(ModelKind::Lumped, 0.02, 1e-5);
    let cases = [
        ("fe", fe.clone(), [1e-5, 1e-6, 1e-7], {
            let mut s = fe;
            s.simulation.step = 2.5e-5;
            s
        }),
        ("lumped", lumped.clone(), [1e-6, 1e-7, 1e-8], dopri(&lumped)),
        (
            "lumped, effector norm",
            {
                let mut s = lumped.clone();
                s.simulation.error_norm = ErrorNorm::Effector;
                s
            },
            [1e-6, 1e-7, 1e-8],
            dopri(&lumped),
        ),
    ];
    std::thread::scope(|scope| {
        for (name, base, tols, reference) in &cases {
            scope.spawn(move || {
                let reference = simulate(reference, &mut |_| {}).unwrap();
                assert!(reference.events.is_empty(), "{:?}", reference.events);
                let runs: Vec<Run> = tols
                    .iter()
                    .map(|&tol| simulate(&adaptive(base.clone(), tol), &mut |_| {}).unwrap())
                    .collect();
                let errors: Vec<f64> = runs.iter().map(|r| x_error(r, &reference)).collect();
                let steps: Vec<u64> = runs.iter().map(|r| r.stats.steps_accepted).collect();
                eprintln!("{name}: tol {tols:?}: x errors {errors:?}, steps {steps:?}");
                for pair in errors.windows(2) {
                    let decades = (pair[0] / pair[1]).log10();
                    assert!(
                        (0.75..=1.25).contains(&decades),
                        "{name}: {errors:?}: {decades} decades per decade"
                    );
                }
            });
        }
    });
}

/// Every MODELS.md §8 row on the paper's 5 s runs with the implicit path under error control at
/// the scenario's default tolerances (rtol 1e-5, atol 1e-9, DOPRI5's), as the fixed step passes
/// them (implicit.rs); the lumped high-frequency row is judged there on a fine fixed step, since
/// its level depends on how the pulley events excite the axial modes. The counters go to
/// metrics.json; an error-controlled FE run takes fewer steps than the fixed one (measured
/// 8 211 against 50 000).
#[test]
fn section_8_rows_pass_under_error_control_at_the_default_tolerance() {
    let is_hf = |c: &acceptance::Check| c.quantity.starts_with("high-frequency");
    let outcomes: Vec<_> = std::thread::scope(|scope| {
        let handles: Vec<_> = ModelKind::MASSIVE
            .into_iter()
            .map(|kind| {
                scope.spawn(move || {
                    let mut s = paper(kind, 5.0, 1e-5);
                    s.simulation.adaptive = true;
                    s.validate().unwrap();
                    (kind, assess(&s, &mut |_| {}).unwrap(), s)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (kind, outcome, s) in &outcomes {
        let stats = outcome.run.stats;
        eprintln!("{kind}: {stats:?}, wall {} s", outcome.run.wall_s);
        let rows = acceptance::model_checks(&acceptance::result(outcome, s));
        let failed: Vec<_> = rows
            .iter()
            .filter(|c| !c.pass)
            .filter(|c| !(*kind == ModelKind::Lumped && is_hf(c)))
            .collect();
        assert!(failed.is_empty(), "{kind}: failed §8 rows: {failed:#?}");
        assert_eq!(outcome.metrics.steps_rejected, stats.steps_rejected);
        assert_eq!(outcome.metrics.factorisations, stats.factorisations);
        if *kind == ModelKind::Fe {
            assert!(stats.steps_accepted < 25_000, "{stats:?}");
        }
    }
}

/// Error control on the effector (`error_norm = "effector"`) on the lumped paper run (5 s, N =
/// 40, rtol 1e-5, atol 1e-6) reaches the accuracy of the fixed h = 1e-4 s run by the issue's
/// bars — T1 min within 1e-3 N, z p2p within 1e-3 relative, the settled error within 1e-7 m
/// (measured 3.0e-4 N, 4.6e-5, 2.5e-9 m) — in under a fifth of its steps (measured 4 147
/// against 51 769: the nodes' string vibrations no longer set the step), and passes every
/// MODELS.md §8 row the fixed step passes (the high-frequency row aside, as above).
#[test]
fn effector_error_control_reaches_the_fixed_step_accuracy_on_the_lumped_paper_run() {
    let fixed = paper(ModelKind::Lumped, 5.0, 1e-4);
    let mut controlled = adaptive(fixed.clone(), 1e-5);
    controlled.simulation.atol = 1e-6;
    controlled.simulation.error_norm = ErrorNorm::Effector;
    controlled.validate().unwrap();
    let (reference, outcome) = std::thread::scope(|scope| {
        let reference = scope.spawn(|| assess(&fixed, &mut |_| {}).unwrap());
        let outcome = assess(&controlled, &mut |_| {}).unwrap();
        (reference.join().unwrap(), outcome)
    });
    let (m, r) = (&outcome.metrics, &reference.metrics);
    eprintln!(
        "T1 min {:e} N apart, z p2p {:e} relative, settled {:e} m; steps {} against {}",
        (m.t1_min - r.t1_min).abs(),
        (m.z_p2p / r.z_p2p - 1.0).abs(),
        (m.err_max_settled - r.err_max_settled).abs(),
        outcome.run.stats.steps_accepted,
        reference.run.stats.steps_accepted
    );
    assert!((m.t1_min - r.t1_min).abs() <= 1e-3);
    assert!((m.z_p2p / r.z_p2p - 1.0).abs() <= 1e-3);
    assert!((m.err_max_settled - r.err_max_settled).abs() <= 1e-7);
    assert!(5 * outcome.run.stats.steps_accepted < reference.run.stats.steps_accepted);
    let is_hf = |c: &acceptance::Check| c.quantity.starts_with("high-frequency");
    let failed: Vec<_> = acceptance::model_checks(&acceptance::result(&outcome, &controlled))
        .into_iter()
        .filter(|c| !c.pass && !is_hf(c))
        .collect();
    assert!(failed.is_empty(), "failed §8 rows: {failed:#?}");
}
