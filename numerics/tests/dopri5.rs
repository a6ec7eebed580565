//! The Dormand–Prince 5(4) integrator against references it did not produce: Hairer's published
//! dopri5.f run on the Arenstorf orbit (statistics, dense output, final state), analytic solutions
//! (convergence order of the steps and of the dense output, tolerance proportionality), and the
//! documented behaviour of the norm exclusion, the failure modes and `restart` (MODELS.md §6).

use cdpr_numerics::{Dopri5, Dopri5Options, IntegratorError, OdeSystem, Stepper};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Systems
// ---------------------------------------------------------------------------------------------

/// Restricted three-body problem of Hairer's dr_dopri5.f (FAREN), optionally with a fifth, wildly
/// oscillating component y5' = 1e6 sin(1e6 t) that does not feed back into the orbit.
struct Arenstorf {
    wild: bool,
    calls: u64,
}

const MU: f64 = 0.012277471;

impl Arenstorf {
    fn new(wild: bool) -> Self {
        Self { wild, calls: 0 }
    }
    fn y0(&self) -> Vec<f64> {
        let mut y = vec![0.994, 0.0, 0.0, -2.001_585_106_379_082_5];
        if self.wild {
            y.push(0.0);
        }
        y
    }
}

/// dr_dopri5.f's XEND (one period of the orbit).
const ARENSTORF_T_END: f64 = 17.065_216_560_157_963;

impl OdeSystem for Arenstorf {
    fn dimension(&self) -> usize {
        if self.wild { 5 } else { 4 }
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.calls += 1;
        let mu_p = 1.0 - MU;
        let r1 = (y[0] + MU).powi(2) + y[1] * y[1];
        let r1 = r1 * r1.sqrt();
        let r2 = (y[0] - mu_p).powi(2) + y[1] * y[1];
        let r2 = r2 * r2.sqrt();
        dy[0] = y[2];
        dy[1] = y[3];
        dy[2] = y[0] + 2.0 * y[3] - mu_p * (y[0] + MU) / r1 - MU * (y[0] - mu_p) / r2;
        dy[3] = y[1] - 2.0 * y[2] - mu_p * y[1] / r1 - MU * y[1] / r2;
        if self.wild {
            dy[4] = 1e6 * (1e6 * t).sin();
        }
    }
}

/// y' = λ y.
struct Decay {
    lambda: f64,
}

impl OdeSystem for Decay {
    fn dimension(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = self.lambda * y[0];
    }
}

/// Rotation y1' = ω y2, y2' = −ω y1 (harmonic oscillator); exact: (cos ωt, −sin ωt) from (1, 0).
struct Rotation {
    omega: f64,
}

impl OdeSystem for Rotation {
    fn dimension(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = self.omega * y[1];
        dy[1] = -self.omega * y[0];
    }
}

/// Any system given by a closure (the failure-mode tests), with a call counter that turns a hang
/// into a test failure.
struct Closure<F: FnMut(f64, &[f64], &mut [f64])> {
    n: usize,
    f: F,
    calls: u64,
    limit: u64,
}

impl<F: FnMut(f64, &[f64], &mut [f64])> OdeSystem for Closure<F> {
    fn dimension(&self) -> usize {
        self.n
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.calls += 1;
        assert!(
            self.calls <= self.limit,
            "integrator did not stop after {} RHS evaluations",
            self.limit
        );
        (self.f)(t, y, dy);
    }
}

/// Integrates to `t_end`, returning the integrator and the end times of all accepted steps.
fn run<S: OdeSystem>(
    sys: &mut S,
    opts: Dopri5Options,
    y0: &[f64],
    t_end: f64,
) -> (Dopri5, Vec<f64>) {
    let mut d = Dopri5::new(y0.len(), opts);
    d.start(sys, 0.0, y0, t_end).unwrap();
    let mut times = Vec::new();
    while d.time() < t_end {
        d.step(sys, t_end).unwrap();
        times.push(d.time());
    }
    (d, times)
}

fn arenstorf_options() -> Dopri5Options {
    // dr_dopri5.f: RTOL = ATOL = 1e-7, all WORK/IWORK defaults (β = 0.04, HINIT, HMAX = XEND − X).
    Dopri5Options {
        rtol: 1e-7,
        atol: 1e-7,
        ..Dopri5Options::default()
    }
}

// ---------------------------------------------------------------------------------------------
// Arenstorf orbit: Hairer's published dopri5.f output
// ---------------------------------------------------------------------------------------------

#[test]
fn arenstorf_statistics_match_hairer() {
    let mut sys = Arenstorf::new(false);
    let y0 = sys.y0();
    let (d, _) = run(&mut sys, arenstorf_options(), &y0, ARENSTORF_T_END);
    let s = d.stats();
    // dr_dopri5.f prints fcn = 1442, step = 240, accpt = 216, rejct = 22; its NREJCT skips the two
    // rejections before the first accepted step, ours counts all: 240 − 216 = 24.
    assert_eq!(s.rhs_evals, 1442, "{s:?}");
    assert_eq!(s.steps_attempted, 240, "{s:?}");
    assert_eq!(s.steps_accepted, 216, "{s:?}");
    assert_eq!(s.steps_rejected, 24, "{s:?}");
    assert_eq!(s.restarts, 0);
    // The counter is the real number of calls (1 at start + 1 HINIT probe + 6 per attempt).
    assert_eq!(sys.calls, s.rhs_evals);
    assert_eq!(d.time(), ARENSTORF_T_END, "the last step lands on t_end");
}

#[test]
fn arenstorf_dense_output_matches_hairer() {
    // (x, y1, y2) printed by dr_dopri5.f's SOLOUT through CONTD5 (11 significant digits).
    const REF: [(f64, f64, f64); 8] = [
        (2.0, -5.798_781_410_8e-1, 6.090_775_250_7e-1),
        (4.0, -1.983_335_269_9e-1, 1.137_638_085_7e0),
        (6.0, -4.735_743_943_0e-1, 2.239_068_117_8e-1),
        (8.0, -1.174_553_350_5e0, -2.759_466_982_4e-1),
        (10.0, -8.398_073_466_2e-1, 4.468_302_268_0e-1),
        (12.0, 1.314_712_468_3e-2, -8.385_751_499_4e-1),
        (14.0, -6.031_129_504_1e-1, -9.912_598_031_4e-1),
        (16.0, 2.427_110_998_8e-1, -3.899_948_833_1e-1),
    ];
    let mut sys = Arenstorf::new(false);
    let y0 = sys.y0();
    let mut d = Dopri5::new(4, arenstorf_options());
    d.start(&mut sys, 0.0, &y0, ARENSTORF_T_END).unwrap();
    let mut next = 0;
    let mut out = [0.0; 4];
    while d.time() < ARENSTORF_T_END {
        d.step(&mut sys, ARENSTORF_T_END).unwrap();
        while next < REF.len() && d.previous_time() <= REF[next].0 && REF[next].0 <= d.time() {
            let (x, y1, y2) = REF[next];
            d.dense_output(x, &mut out);
            // 11 printed digits round the reference to ≤ 6e-12; 1e-9 leaves room for last-bit
            // differences in the summation order amplified along the orbit (observed ≤ 4e-12),
            // while the run's own error, hence any change of steps or interpolant, is ~1e-7.
            let tol = 1e-9;
            assert!(
                (out[0] - y1).abs() < tol && (out[1] - y2).abs() < tol,
                "x = {x}: got ({:.10e}, {:.10e}), Hairer ({y1:.10e}, {y2:.10e})",
                out[0],
                out[1]
            );
            next += 1;
        }
    }
    assert_eq!(
        next,
        REF.len(),
        "every output point was inside some accepted step"
    );
}

#[test]
fn arenstorf_final_state_matches_hairer() {
    let mut sys = Arenstorf::new(false);
    let y0 = sys.y0();
    let (d, _) = run(&mut sys, arenstorf_options(), &y0, ARENSTORF_T_END);
    let y = d.state();
    // Printed as 0.9940021016E+00: 10 significant digits round to 5e-11; 1e-10 adds the round-off
    // spread of y2 below, while a 0.1 % change of rtol alone moves y1 by 5e-9.
    assert!((y[0] - 0.994_002_101_6).abs() < 1e-10, "y1 = {:.12e}", y[0]);
    // Printed as 0.8911185692E-05, and as 0.8911185056E-05 by another published run of the same
    // code: round-off amplified along the orbit spreads y2 by 6.4e-13. 1e-12 covers that spread,
    // while a 0.1 % change of rtol alone moves y2 by 1.6e-8.
    assert!(
        (y[1] - 0.891_118_569_2e-5).abs() < 1e-12,
        "y2 = {:.12e}",
        y[1]
    );
}

// ---------------------------------------------------------------------------------------------
// Order of accuracy with fixed steps
// ---------------------------------------------------------------------------------------------

/// Fixed step h: every error test passes at tolerance 1 and the step never grows past max_step.
fn fixed(h: f64) -> Dopri5Options {
    Dopri5Options {
        rtol: 1.0,
        atol: 1.0,
        initial_step: Some(h),
        max_step: Some(h),
        ..Dopri5Options::default()
    }
}

/// Error at t = 1 and max dense-output error at step mid-points, with n fixed steps.
fn fixed_step_errors<S: OdeSystem>(
    sys: &mut S,
    y0: &[f64],
    exact: impl Fn(f64) -> Vec<f64>,
    n: u32,
) -> (f64, f64) {
    let h = 1.0 / f64::from(n);
    let mut d = Dopri5::new(y0.len(), fixed(h));
    d.start(sys, 0.0, y0, 1.0).unwrap();
    let mut out = vec![0.0; y0.len()];
    let mut dense_err: f64 = 0.0;
    while d.time() < 1.0 {
        d.step(sys, 1.0).unwrap();
        let tm = 0.5 * (d.previous_time() + d.time());
        d.dense_output(tm, &mut out);
        for (a, b) in out.iter().zip(exact(tm)) {
            dense_err = dense_err.max((a - b).abs());
        }
    }
    let s = d.stats();
    assert_eq!(s.steps_rejected, 0, "fixed-step run rejected a step");
    assert_eq!(
        s.steps_accepted,
        u64::from(n),
        "fixed-step run used other steps"
    );
    let end_err = d
        .state()
        .iter()
        .zip(exact(1.0))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    (end_err, dense_err)
}

fn assert_orders<S: OdeSystem>(
    name: &str,
    mut make: impl FnMut() -> S,
    y0: &[f64],
    exact: impl Fn(f64) -> Vec<f64> + Copy,
) {
    // h = 1/8 and 1/16: errors ~1e-9..1e-11, far above round-off, in the asymptotic regime.
    let (e1, d1) = fixed_step_errors(&mut make(), y0, exact, 8);
    let (e2, d2) = fixed_step_errors(&mut make(), y0, exact, 16);
    let p = (e1 / e2).log2();
    let q = (d1 / d2).log2();
    // Order 5: log2 ratio 5 up to the O(h) contribution of the next error term (±0.3).
    assert!(
        (4.7..=5.3).contains(&p),
        "{name}: step order {p:.3} (errors {e1:e}, {e2:e})"
    );
    // Shampine's dense output is of order 4: its local error O(h^5) gives at least 4 (−0.3 slack).
    assert!(
        q >= 3.7,
        "{name}: dense-output order {q:.3} (errors {d1:e}, {d2:e})"
    );
}

#[test]
fn fifth_order_steps_and_fourth_order_dense_output_decay() {
    assert_orders(
        "y' = -y",
        || Decay { lambda: -1.0 },
        &[1.0],
        |t| vec![(-t).exp()],
    );
}

#[test]
fn fifth_order_steps_and_fourth_order_dense_output_oscillator() {
    assert_orders(
        "oscillator",
        || Rotation { omega: 1.0 },
        &[1.0, 0.0],
        |t| vec![t.cos(), -t.sin()],
    );
}

/// y' = cos(t) y: the right-hand side depends on t, so the stage times c_i h enter (an
/// autonomous problem never sees them); y = e^{sin t} for y(0) = 1 (a fixed-step DOPRI5 written
/// from the tableau shows orders 5.16, 5.10, 5.05 for h = 1/8 … 1/64; y' = t y was rejected as a
/// check: its error constant nearly cancels, orders 4.68, 4.05, 4.68). A wrong stage time
/// (c_5 = 8 for 8/9, t − c_4 h) leaves first order.
struct Forced;

impl OdeSystem for Forced {
    fn dimension(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = t.cos() * y[0];
    }
}

#[test]
fn fifth_order_steps_and_fourth_order_dense_output_time_dependent() {
    assert_orders("y' = cos(t) y", || Forced, &[1.0], |t| vec![t.sin().exp()]);
}

// ---------------------------------------------------------------------------------------------
// Tolerance proportionality
// ---------------------------------------------------------------------------------------------

fn tight() -> Dopri5Options {
    Dopri5Options {
        rtol: 1e-8,
        atol: 1e-10,
        ..Dopri5Options::default()
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        // Integration tests have no lib.rs next to them for proptest's regression files.
        failure_persistence: None,
        ..ProptestConfig::with_cases(20)
    })]

    #[test]
    fn decay_global_error_is_proportional_to_rtol(lambda in -5.0f64..-0.1) {
        let (d, _) = run(&mut Decay { lambda }, tight(), &[1.0], 2.0);
        let err = (d.state()[0] - (2.0 * lambda).exp()).abs();
        // max|y| = 1; on a contracting problem the local-error controller keeps the global error
        // within a few rtol (observed < 2 rtol): 100 rtol leaves margin yet fails at 1e-6.
        prop_assert!(err < 100.0 * 1e-8, "λ = {lambda}: error {err:e}");
    }

    #[test]
    fn rotation_global_error_is_proportional_to_rtol(omega in 0.5f64..10.0) {
        let (d, _) = run(&mut Rotation { omega }, tight(), &[1.0, 0.0], 2.0);
        let y = d.state();
        let err = (y[0] - (2.0 * omega).cos()).abs().max((y[1] + (2.0 * omega).sin()).abs());
        // max|y| = 1; ~3 periods of linear error growth (observed < 2 rtol) stay inside 100 rtol.
        prop_assert!(err < 100.0 * 1e-8, "ω = {omega}: error {err:e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Norm exclusion
// ---------------------------------------------------------------------------------------------

#[test]
fn components_outside_the_norm_do_not_steer_the_steps() {
    let mut plain = Arenstorf::new(false);
    let y0 = plain.y0();
    let (a, ta) = run(&mut plain, arenstorf_options(), &y0, ARENSTORF_T_END);

    let mut wild = Arenstorf::new(true);
    let y0w = wild.y0();
    let opts = Dopri5Options {
        norm_components: Some(4),
        ..arenstorf_options()
    };
    let (b, tb) = run(&mut wild, opts, &y0w, ARENSTORF_T_END);
    assert_eq!(a.stats(), b.stats());
    assert_eq!(ta, tb, "same accepted step times");
    assert_eq!(a.state(), &b.state()[..4]);

    // The extra component does steer the steps when it is in the norm: over the first 1e-3 s
    // (a handful of steps when excluded) it forces steps of order 1e-6.
    let t_short = 1e-3;
    let (excl, _) = run(&mut Arenstorf::new(true), opts, &y0w, t_short);
    let (incl, _) = run(
        &mut Arenstorf::new(true),
        arenstorf_options(),
        &y0w,
        t_short,
    );
    assert!(
        incl.stats().steps_accepted > 100 * excl.stats().steps_accepted,
        "included: {:?}, excluded: {:?}",
        incl.stats(),
        excl.stats()
    );
}

// ---------------------------------------------------------------------------------------------
// Failure modes: errors, never panics or hangs
// ---------------------------------------------------------------------------------------------

#[test]
fn blow_up_at_t_1_is_a_step_size_error_near_1() {
    // y' = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
    let mut sys = Closure {
        n: 1,
        f: |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0] * y[0],
        calls: 0,
        limit: 10_000_000,
    };
    let mut d = Dopri5::new(1, Dopri5Options::default());
    d.start(&mut sys, 0.0, &[1.0], 2.0).unwrap();
    let err = loop {
        match d.step(&mut sys, 2.0) {
            Ok(()) => assert!(
                d.time() < 1.001,
                "stepped across the singularity to {}",
                d.time()
            ),
            Err(e) => break e,
        }
    };
    let t = match err {
        IntegratorError::StepSizeUnderflow { t, .. } | IntegratorError::NonFinite { t, .. } => t,
        other => panic!("unexpected error {other:?}"),
    };
    // The computed solution is 1/(t* − t) with its own singularity t* shifted from 1 by the
    // global error (≈ 2e-6 at the default rtol 1e-5, either side of 1): allow 1e-3 = 100 rtol.
    assert!((t - 1.0).abs() <= 1e-3, "stopped at t = {t}");
    // It stopped because the solution exploded, not for an unrelated reason: y ≫ 1/1e-3.
    assert!(d.state()[0] > 1e6, "y = {} at the stop", d.state()[0]);
    assert!(
        err.to_string().contains("step size underflow") || err.to_string().contains("non-finite")
    );
}

#[test]
fn nan_right_hand_side_is_an_error_before_the_nan_region() {
    let mut sys = Closure {
        n: 1,
        f: |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = if t > 0.5 { f64::NAN } else { -y[0] },
        calls: 0,
        limit: 10_000_000,
    };
    let mut d = Dopri5::new(1, Dopri5Options::default());
    d.start(&mut sys, 0.0, &[1.0], 2.0).unwrap();
    let err = loop {
        if let Err(e) = d.step(&mut sys, 2.0) {
            break e;
        }
        assert!(
            d.state()[0].is_finite(),
            "accepted a non-finite state at {}",
            d.time()
        );
    };
    let t = match err {
        IntegratorError::StepSizeUnderflow { t, .. } | IntegratorError::NonFinite { t, .. } => t,
        other => panic!("unexpected error {other:?}"),
    };
    // No accepted step may use a stage past 0.5; 1e-9 absorbs the stage-time arithmetic. And it
    // gets there: stopping before 0.4 would be a failure of a well-behaved region.
    assert!(t <= 0.5 + 1e-9 && t > 0.4, "stopped at t = {t}");
}

#[test]
fn misuse_is_a_usage_error() {
    let mut sys = Decay { lambda: -1.0 };
    let mut d = Dopri5::new(1, Dopri5Options::default());
    assert!(matches!(
        d.step(&mut sys, 1.0),
        Err(IntegratorError::Usage(_))
    ));
    let mut d2 = Dopri5::new(2, Dopri5Options::default());
    assert!(matches!(
        d2.start(&mut sys, 0.0, &[1.0, 2.0], 1.0),
        Err(IntegratorError::Usage(_))
    ));
    assert!(matches!(
        d.start(&mut sys, 1.0, &[1.0], 1.0),
        Err(IntegratorError::Usage(_))
    ));
    d.start(&mut sys, 0.0, &[1.0], 1.0).unwrap();
    while d.time() < 1.0 {
        d.step(&mut sys, 1.0).unwrap();
    }
    assert!(matches!(
        d.step(&mut sys, 1.0),
        Err(IntegratorError::Usage(_))
    ));
}

// ---------------------------------------------------------------------------------------------
// restart()
// ---------------------------------------------------------------------------------------------

#[test]
fn restart_counts_one_evaluation_and_continues_from_the_new_state() {
    let mut sys = Decay { lambda: -1.0 };
    let opts = Dopri5Options {
        rtol: 1e-10,
        atol: 1e-12,
        ..Dopri5Options::default()
    };
    let mut d = Dopri5::new(1, opts);
    d.start(&mut sys, 0.0, &[1.0], 2.0).unwrap();
    while d.time() < 0.5 {
        d.step(&mut sys, 2.0).unwrap();
    }
    // Restart inside the last accepted step, as a located model event does.
    let t_r = 0.5 * (d.previous_time() + d.time());
    let h_last = d.time() - d.previous_time();
    let before = d.stats();
    d.restart(&mut sys, t_r, &[3.0]);
    let after = d.stats();
    assert_eq!(after.rhs_evals, before.rhs_evals + 1);
    assert_eq!(after.restarts, before.restarts + 1);
    assert_eq!(after.steps_attempted, before.steps_attempted);
    assert_eq!(d.time(), t_r);
    assert_eq!(d.state(), &[3.0]);
    assert_eq!(
        d.derivative(),
        &[-3.0],
        "derivative re-evaluated at the new state"
    );
    // MODELS.md §6: the step size of the last accepted step (1e-12: t − t_old round-off).
    assert!((d.step_size() - h_last).abs() <= 1e-12 * h_last.max(1.0));
    let mut out = [0.0];
    d.dense_output(t_r, &mut out);
    assert_eq!(
        out,
        [3.0],
        "dense output at the restart time is the new state"
    );

    while d.time() < 2.0 {
        d.step(&mut sys, 2.0).unwrap();
    }
    let exact = 3.0 * (-(2.0 - t_r)).exp();
    // rtol 1e-10 on a contracting problem: global error within 100 × rtol × max|y| (= 3).
    assert!((d.state()[0] - exact).abs() < 100.0 * 1e-10 * 3.0);
}

/// The `Stepper` view (what the runner's event location uses) reports DOPRI5's own times.
#[test]
fn stepper_view_reports_the_step() {
    fn times<S: OdeSystem, T: Stepper<S>>(t: &T) -> (f64, f64) {
        (t.time(), t.previous_time())
    }
    let mut sys = Decay { lambda: -1.0 };
    let mut d = Dopri5::new(1, fixed(0.125));
    d.start(&mut sys, 0.0, &[1.0], 1.0).unwrap();
    d.step(&mut sys, 1.0).unwrap();
    d.step(&mut sys, 1.0).unwrap();
    assert_eq!(times::<Decay, _>(&d), (0.25, 0.125));
    assert_eq!((d.time(), d.previous_time()), (0.25, 0.125));
}
