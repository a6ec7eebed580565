//! The `step5` trajectory, the PID with derivative filter and the tension distribution
//! (MODELS.md §2) against their defining formulas: sampled extremes and finite differences for the
//! quintic, the closed-form step and ramp responses of C(s) = P + I/s + D N_f s/(s + N_f) for the
//! PID integrated as an ODE, and the two identities of Pott's distribution.

use cdpr_core::controller::{Pid, PidState, TensionDistribution};
use cdpr_core::scenario;
use cdpr_core::trajectory::Step5;
use cdpr_numerics::{Dopri5, Dopri5Options, OdeSystem};
use proptest::prelude::*;

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        // Integration tests have no lib.rs next to them for proptest's regression files.
        failure_persistence: None,
        ..ProptestConfig::with_cases(cases)
    }
}

/// Random step5 within MODELS.md §9's workspace: x1, x2 in [0.05, 0.95], t1 in [0, 1],
/// t2 − t1 in [0.01, 2].
fn any_step5() -> impl Strategy<Value = Step5> {
    (0.05f64..0.95, 0.05f64..0.95, 0.0f64..1.0, 0.01f64..2.0).prop_map(|(x1, x2, t1, span)| Step5 {
        x1,
        x2,
        t1,
        t2: t1 + span,
    })
}

/// Sample times t1 + (t2 − t1) k / 10000, k = 0 … 10000.
fn grid(s: &Step5) -> impl Iterator<Item = f64> + '_ {
    (0..=10_000).map(move |k| s.t1 + (s.t2 - s.t1) * f64::from(k) / 10_000.0)
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn step5_ends_are_exact_and_at_rest(s in any_step5(), before in 1e-9f64..5.0, after in 1e-9f64..5.0) {
        // The end points are the defining data: no round-off is acceptable (1e-15 is a few ulps).
        prop_assert!((s.position(s.t1) - s.x1).abs() <= 1e-15, "x(t1) = {}", s.position(s.t1));
        prop_assert!((s.position(s.t2) - s.x2).abs() <= 1e-15, "x(t2) = {}", s.position(s.t2));
        let span = s.t2 - s.t1;
        let v_scale = (s.x2 - s.x1).abs() / span;
        let a_scale = v_scale / span;
        for t in [s.t1, s.t2] {
            // Zero velocity and acceleration: 1e-12 of their natural scales Δx/T and Δx/T².
            prop_assert!(s.velocity(t).abs() <= 1e-12 * v_scale, "v({t}) = {}", s.velocity(t));
            prop_assert!(s.acceleration(t).abs() <= 1e-12 * a_scale, "a({t}) = {}", s.acceleration(t));
        }
        // Constant outside [t1, t2].
        for (t, x) in [(s.t1 - before, s.x1), (s.t2 + after, s.x2)] {
            prop_assert_eq!(s.position(t), x);
            prop_assert_eq!(s.velocity(t), 0.0);
            prop_assert_eq!(s.acceleration(t), 0.0);
        }
    }
}

proptest! {
    #![proptest_config(config(48))]

    #[test]
    fn step5_max_speed_is_the_sampled_maximum_at_the_midpoint(s in any_step5()) {
        let sampled = grid(&s).map(|t| s.velocity(t).abs()).fold(0.0, f64::max);
        let vmax = s.max_speed();
        // The midpoint is a grid point (k = 5000): only rounding separates the two, 1e-6 is loose.
        prop_assert!((sampled - vmax).abs() <= 1e-6 * vmax, "sampled {sampled}, max_speed {vmax}");
        // No sample exceeds the maximum (1e-12: rounding of the formulas).
        prop_assert!(sampled <= vmax * (1.0 + 1e-12));
        let mid = 0.5 * (s.t1 + s.t2);
        // Attained at the midpoint, up to rounding (1e-12 relative).
        prop_assert!((s.velocity(mid).abs() - vmax).abs() <= 1e-12 * vmax);
        // The speed has the sign of Δx.
        prop_assert!(s.velocity(mid) * (s.x2 - s.x1) >= 0.0);
    }

    #[test]
    fn step5_max_acceleration_is_the_sampled_maximum(s in any_step5()) {
        let sampled = grid(&s).map(|t| s.acceleration(t).abs()).fold(0.0, f64::max);
        let amax = s.max_acceleration();
        // The grid (Δ spacing 1e-4) misses the extreme by ≤ 5e-5 in Δ; the quadratic drop there
        // is ≤ 5e-8 relative, so 1e-6 holds with margin.
        prop_assert!((sampled - amax).abs() <= 1e-6 * amax, "sampled {sampled}, max {amax}");
        // No sample exceeds the maximum (1e-12: rounding of the formulas).
        prop_assert!(sampled <= amax * (1.0 + 1e-12));
        let [ta, tb] = s.max_acceleration_times();
        prop_assert!(s.t1 < ta && ta < tb && tb < s.t2);
        let sign = (s.x2 - s.x1).signum();
        // ±max at the two times: rounding of √3 and of the polynomial, 1e-9 relative.
        prop_assert!((s.acceleration(ta) - sign * amax).abs() <= 1e-9 * amax, "a(ta) = {}", s.acceleration(ta));
        prop_assert!((s.acceleration(tb) + sign * amax).abs() <= 1e-9 * amax, "a(tb) = {}", s.acceleration(tb));
    }

    #[test]
    fn step5_derivatives_are_consistent(s in any_step5()) {
        let span = s.t2 - s.t1;
        let eta = 1e-5 * span;
        for k in 1..100 {
            let t = s.t1 + span * f64::from(k) / 100.0;
            let dx = (s.position(t + eta) - s.position(t - eta)) / (2.0 * eta);
            // Truncation η²/6·max|x'''| ≈ 5e-10 max_speed, plus the round-off of positions
            // (|x| < 1: a few ulps, 1e-15) divided by 2η.
            let tol_v = 1e-6 * s.max_speed() + 1e-15 / eta;
            prop_assert!((dx - s.velocity(t)).abs() <= tol_v, "t = {t}: fd {dx}, v {}", s.velocity(t));
            let dv = (s.velocity(t + eta) - s.velocity(t - eta)) / (2.0 * eta);
            // Truncation η²/6·max|x''''| ≈ 1e-9 max_acceleration; velocities scale with Δx, so
            // their round-off (≈ 1e-11 max_acceleration) is relative too.
            let tol_a = 1e-6 * s.max_acceleration();
            prop_assert!((dv - s.acceleration(t)).abs() <= tol_a, "t = {t}: fd {dv}, a {}", s.acceleration(t));
        }
    }
}

#[test]
fn paper_scenario_maps_to_the_paper_values() {
    // MODELS.md §2: x1 = 0.5, x2 = 0.6, t1 = 0, t2 = 0.2; P = 1860, I = 8700, D = 100, N_f = 540.
    let s = Step5::from(&scenario::Trajectory::default());
    assert_eq!(
        s,
        Step5 {
            x1: 0.5,
            x2: 0.6,
            t1: 0.0,
            t2: 0.2
        }
    );
    let c = scenario::Controller::default();
    assert_eq!(
        Pid::from(&c),
        Pid {
            p: 1860.0,
            i: 8700.0,
            d: 100.0,
            filter: 540.0
        }
    );
    let td = TensionDistribution::from(&c);
    assert_eq!(td.tension_sum, 200.0);
    assert_eq!(td.tensions(0.0), [100.0, 100.0]);
    // Saturation is off by default: a force beyond ΣT gives a negative (slack) command.
    assert_eq!(td.tensions(300.0), [-50.0, 250.0]);
}

// ---------------------------------------------------------------------------------------------
// PID: step and ramp responses of the transfer function
// ---------------------------------------------------------------------------------------------

/// The PID states integrated as an ODE for a prescribed error e(t) (1 or t).
struct PidOde {
    pid: Pid,
    ramp: bool,
}

impl PidOde {
    fn error(&self, t: f64) -> f64 {
        if self.ramp { t } else { 1.0 }
    }
}

impl OdeSystem for PidOde {
    fn dimension(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let rate = self.pid.state_rate(
            self.error(t),
            PidState {
                integral: y[0],
                filter: y[1],
            },
        );
        dy[0] = rate.integral;
        dy[1] = rate.filter;
    }
}

/// F(t) from zero state, integrating the PID ODE to exactly t.
fn pid_force(pid: Pid, ramp: bool, t: f64) -> f64 {
    let mut sys = PidOde { pid, ramp };
    let mut y = [0.0, 0.0];
    if t > 0.0 {
        let opts = Dopri5Options {
            rtol: 1e-12,
            atol: 1e-14,
            ..Dopri5Options::default()
        };
        let mut d = Dopri5::new(2, opts);
        d.start(&mut sys, 0.0, &y, t).unwrap();
        while d.time() < t {
            d.step(&mut sys, t).unwrap();
        }
        y.copy_from_slice(d.state());
    }
    pid.force(
        sys.error(t),
        PidState {
            integral: y[0],
            filter: y[1],
        },
    )
}

const PID_TIMES: [f64; 7] = [0.0, 1e-4, 1e-3, 4e-3, 1e-2, 2.5e-2, 5e-2];

proptest! {
    #![proptest_config(config(48))]

    #[test]
    fn pid_matches_its_transfer_function(
        p in 0.0f64..5000.0,
        i in 0.0f64..5000.0,
        d in 0.0f64..5000.0,
        nf in 10.0f64..1000.0,
    ) {
        let pid = Pid { p, i, d, filter: nf };
        for t in PID_TIMES {
            // Inverse Laplace transforms of C(s)/s and C(s)/s².
            let step = p + i * t + d * nf * (-nf * t).exp();
            let ramp = p * t + i * t * t / 2.0 - d * (-nf * t).exp_m1();
            for (is_ramp, exact) in [(false, step), (true, ramp)] {
                let e = if is_ramp { t } else { 1.0 };
                let f = pid_force(pid, is_ramp, t);
                // 1e-8 relative to max(|F|, 1) for the smooth terms; plus the cancellation in
                // D N_f (e − f): f carries ≲ 100 × rtol (1e-12) relative integration error.
                let tol = 1e-8 * exact.abs().max(1.0) + 1e-10 * d * nf * e;
                prop_assert!(
                    (f - exact).abs() <= tol,
                    "{} t = {t}: F = {f}, closed form {exact}",
                    if is_ramp { "ramp" } else { "step" }
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn state_holding_holds_the_force_at_rest(
        p in 0.0f64..5000.0,
        i in 1e-3f64..5000.0,
        d in 0.0f64..5000.0,
        nf in 10.0f64..1000.0,
        f0 in -1e4f64..1e4,
    ) {
        let pid = Pid { p, i, d, filter: nf };
        let s = pid.state_holding(f0).unwrap();
        // I·(F0/I): two roundings, 1e-12 relative is generous.
        prop_assert!((pid.force(0.0, s) - f0).abs() <= 1e-12 * f0.abs(), "F = {}", pid.force(0.0, s));
        // At rest: zero error keeps the state where it is.
        prop_assert_eq!(pid.state_rate(0.0, s), PidState::default());
        prop_assert_eq!(s.filter, 0.0);

        let no_integral = Pid { i: 0.0, ..pid };
        if f0 != 0.0 {
            prop_assert_eq!(no_integral.state_holding(f0), None);
        }
        prop_assert_eq!(no_integral.state_holding(0.0), Some(PidState::default()));
    }

    #[test]
    fn tension_distribution_identities(sum in 1.0f64..1e4, force_frac in -3.0f64..3.0) {
        let force = force_frac * sum;
        let td = TensionDistribution { tension_sum: sum, t_min: f64::NEG_INFINITY, t_max: f64::INFINITY };
        let [t1, t2] = td.tensions(force);
        let scale = sum.abs().max(force.abs());
        // Two halvings and one addition: 1e-12 relative is far above their rounding.
        prop_assert!((t1 + t2 - sum).abs() <= 1e-12 * scale, "T1 + T2 = {}", t1 + t2);
        prop_assert!((t2 - t1 - force).abs() <= 1e-12 * scale, "T2 − T1 = {}", t2 - t1);
        // F > 0 pulls toward A2: cable 2 carries more.
        prop_assert!((t2 - t1) * force >= 0.0);
    }

    #[test]
    fn tension_saturation_bounds(
        sum in 1.0f64..1e4,
        force_frac in -3.0f64..3.0,
        lo_frac in 0.0f64..1.0,
        width_frac in 1e-3f64..2.0,
    ) {
        let force = force_frac * sum;
        let t_min = lo_frac * sum;
        let t_max = t_min + width_frac * sum;
        let td = TensionDistribution { tension_sum: sum, t_min, t_max };
        let free = TensionDistribution { t_min: f64::NEG_INFINITY, t_max: f64::INFINITY, ..td };
        let sat = td.tensions(force);
        let unsat = free.tensions(force);
        for k in 0..2 {
            prop_assert!(t_min <= sat[k] && sat[k] <= t_max, "T{} = {} outside [{t_min}, {t_max}]", k + 1, sat[k]);
            // Inside the band saturation changes nothing; outside it clips to the nearer bound.
            let expected = if unsat[k] < t_min { t_min } else if unsat[k] > t_max { t_max } else { unsat[k] };
            prop_assert_eq!(sat[k], expected);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The implicit path's PID update (MODELS.md FE.9.3) is the trapezoidal rule of the PID's own
    /// state equations: w_{n+1} − w_n = h (e_n + e_{n+1})/2 and f_{n+1} − f_n = h (f'_n + f'_{n+1})/2
    /// with f' = N_f (e − f) from `state_rate`, to round-off (1e-12 of the terms), for any step,
    /// stiff (h N_f up to 1e3) or not.
    #[test]
    fn trapezoidal_step_is_the_trapezoidal_rule_of_the_state_equations(
        nf in 1.0f64..1e4,
        h in 1e-6f64..0.1,
        w0 in -1.0f64..1.0,
        f0 in -1e-2f64..1e-2,
        e0 in -1e-2f64..1e-2,
        e1 in -1e-2f64..1e-2,
    ) {
        let pid = Pid { p: 1.0, i: 1.0, d: 1.0, filter: nf };
        let start = PidState { integral: w0, filter: f0 };
        let end = pid.trapezoidal_step(start, e0, e1, h);
        let (r0, r1) = (pid.state_rate(e0, start), pid.state_rate(e1, end));
        let scale = h * (e0.abs() + e1.abs()) + 1e-300;
        prop_assert!((end.integral - w0 - 0.5 * h * (r0.integral + r1.integral)).abs() <= 1e-12 * (w0.abs() + scale));
        let filter_terms = f0.abs() + 0.5 * h * (r0.filter.abs() + r1.filter.abs()) + 1e-300;
        prop_assert!(
            (end.filter - f0 - 0.5 * h * (r0.filter + r1.filter)).abs() <= 1e-12 * filter_terms,
            "f: {} − {} vs h/2 ({} + {})", end.filter, f0, r0.filter, r1.filter
        );
    }
}

/// Second order, A-stable: for a ramp error e = a + b t the filter state f' = N_f (e − f) has
/// the closed form f = e − b/N_f + (f0 − a + b/N_f) e^(−N_f t); n trapezoidal steps to T = 5 ms
/// (N_f T = 2.7, while the transient still dominates) err by O(h²), so halving h divides the
/// error by 4 (3.8–4.2, the next term's share); the
/// integral is exact for a linear error (1e-14). With h N_f = 1e3 the filter state stays
/// bounded by its start and the error (no growth of a stiff pole).
#[test]
fn trapezoidal_step_is_second_order_and_a_stable() {
    let nf = 540.0;
    let pid = Pid {
        p: 1.0,
        i: 1.0,
        d: 1.0,
        filter: nf,
    };
    let (a, b, f0, t_end) = (1e-3, 0.05, -2e-3, 5e-3);
    let error = |t: f64| a + b * t;
    let exact = error(t_end) - b / nf + (f0 - a + b / nf) * (-nf * t_end).exp();
    let run = |steps: usize| {
        let h = t_end / steps as f64;
        let mut s = PidState {
            integral: 0.0,
            filter: f0,
        };
        for k in 0..steps {
            s = pid.trapezoidal_step(s, error(k as f64 * h), error((k + 1) as f64 * h), h);
        }
        s
    };
    let (coarse, fine) = (run(20), run(40));
    let ratio = (coarse.filter - exact).abs() / (fine.filter - exact).abs();
    assert!((3.8..4.2).contains(&ratio), "error ratio {ratio}");
    let integral = a * t_end + 0.5 * b * t_end * t_end;
    assert!(
        (fine.integral - integral).abs() < 1e-14,
        "{}",
        fine.integral
    );
    let mut s = PidState {
        integral: 0.0,
        filter: 1.0,
    };
    for _ in 0..100 {
        s = pid.trapezoidal_step(s, 0.5, 0.5, 1e3 / nf);
        assert!(
            s.filter.abs() <= 1.0 + 1e-12,
            "stiff step grew: {}",
            s.filter
        );
    }
}
