//! The acceptance table of MODELS.md §8: for each of the paper's results, the paper's value, ours,
//! the accepted range and pass/fail. The bounds are MODELS.md's, not ours; they apply to the
//! paper's scenario.

use cdpr_bench::ModelKind;
use cdpr_bench::analysis::metrics::Metrics;
use cdpr_bench::core::scenario::{IntegratorKind, Scenario};

/// Lowest closed-loop axial mode of the paper's lumped model, MODELS.md §4 [rad/s].
pub const LUMPED_AXIAL_MODE: f64 = 5649.0;

/// One row of the table.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Check {
    /// What is compared.
    pub quantity: String,
    /// Model name, or "all" for rows about the scenario or several models.
    pub model: String,
    /// The paper's statement.
    pub paper: String,
    /// Our value, formatted.
    pub ours: String,
    /// The accepted range (MODELS.md §8).
    pub accept: String,
    pub pass: bool,
}

/// What §8 needs to know about one model's paper run.
#[derive(Debug, Clone, Copy)]
pub struct ModelResult<'a> {
    pub kind: ModelKind,
    pub metrics: &'a Metrics,
    /// Closed-loop vertical eigenfrequency at the x2 equilibrium [rad/s].
    pub vertical_mode: f64,
    /// The lowest closed-loop axial mode (lumped, ≈ 5649 rad/s) as the run's integrator renders it
    /// [rad/s]: generalised-α shifts it (period elongation), DOPRI5 does not.
    pub axial_mode: f64,
    /// The integrator of the run (names the axial mode's image in the table).
    pub integrator: IntegratorKind,
}

impl<'a> ModelResult<'a> {
    /// The view of an assessed run; `axial_mode` is the lowest closed-loop axial mode of the
    /// lumped model as the run's integrator renders it
    /// ([`cdpr_bench::mode_as_integrated`] of [`LUMPED_AXIAL_MODE`]).
    pub fn of(outcome: &'a cdpr_bench::Assessed, axial_mode: f64) -> Self {
        Self {
            kind: outcome.kind,
            metrics: &outcome.metrics,
            // Without the end's modal analysis the rows that compare with it fail.
            vertical_mode: outcome.end.state().map_or(f64::NAN, |end| end.mode.omega),
            axial_mode,
            integrator: outcome.integrator,
        }
    }
}

/// The view of `outcome`, a run of `scenario`, that the table takes.
pub fn result<'a>(outcome: &'a cdpr_bench::Assessed, scenario: &Scenario) -> ModelResult<'a> {
    ModelResult::of(
        outcome,
        cdpr_bench::mode_as_integrated(scenario, LUMPED_AXIAL_MODE),
    )
}

/// A unit of the table, with the factor from SI to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    Newton,
    Metre,
    Millimetre,
    RadPerSecond,
}

impl Unit {
    fn symbol(self) -> &'static str {
        match self {
            Unit::Newton => "N",
            Unit::Metre => "m",
            Unit::Millimetre => "mm",
            Unit::RadPerSecond => "rad/s",
        }
    }

    /// How many of this unit make one SI unit.
    fn per_si(self) -> f64 {
        match self {
            Unit::Millimetre => 1e3,
            _ => 1.0,
        }
    }
}

/// An accepted range of MODELS.md §8: one value that both decides pass or fail
/// ([`Bound::accepts`], on SI values) and prints the table's "accept" column ([`Display`]).
/// Limits are held in the unit they are printed in.
#[derive(Debug, Clone, PartialEq)]
pub enum Bound {
    /// lo ≤ v ≤ hi.
    Between { lo: f64, hi: f64, unit: Unit },
    /// |v − target| ≤ tolerance.
    Around {
        target: f64,
        tolerance: f64,
        unit: Unit,
    },
    /// v < limit.
    Below { limit: f64, unit: Unit },
    /// |v − reference| ≤ tolerance, the reference a value of the run named `of`.
    Near {
        reference: f64,
        tolerance: f64,
        of: &'static str,
    },
    /// |v / reference − 1| ≤ percent / 100.
    Relative {
        reference: f64,
        percent: f64,
        of: &'static str,
    },
    /// Both bounds.
    Both(Box<Bound>, Box<Bound>),
    /// Any finite value: the row is reported, not judged.
    Reported,
}

impl Bound {
    /// Whether the SI value `v` lies inside.
    pub fn accepts(&self, v: f64) -> bool {
        match self {
            Bound::Between { lo, hi, unit } => v >= lo / unit.per_si() && v <= hi / unit.per_si(),
            Bound::Around {
                target,
                tolerance,
                unit,
            } => (v - target / unit.per_si()).abs() <= tolerance / unit.per_si(),
            Bound::Below { limit, unit } => v < limit / unit.per_si(),
            Bound::Near {
                reference,
                tolerance,
                ..
            } => (v - reference).abs() <= *tolerance,
            Bound::Relative {
                reference, percent, ..
            } => (v / reference - 1.0).abs() <= percent / 100.0,
            Bound::Both(a, b) => a.accepts(v) && b.accepts(v),
            Bound::Reported => v.is_finite(),
        }
    }
}

impl std::fmt::Display for Bound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Bound::Between { lo, hi, unit } => write!(f, "{lo:?} – {hi:?} {}", unit.symbol()),
            Bound::Around {
                target,
                tolerance,
                unit,
            } => write!(f, "{target:?} ± {tolerance:?} {}", unit.symbol()),
            Bound::Below { limit, unit } => write!(f, "< {limit:e} {}", unit.symbol()),
            Bound::Near { tolerance, of, .. } => write!(f, "within ±{tolerance:?} of {of}"),
            Bound::Relative { percent, of, .. } => write!(f, "within {percent:?} % of {of}"),
            Bound::Both(a, b) => write!(f, "{a} and {b}"),
            Bound::Reported => f.write_str("reported"),
        }
    }
}

fn check(quantity: &str, model: &str, paper: &str, ours: String, accept: &Bound, v: f64) -> Check {
    let pass = accept.accepts(v);
    row(quantity, model, paper, ours, &accept.to_string(), pass)
}

/// A row whose judgement is not one value against a [`Bound`] (its text and its numbers come from
/// the same constants).
fn row(quantity: &str, model: &str, paper: &str, ours: String, accept: &str, pass: bool) -> Check {
    Check {
        quantity: quantity.to_owned(),
        model: model.to_owned(),
        paper: paper.to_owned(),
        ours,
        accept: accept.to_owned(),
        pass,
    }
}

/// The plain FFT's peak of z over the whole record: bin 16 of a 5 s record, 20.106 rad/s.
const FFT_BIN: usize = 16;
const FFT_OMEGA: f64 = 20.106;
const FFT_TOLERANCE: f64 = 0.001;
/// High-frequency rows: peaks above this frequency [rad/s]; the elastic model's largest stays
/// below `ELASTIC_HF_DB`, the lumped one's axial peak lies within `AXIAL_PERCENT` of the axial
/// mode at no less than `AXIAL_DB`.
const HF_ABOVE: f64 = 100.0;
const ELASTIC_HF_DB: f64 = -100.0;
const AXIAL_PERCENT: f64 = 2.0;
const AXIAL_DB: f64 = -40.0;

/// The per-model rows of §8.
pub fn model_checks(r: &ModelResult) -> Vec<Check> {
    let (m, name) = (r.metrics, r.kind.name());
    let mut rows = tension_rows(m, name);
    rows.extend(error_rows(m, name));
    rows.extend(spectrum_rows(r));
    rows.push(high_frequency_row(r));
    rows
}

/// Fig. 8's tensions: the extremes in the move, the settled means and final values.
fn tension_rows(m: &Metrics, name: &str) -> Vec<Check> {
    use Unit::Newton;
    vec![
        check(
            "T1 minimum",
            name,
            "92 N near t ≈ 0.05 s",
            format!("{:.3} N at t = {:.4} s", m.t1_min, m.t1_min_time),
            &Bound::Between {
                lo: 91.0,
                hi: 93.0,
                unit: Newton,
            },
            m.t1_min,
        ),
        check(
            "T1 maximum",
            name,
            "108 N near t ≈ 0.16 s",
            format!("{:.3} N at t = {:.4} s", m.t1_max, m.t1_max_time),
            &Bound::Between {
                lo: 107.0,
                hi: 109.0,
                unit: Newton,
            },
            m.t1_max,
        ),
        check(
            "T1 settled (mean over [4, 5] s)",
            name,
            "99.95 N",
            format!("{:.5} N", m.t1_mean_last_1s),
            &Bound::Around {
                target: 99.95,
                tolerance: 0.01,
                unit: Newton,
            },
            m.t1_mean_last_1s,
        ),
        check(
            "T2 settled (mean over [4, 5] s)",
            name,
            "100.05 N",
            format!("{:.5} N", m.t2_mean_last_1s),
            &Bound::Around {
                target: 100.05,
                tolerance: 0.01,
                unit: Newton,
            },
            m.t2_mean_last_1s,
        ),
        row(
            "T1(5 s), T2(5 s)",
            name,
            "99.95 N, 100.05 N",
            format!("{:.5} N, {:.5} N", m.t1_final, m.t2_final),
            &Bound::Reported.to_string(),
            Bound::Reported.accepts(m.t1_final) && Bound::Reported.accepts(m.t2_final),
        ),
    ]
}

/// Fig. 5–6's error and height: in the transition, the overshoot, settled, z's ripple.
fn error_rows(m: &Metrics, name: &str) -> Vec<Check> {
    use Unit::{Metre, Millimetre};
    vec![
        check(
            "max |error| in the transition [0, 0.2] s",
            name,
            "< 1e-2 m",
            format!("{:.4e} m", m.err_max_transition),
            &Bound::Below {
                limit: 1e-2,
                unit: Metre,
            },
            m.err_max_transition,
        ),
        check(
            "overshoot",
            name,
            "< 1 cm",
            format!("{:.4e} m", m.overshoot),
            &Bound::Below {
                limit: 1e-2,
                unit: Metre,
            },
            m.overshoot,
        ),
        check(
            "max |error| over [1, 5] s",
            name,
            "< 1e-5 m after 1 s",
            format!("{:.4e} m", m.err_max_settled),
            &Bound::Below {
                limit: 2e-5,
                unit: Metre,
            },
            m.err_max_settled,
        ),
        check(
            "max |error| over [1.5, 5] s",
            name,
            "< 1e-5 m after 1 s",
            format!("{:.4e} m", m.err_max_settled_strict),
            &Bound::Below {
                limit: 1e-5,
                unit: Metre,
            },
            m.err_max_settled_strict,
        ),
        check(
            "z peak-to-peak over [1, 5] s",
            name,
            "~1 mm",
            format!("{:.4} mm", m.z_p2p * 1e3),
            &Bound::Between {
                lo: 0.5,
                hi: 2.5,
                unit: Millimetre,
            },
            m.z_p2p,
        ),
    ]
}

/// Fig. 7's spectral peaks: refined (against the closed-loop mode) and the plain FFT bin.
fn spectrum_rows(r: &ModelResult) -> Vec<Check> {
    use Unit::RadPerSecond;
    let (m, name) = (r.metrics, r.kind.name());
    let mut rows = Vec::new();
    let peak_bound = Bound::Both(
        Box::new(Bound::Between {
            lo: 19.8,
            hi: 20.6,
            unit: RadPerSecond,
        }),
        Box::new(Bound::Near {
            reference: r.vertical_mode,
            tolerance: 0.02,
            of: "the closed-loop vertical mode",
        }),
    );
    for (signal, omega) in [
        ("z", m.spectral.z_peak_rad_s),
        ("error", m.spectral.err_peak_rad_s),
    ] {
        rows.push(check(
            &format!("{signal} refined spectral peak over [1, 5] s"),
            name,
            "20.11 rad/s",
            format!("{omega:.4} rad/s (closed-loop mode {:.4})", r.vertical_mode),
            &peak_bound,
            omega,
        ));
    }
    rows.push(row(
        "plain FFT peak of z over [0, 5] s",
        name,
        "20.11 rad/s",
        format!(
            "{:.4} rad/s (bin {})",
            m.spectral.z_fft_record_rad_s, m.spectral.z_fft_record_bin
        ),
        &format!("bin {FFT_BIN}, |ω − {FFT_OMEGA}| < {FFT_TOLERANCE} rad/s"),
        m.spectral.z_fft_record_bin == FFT_BIN
            && (m.spectral.z_fft_record_rad_s - FFT_OMEGA).abs() < FFT_TOLERANCE,
    ));
    rows
}

/// The high-frequency row, which MODELS.md §8 states per model: nothing for the elastic model,
/// the lowest closed-loop axial mode for the lumped one, reported for FE.
fn high_frequency_row(r: &ModelResult) -> Check {
    let (m, name) = (r.metrics, r.kind.name());
    let quantity = "high-frequency content of the error spectrum";
    let hf = format!(
        "{:.1} rad/s at {:.1} dB",
        m.spectral.err_hf_peak_rad_s, m.spectral.err_hf_peak_db
    );
    match r.kind {
        ModelKind::Elastic => row(
            quantity,
            name,
            "none for the elastic model",
            hf,
            &format!(
                "largest local maximum above {HF_ABOVE} rad/s below {} dB",
                minus(ELASTIC_HF_DB)
            ),
            // No local maximum at all (NaN) is "nothing" too.
            m.spectral.err_hf_peak_db.is_nan() || m.spectral.err_hf_peak_db < ELASTIC_HF_DB,
        ),
        ModelKind::Lumped => {
            let axial = m.spectral.err_hf_peaks.iter().find(|[w, db]| {
                (w / r.axial_mode - 1.0).abs() <= AXIAL_PERCENT / 100.0 && *db >= AXIAL_DB
            });
            let target = match r.integrator {
                IntegratorKind::Dopri5 => format!("{LUMPED_AXIAL_MODE} rad/s"),
                IntegratorKind::Implicit => format!(
                    "{:.1} rad/s (the implicit step's image of {LUMPED_AXIAL_MODE} rad/s)",
                    r.axial_mode
                ),
            };
            row(
                quantity,
                name,
                "extra peaks (cable discretisation)",
                match axial {
                    Some([w, db]) => format!("{w:.1} rad/s at {db:.1} dB (largest: {hf})"),
                    None => format!("none near {target} (largest: {hf})"),
                },
                &format!(
                    "a local maximum within ±{AXIAL_PERCENT} % of the lowest closed-loop axial mode, {target}, at ≥ {} dB",
                    minus(AXIAL_DB)
                ),
                axial.is_some(),
            )
        }
        ModelKind::Fe => row(
            quantity,
            name,
            "extra peaks (cable discretisation)",
            hf,
            &Bound::Reported.to_string(),
            true,
        ),
    }
}

/// A negative number with the typographic minus sign the table uses.
fn minus(v: f64) -> String {
    if v < 0.0 {
        format!("−{}", -v)
    } else {
        v.to_string()
    }
}

/// The whole table: each model's rows, then the scenario and cross-model rows.
pub fn table(eq15: f64, results: &[ModelResult]) -> Vec<Check> {
    let mut rows: Vec<Check> = results.iter().flat_map(model_checks).collect();
    rows.extend(scenario_checks(eq15, results));
    rows
}

/// Rows about the scenario and across models (those whose models are present).
pub fn scenario_checks(eq15: f64, results: &[ModelResult]) -> Vec<Check> {
    let mut rows = vec![check(
        "eq. 15 at x = 0.6",
        "all",
        "20.41 rad/s",
        format!("{eq15:.4} rad/s"),
        &Bound::Around {
            target: 20.41,
            tolerance: 0.005,
            unit: Unit::RadPerSecond,
        },
        eq15,
    )];
    let elastic = results.iter().find(|r| r.kind == ModelKind::Elastic);
    if let Some(e) = elastic {
        rows.push(check(
            "closed-loop vertical eigenfrequency at x = 0.6",
            "elastic",
            "close to eq. 15 (20.41 rad/s)",
            format!(
                "{:.4} rad/s ({:+.3} % of eq. 15)",
                e.vertical_mode,
                100.0 * (e.vertical_mode / eq15 - 1.0)
            ),
            &Bound::Relative {
                reference: eq15,
                percent: 0.5,
                of: "eq. 15",
            },
            e.vertical_mode,
        ));
        for r in results.iter().filter(|r| r.kind != ModelKind::Elastic) {
            rows.push(row(
                "mean z over [1, 5] s",
                &format!("elastic vs {}", r.kind.name()),
                "elastic higher than the massive-cable models",
                format!("{:.7} m vs {:.7} m", e.metrics.z_mean, r.metrics.z_mean),
                "elastic > massive",
                e.metrics.z_mean > r.metrics.z_mean,
            ));
            rows.push(row(
                "closed-loop vertical mode",
                &format!("elastic vs {}", r.kind.name()),
                "massive cables lower the vertical mode",
                format!("{:.4} vs {:.4} rad/s", e.vertical_mode, r.vertical_mode),
                "massive < elastic",
                r.vertical_mode < e.vertical_mode,
            ));
        }
    }
    rows
}
