//! The printer's speed–accuracy frontier (`cargo xtask print-study`, a section of REPORT.md):
//! the first layer of the sliced 20 mm cube and cylinder printed by the Hangprinter-like robot
//! at accelerations of 1 000 … 10 000 mm/s², under the reels driven by length as firmware does
//! (flex compensation none or static, and dynamic) and under the tension controllers (computed-torque,
//! LQR), each unshaped and with the best of Klipper's shapers at the frequencies of the loop's
//! least-damped modes at the layer's centre ([`auto_frequencies`]). The answer to "at which
//! acceleration does my print go wrong, and what buys it back" is each configuration's knee:
//! the highest acceleration whose contour error over the printing moves (travel excluded: a
//! travel's error draws nothing) stays within [`GOOD_CONTOUR`].

mod tables;

use crate::repeated_modes::{self, Complex};
use crate::spatial_modes::{SpatialLoop, SpatialMode, SpatialModes, at_pose};
use crate::{Result, pool};
use cdpr_bench::ModelKind;
use cdpr_bench::core::runner::Observer;
use cdpr_bench::core::scenario::{
    AutoWord, ControllerKind, Designed, FirmwareShaper, FlexCompensation, IntegratorKind, Printer,
    Scenario,
};
use cdpr_bench::printing::gcode::MoveKind;
use std::ops::RangeInclusive;

/// The contour error a good first layer keeps [m] (an eighth of the 0.4 mm line width).
pub const GOOD_CONTOUR: f64 = 50e-6;

/// Printing accelerations [mm/s²] (M204's unit, the firmware's).
pub const ACCELERATIONS: [f64; 4] = [1000.0, 3000.0, 6000.0, 10000.0];

/// Klipper's shapers the best is chosen from (its calibration's usual three; ZVD and 2-hump EI
/// won a few setups by < 10 % in a wider run and cost 40 % more prints).
pub const SHAPERS: [FirmwareShaper; 3] =
    [FirmwareShaper::Zv, FirmwareShaper::Mzv, FirmwareShaper::Ei];

/// A controller configuration of the study.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    pub label: &'static str,
    pub controller: ControllerKind,
    pub flex: FlexCompensation,
}

/// Reels by length (flex none, static: as firmware; dynamic: the stretch under the reference's
/// acceleration too), and the tension controllers.
pub const SETUPS: [Setup; 5] = [
    Setup {
        label: "length, flex none",
        controller: ControllerKind::Length,
        flex: FlexCompensation::None,
    },
    Setup {
        label: "length, flex static",
        controller: ControllerKind::Length,
        flex: FlexCompensation::Static,
    },
    Setup {
        label: "length, flex dynamic",
        controller: ControllerKind::Length,
        flex: FlexCompensation::Dynamic,
    },
    Setup {
        label: "computed-torque",
        controller: ControllerKind::ComputedTorque,
        flex: FlexCompensation::Static,
    },
    Setup {
        label: "lqr",
        controller: ControllerKind::Lqr,
        flex: FlexCompensation::Static,
    },
];

/// A part to print: its name, G-code and layers.
#[derive(Debug, Clone)]
pub struct Part {
    pub name: String,
    pub gcode: String,
    pub layers: RangeInclusive<usize>,
}

/// The massive lines the cube is printed on too (implicit path, h = 1e-4 s), at the sizes of
/// the print goals: lumped lines of 20 springs, FE cables of 10 elements.
pub const MASSIVE: [(ModelKind, usize); 2] = [(ModelKind::Lumped, 20), (ModelKind::Fe, 10)];

/// One print of the study.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Row {
    /// The cable model ("elastic", "lumped", "fe").
    pub model: &'static str,
    pub part: String,
    pub setup: &'static str,
    pub accel_mm_s2: f64,
    /// "none" or Klipper's shaper name.
    pub shaper: String,
    /// The shaper's frequencies [Hz] (x, y; z unshaped).
    pub shaper_freq_hz: [f64; 2],
    pub print_time_s: f64,
    /// Over the printing moves (travel excluded) [m].
    pub contour_err_max_printing: f64,
    pub contour_err_rms_printing: f64,
    /// Over every move [m].
    pub contour_err_max: f64,
    pub contour_err_p99: f64,
    pub contour_err_max_external_perimeter: f64,
    pub tracking_err_max: f64,
    pub steps: u64,
    pub rhs_evaluations: u64,
    /// Why the print stopped before its end (its errors then NaN), if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
}

/// The study's prints and the frequencies it shaped at.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PrintStudy {
    pub rows: Vec<Row>,
}

/// Per axis x, y, z: the frequency [Hz] of the loop's least-damped oscillatory mode whose
/// motion can lie mostly along that axis, from the closed-loop modes; where no mode does, the
/// least-damped oscillatory mode.
///
/// A mode lies along axis k when a unit motion in its eigenspace has a k component of at least
/// 1/2. For a simple mode that is |direction_k| ≥ 1/2; a repeated eigenvalue (a controller with
/// equal gains on every axis has three) has directions that are any basis of its eigenspace,
/// so there it is the length of e_k's projection onto their span — a choice the eigen-solver's
/// round-off cannot change.
pub fn auto_frequencies(modes: &SpatialModes) -> [Option<f64>; 3] {
    let closed: Vec<&SpatialMode> = modes
        .modes
        .iter()
        .filter(|m| m.linearisation == SpatialLoop::Closed && m.omega_rad_s > 0.0)
        .collect();
    let mut best: [Option<(f64, f64)>; 3] = [None; 3];
    let mut any: Option<(f64, f64)> = None;
    for m in &closed {
        let zeta = -m.growth / m.growth.hypot(m.omega_rad_s);
        let hz = m.omega_rad_s / (2.0 * std::f64::consts::PI);
        if any.is_none_or(|(z, _)| zeta < z) {
            any = Some((zeta, hz));
        }
        let motions: Vec<[Complex; 3]> = closed
            .iter()
            .filter(|o| same_eigenvalue(o, m))
            .map(|o| o.direction.map(|c| (c, 0.0)))
            .collect();
        let held = repeated_modes::axes_held(&motions);
        for (k, slot) in best.iter_mut().enumerate() {
            let along = held[k];
            if along >= 0.5 && slot.is_none_or(|(z, _)| zeta < z) {
                *slot = Some((zeta, hz));
            }
        }
    }
    best.map(|b| b.or(any).map(|(_, hz)| hz))
}

/// Whether two modes share their eigenvalue ([`repeated_modes::same_eigenvalue`]).
fn same_eigenvalue(a: &SpatialMode, b: &SpatialMode) -> bool {
    repeated_modes::same_eigenvalue((a.growth, a.omega_rad_s), (b.growth, b.omega_rad_s))
}

/// Whether the scenario shapes an axis at an `"auto"` frequency.
pub fn needs_auto(scenario: &Scenario) -> bool {
    scenario.printer.as_ref().is_some_and(|p| {
        p.shaper != FirmwareShaper::None
            && [p.shaper_freq_x, p.shaper_freq_y, p.shaper_freq_z]
                .into_iter()
                .any(|f| matches!(f, Designed::Auto(_)))
    })
}

/// The printing scenario with every `"auto"` shaper frequency resolved at `centre` [m]: the
/// closed loop's modes there ([`auto_frequencies`]); an axis without such a mode is unshaped.
pub fn resolve_auto(scenario: &Scenario, centre: [f64; 3]) -> Result<Scenario> {
    let mut out = scenario.clone();
    let Some(printer) = out.printer.as_mut() else {
        return Ok(out);
    };
    let auto = |f: Designed| matches!(f, Designed::Auto(_));
    if !needs_auto(scenario) {
        return Ok(out);
    }
    let found = auto_frequencies(&at_pose(scenario, centre)?);
    for (k, slot) in [
        &mut printer.shaper_freq_x,
        &mut printer.shaper_freq_y,
        &mut printer.shaper_freq_z,
    ]
    .into_iter()
    .enumerate()
    {
        if auto(*slot) {
            // No mode along the axis: unshaped (0, Klipper's convention).
            *slot = Designed::Value(found[k].unwrap_or(0.0));
        }
    }
    Ok(out)
}

/// The centre of the bounding box of `part`'s printed layers in the robot's frame [m].
pub fn layer_centre(scenario: &Scenario, part: &Part) -> Result<[f64; 3]> {
    let (_, layers, plan) =
        cdpr_bench::plan_layers(scenario, &part.gcode, Some(part.layers.clone()))?;
    let origin = scenario.printer.clone().unwrap_or_default().origin3();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for g in plan.segments.iter().filter(|g| layers.contains(&g.layer)) {
        let length = g.length();
        for k in 0..3 {
            // In the robot's frame, as `PrintPath::segment_ends` places them.
            let a = origin[k] + g.start[k] + g.dir[k] * 0.0;
            let b = origin[k] + g.start[k] + g.dir[k] * length;
            lo[k] = lo[k].min(a).min(b);
            hi[k] = hi[k].max(a).max(b);
        }
    }
    Ok([0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k])))
}

/// One job: a part, a setup, an acceleration, a shaper, a cable model.
struct Job<'a> {
    part: &'a Part,
    setup: Setup,
    accel: f64,
    shaper: FirmwareShaper,
    model: ModelKind,
}

/// Runs the study on `base` (a printing robot's scenario) for `parts`, and the first part on
/// the [`MASSIVE`] lines at the accelerations `massive` [mm/s²] (seconds a print each, where an
/// elastic one takes tens of milliseconds: the report takes the 3 000 mm/s², `cargo
/// xtask print-study` all of [`ACCELERATIONS`]).
pub fn run(base: &Scenario, parts: &[Part], massive: &[f64]) -> Result<PrintStudy> {
    let mut jobs = Vec::new();
    for part in parts {
        for setup in SETUPS {
            for accel in ACCELERATIONS {
                for shaper in std::iter::once(FirmwareShaper::None).chain(SHAPERS) {
                    jobs.push(Job {
                        part,
                        setup,
                        accel,
                        shaper,
                        model: ModelKind::Elastic,
                    });
                }
            }
        }
    }
    // The shaper frequencies per part and setup (the modes depend on the controller).
    let mut resolved = Vec::new();
    for part in parts {
        let centre = layer_centre(base, part)?;
        for setup in SETUPS {
            let mut s = configure(base, setup, ACCELERATIONS[0], FirmwareShaper::Zv);
            s = resolve_auto(&s, centre)?;
            let p = s.printer.as_ref().expect("configured");
            resolved.push((
                (part.name.clone(), setup.label),
                [p.shaper_freq_x, p.shaper_freq_y],
            ));
        }
    }
    let freqs = |job: &Job| {
        resolved
            .iter()
            .find(|(key, _)| key.0 == job.part.name && key.1 == job.setup.label)
            .map(|(_, f)| *f)
            .expect("resolved per part and setup")
    };
    let rows = pool::map(&jobs, |job| print_row(base, job, freqs(job)))?;
    let mut study = PrintStudy {
        rows: rows.into_iter().collect::<Result<_>>()?,
    };
    // The cube on the massive lines, unshaped and with the elastic study's best shaper (the
    // one a builder calibrates on the loop's modes), at the same frequencies.
    let (accelerations, Some(cube)) = (massive, parts.first()) else {
        return Ok(study);
    };
    let mut massive = Vec::new();
    for (model, elements) in MASSIVE {
        let s = massive_variant(base, model, elements)?;
        for setup in SETUPS {
            for &accel in accelerations {
                let best = study
                    .pair(ModelKind::Elastic.name(), &cube.name, setup.label, accel)
                    .map(|(_, b)| b.shaper.clone());
                let shapers = SHAPERS
                    .iter()
                    .filter(|f| Some(f.name().to_string()) == best);
                for &shaper in std::iter::once(&FirmwareShaper::None).chain(shapers) {
                    massive.push((
                        s.clone(),
                        Job {
                            part: cube,
                            setup,
                            accel,
                            shaper,
                            model,
                        },
                    ));
                }
            }
        }
    }
    let rows = pool::map(&massive, |(s, job)| {
        print_row(s, job, freqs(job)).unwrap_or_else(|e| stopped_row(job, e.to_string()))
    })?;
    study.rows.extend(rows);
    Ok(study)
}

/// The modelled line of the massive prints [m]: examples/robots/hangprinter-lumped.toml's (the
/// Hangprinter's longest chord 2.30 m, its stretch, and spare stored line on the reel).
const MASSIVE_LINE_LENGTH: f64 = 3.2;

/// `base` on massive lines of `model` with `elements` each, on the implicit path.
fn massive_variant(base: &Scenario, model: ModelKind, elements: usize) -> Result<Scenario> {
    let mut config = cdpr_bench::ModelConfig::from_scenario(base)?;
    config.kind = model;
    config.elements = Some(elements as i64);
    let mut s = base.clone();
    s.cable.modelled_length = MASSIVE_LINE_LENGTH;
    s.model = config.section();
    s.simulation.integrator = IntegratorKind::Implicit;
    cdpr_bench::validate(&s)?;
    Ok(s)
}

/// One print of `job` on `base` (configured for it), shaped at `freqs` (x, y).
fn print_row(base: &Scenario, job: &Job, freqs: [Designed; 2]) -> Result<Row> {
    let mut s = configure(base, job.setup, job.accel, job.shaper);
    let printer = s.printer.as_mut().expect("configured");
    (printer.shaper_freq_x, printer.shaper_freq_y) = (freqs[0], freqs[1]);
    let print = cdpr_bench::prepare_print(&s, &job.part.gcode, Some(job.part.layers.clone()))?;
    let run = cdpr_bench::simulate_print(&s, &print, &mut Observer::progress(&mut |_| {}))?;
    let c = &run.contour;
    let hz = |f: Designed| match f {
        Designed::Value(v) => v,
        Designed::Auto(_) => f64::NAN,
    };
    Ok(Row {
        model: job.model.name(),
        part: job.part.name.clone(),
        setup: job.setup.label,
        accel_mm_s2: job.accel,
        shaper: job.shaper.name().to_string(),
        shaper_freq_hz: if job.shaper == FirmwareShaper::None {
            [f64::NAN; 2]
        } else {
            [hz(freqs[0]), hz(freqs[1])]
        },
        print_time_s: print.path.plan().print_time,
        contour_err_max_printing: c.printing.max,
        contour_err_rms_printing: c.printing.rms,
        contour_err_max: c.overall.max,
        contour_err_p99: c.overall.p99,
        contour_err_max_external_perimeter: c
            .by_kind
            .get(&MoveKind::ExternalPerimeter)
            .map_or(f64::NAN, |s| s.max),
        tracking_err_max: c.tracking.max,
        steps: run.run.stats.steps_accepted,
        rhs_evaluations: run.run.stats.rhs_evals,
        stopped: None,
    })
}

/// The row of a print that stopped (a line gone slack, the integrator's failure): its errors
/// NaN and why.
fn stopped_row(job: &Job, why: String) -> Row {
    Row {
        model: job.model.name(),
        part: job.part.name.clone(),
        setup: job.setup.label,
        accel_mm_s2: job.accel,
        shaper: job.shaper.name().to_string(),
        shaper_freq_hz: [f64::NAN; 2],
        print_time_s: f64::NAN,
        contour_err_max_printing: f64::NAN,
        contour_err_rms_printing: f64::NAN,
        contour_err_max: f64::NAN,
        contour_err_p99: f64::NAN,
        contour_err_max_external_perimeter: f64::NAN,
        tracking_err_max: f64::NAN,
        steps: 0,
        rhs_evaluations: 0,
        stopped: Some(why),
    }
}

/// `base` with the setup's controller, the printing acceleration and the shaper (frequencies
/// "auto").
fn configure(base: &Scenario, setup: Setup, accel: f64, shaper: FirmwareShaper) -> Scenario {
    let mut s = base.clone();
    s.controller.kind = setup.controller;
    s.controller.flex_compensation = setup.flex;
    let printer = s.printer.get_or_insert_with(Printer::default);
    printer.max_accel = accel * 1e-3;
    printer.shaper = shaper;
    printer.shaper_freq_x = Designed::Auto(AutoWord::Auto);
    printer.shaper_freq_y = Designed::Auto(AutoWord::Auto);
    // The first layer moves in z only at its start: z stays unshaped.
    printer.shaper_freq_z = Designed::Value(0.0);
    s
}
