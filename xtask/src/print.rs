//! `cargo xtask plan` and `cargo xtask print`: a slicer's G-code through the firmware's planner
//! (→ `plan.csv`), and through the simulated printer (→ `metrics.json` with the contour error
//! overall and per move type, `print.csv`, a figure per layer). The print is checked before any
//! work (the file, the limits, the reference's wrench feasibility), streams its rows to
//! `print.partial.csv` as it runs, shows its progress with an ETA, and an interrupt or a failure
//! keeps what it computed.

use crate::output::{Progress, csv_row, write_atomic, write_json};
use crate::simulate::{STOP, load_scenario, writable_out};
use anyhow::{Context, Result, bail};
use cdpr_bench::analysis::contour::{ContourMetrics, ErrorStats, contour_sample};
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::robot::Vector;
use cdpr_bench::core::runner::{Observer, RunError};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::printing::gcode::MoveKind;
use cdpr_bench::printing::{gcode, planner};
use cdpr_bench::{Error, PreparedPrint, Provenance};
use cdpr_sweep::DirLock;
use std::collections::BTreeMap;
use std::io::{BufWriter, Write};
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

/// `plan.csv`.
const PLAN: &str = "plan.csv";
/// `print.csv` and its partial form while the print runs.
const PRINT: &str = "print.csv";
const PRINT_PARTIAL: &str = "print.partial.csv";

/// `--layers A..B` (or a single layer `A`).
pub fn parse_layers(text: &str) -> Result<RangeInclusive<usize>, String> {
    let parse = |s: &str| {
        s.trim()
            .parse::<usize>()
            .map_err(|_| format!("--layers {text}: `{s}` is not a layer number (0, 1, 2, …)"))
    };
    let (a, b) = match text.split_once("..") {
        Some((a, b)) => (parse(a)?, parse(b.trim_start_matches('='))?),
        None => (parse(text)?, parse(text)?),
    };
    if a > b {
        return Err(format!(
            "--layers {text}: the first layer must not follow the last"
        ));
    }
    Ok(a..=b)
}

fn read_gcode(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("reading --gcode {}", path.display()))
}

/// `cargo xtask plan`: the firmware's plan of the whole file in the robot's frame.
pub fn plan(scenario: Option<&Path>, gcode_file: &Path, out: &Path) -> Result<()> {
    let scenario = load_scenario(scenario, None)?;
    let printer = scenario.printer.clone().unwrap_or_default();
    let origin = printer.origin3();
    let program = gcode::read(&read_gcode(gcode_file)?, cdpr_bench::gcode_home(&scenario))
        .with_context(|| format!("reading {}", gcode_file.display()))?;
    let started = std::time::Instant::now();
    let plan = planner::plan(&program, &printer.limits())?;
    let planning = started.elapsed().as_secs_f64();
    writable_out(out)?;
    let csv = plan.csv(origin);
    write_atomic(&out.join(PLAN), |w| w.write_all(csv.as_bytes()))?;
    list_skipped(&program);
    println!(
        "{} segments over {} layers, print time {:.3} s, planned in {:.1} ms → {}",
        plan.segments.len(),
        program.layers,
        plan.print_time,
        planning * 1e3,
        out.join(PLAN).display()
    );
    Ok(())
}

/// Where a print's channels sit in a run's row.
struct Columns {
    t: usize,
    xyz: [usize; 3],
    tensions: Vec<usize>,
}

/// `print.csv`, written as the print runs: t, reference, effector, contour error, tensions.
struct PrintCsv {
    writer: BufWriter<std::fs::File>,
    path: PathBuf,
    rows: usize,
    every: usize,
    error: Option<std::io::Error>,
}

impl PrintCsv {
    fn create(path: PathBuf, cables: usize, every: usize) -> Result<Self> {
        let file =
            std::fs::File::create(&path).with_context(|| format!("creating {}", path.display()))?;
        let mut writer = BufWriter::with_capacity(1 << 16, file);
        let mut heading =
            String::from("t [s],x_ref [m],y_ref [m],z_ref [m],x [m],y [m],z [m],contour_err [m]");
        for i in 1..=cables {
            heading.push_str(&format!(",T{i} [N]"));
        }
        writeln!(writer, "{heading}").with_context(|| format!("writing {}", path.display()))?;
        Ok(PrintCsv {
            writer,
            path,
            rows: 0,
            every,
            error: None,
        })
    }

    fn push(&mut self, print: &PreparedPrint, columns: &Columns, row: &[f64]) {
        if self.rows.is_multiple_of(self.every) && self.error.is_none() {
            let t = row[columns.t];
            let p = Vector::<3>::from_fn(|k, _| row[columns.xyz[k]]);
            let reference = print.path.reference(t, false)[0];
            let contour = contour_sample(&print.path, t, &p).error;
            let mut values = vec![
                t,
                reference[0],
                reference[1],
                reference[2],
                p[0],
                p[1],
                p[2],
            ];
            values.push(contour);
            values.extend(columns.tensions.iter().map(|&i| row[i]));
            let mut line = String::with_capacity(24 * values.len());
            csv_row(&mut line, &values);
            if let Err(e) = self.writer.write_all(line.as_bytes()) {
                self.error = Some(e);
                STOP.store(true, Ordering::Relaxed);
            }
        }
        self.rows += 1;
    }

    fn finish(self, target: &Path) -> Result<()> {
        if let Some(e) = self.error {
            bail!("writing {}: {e}", self.path.display());
        }
        let path = self.path.clone();
        self.writer
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all())
            .with_context(|| format!("writing {}", path.display()))?;
        std::fs::rename(&path, target)
            .with_context(|| format!("renaming into {}", target.display()))
    }
}

/// `metrics.json` of a print.
#[derive(serde::Serialize)]
struct PrintMetricsFile<'a> {
    status: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
    provenance: &'a Provenance,
    gcode: String,
    layers: [usize; 2],
    segments: usize,
    /// The firmware's print time of the printed part [s].
    print_time_s: f64,
    t_reached: f64,
    #[serde(flatten)]
    contour: BTreeMap<String, f64>,
    samples: usize,
    /// The run's cost.
    #[serde(flatten)]
    cost: crate::cost::RunCost,
    wall_s: f64,
    units: BTreeMap<&'static str, &'static str>,
}

/// The contour and tracking statistics as flat keys: `contour_err_max`, …,
/// `contour_err_max_external_perimeter`, …, `tracking_err_max`, ….
fn flat(contour: &ContourMetrics) -> BTreeMap<String, f64> {
    let mut out = BTreeMap::new();
    let mut put = |prefix: &str, suffix: &str, s: &ErrorStats| {
        out.insert(format!("{prefix}_max{suffix}"), s.max);
        out.insert(format!("{prefix}_rms{suffix}"), s.rms);
        out.insert(format!("{prefix}_p99{suffix}"), s.p99);
    };
    put("contour_err", "", &contour.overall);
    put("contour_err", "_printing", &contour.printing);
    for kind in MoveKind::ALL {
        let stats = contour
            .by_kind
            .get(&kind)
            .copied()
            .unwrap_or(ErrorStats::of(&mut []));
        put("contour_err", &format!("_{}", kind.name()), &stats);
    }
    put("tracking_err", "", &contour.tracking);
    out
}

/// Options of `cargo xtask print`.
pub struct PrintOptions<'a> {
    pub scenario: &'a Path,
    pub gcode: &'a Path,
    pub layers: Option<RangeInclusive<usize>>,
    pub out: &'a Path,
    pub every: usize,
}

/// `cargo xtask print`.
pub fn print(options: &PrintOptions) -> Result<()> {
    let (scenario, prepared) = prepare(options)?;
    list_skipped(&prepared.program);
    let provenance = Provenance::of(&scenario)?;
    let out = options.out;
    writable_out(out)?;
    let _lock = DirLock::acquire(out, "print")?;
    for stale in [PRINT, PRINT_PARTIAL, crate::simulate::METRICS] {
        let _ = std::fs::remove_file(out.join(stale));
    }
    let ended = run_streamed(&scenario, &prepared, out, options.every)?;
    let plan = prepared.path.plan();
    write_metrics(options, &provenance, &prepared, &ended)?;
    ended.written?;
    if let (Some(run), Some(contour)) = (&ended.run, &ended.contour) {
        crate::print_figures::write(&prepared, run, out)?;
        println!(
            "{} segments, print time {:.2} s, simulated in {:.2} s: contour error of the \
             printing moves max {:.1} µm, rms {:.1} µm (all moves max {:.1} µm) → {}",
            plan.segments.len(),
            plan.print_time,
            ended.wall_s,
            contour.printing.max * 1e6,
            contour.printing.rms * 1e6,
            contour.overall.max * 1e6,
            out.display()
        );
    }
    match ended.error {
        None => Ok(()),
        Some(e) => bail!(
            "{e}; {} print kept up to t = {} s in {} and {}",
            ended.status,
            ended.run.as_ref().map_or(0.0, |r| r.t_reached),
            out.join(PRINT).display(),
            out.join(crate::simulate::METRICS).display()
        ),
    }
}

/// The scenario (its `"auto"` shaper frequencies resolved at the printed layers' centre) and
/// the print, checked before anything is written.
fn prepare(options: &PrintOptions) -> Result<(Scenario, PreparedPrint)> {
    let scenario = load_scenario(Some(options.scenario), None)?;
    let text = read_gcode(options.gcode)?;
    let printing = || format!("printing {}", options.gcode.display());
    let scenario = if cdpr_studies::print_study::needs_auto(&scenario) {
        let part = cdpr_studies::print_study::Part {
            name: options.gcode.display().to_string(),
            gcode: text.clone(),
            layers: options.layers.clone().unwrap_or(0..=usize::MAX),
        };
        let centre =
            cdpr_studies::print_study::layer_centre(&scenario, &part).with_context(printing)?;
        cdpr_studies::print_study::resolve_auto(&scenario, centre)?
    } else {
        scenario
    };
    let prepared = cdpr_bench::prepare_print(&scenario, &text, options.layers.clone())
        .with_context(printing)?;
    Ok((scenario, prepared))
}

/// The commands the reader skipped, once each, on stderr.
fn list_skipped(program: &gcode::Program) {
    for s in &program.skipped {
        eprintln!(
            "skipped {} ({}×, first on line {})",
            s.command, s.count, s.first_line
        );
    }
}

/// Where the print's channels sit in the run's row.
fn columns(scenario: &Scenario) -> Result<(Columns, usize)> {
    let cables = scenario.spatial_robot().map_or(0, |r| r.cables());
    let (names, _) = cdpr_bench::spatial_channel_headings(scenario)?;
    let index = |name: &str| names.iter().position(|n| n == name).expect("channel");
    let columns = Columns {
        t: index(&Channel::Time.name()),
        xyz: [Channel::X, Channel::Y, Channel::Z].map(|c| index(&c.name())),
        tensions: (1..=cables).map(|i| index(&format!("T{i}"))).collect(),
    };
    Ok((columns, cables))
}

/// How a print ended: what it computed (all, or what a failed or interrupted run sampled),
/// "complete" | "interrupted" | "failed", why, its wall time, and whether print.csv was written.
struct Ended {
    run: Option<cdpr_bench::core::runner::Run>,
    /// The run's contour metrics (a complete run's from the print itself).
    contour: Option<ContourMetrics>,
    status: &'static str,
    error: Option<String>,
    wall_s: f64,
    written: Result<()>,
}

/// Runs the print with its rows streamed to `print.partial.csv` (renamed to `print.csv` at the
/// end, whatever the ending), its progress shown, SIGINT/SIGTERM honoured.
fn run_streamed(
    scenario: &Scenario,
    prepared: &PreparedPrint,
    out: &Path,
    every: usize,
) -> Result<Ended> {
    let (columns, cables) = columns(scenario)?;
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .context("installing the SIGINT/SIGTERM handler")?;
    let mut csv = PrintCsv::create(out.join(PRINT_PARTIAL), cables, every)?;
    let started = std::time::Instant::now();
    let mut progress = Progress::new("print");
    let result = {
        let mut on_sample = |row: &[f64]| csv.push(prepared, &columns, row);
        let mut report = |f: f64| progress.set(f);
        let mut observer = Observer {
            progress: &mut report,
            on_sample: Some(&mut on_sample),
            stop: Some(&STOP),
            frames: None,
        };
        cdpr_bench::simulate_print(scenario, prepared, &mut observer)
    };
    progress.finish();
    let wall_s = started.elapsed().as_secs_f64();
    let (run, contour, status, error) = match result {
        Ok(done) => (Some(done.run), Some(done.contour), "complete", None),
        Err(Error::Run(failure)) => {
            let status = match failure.error {
                RunError::Interrupted { .. } => "interrupted",
                _ => "failed",
            };
            let contour = failure
                .partial
                .as_ref()
                .map(|r| cdpr_bench::contour_of(prepared, r));
            let error = Some(failure.error.to_string());
            (failure.partial, contour, status, error)
        }
        Err(e) => (None, None, "failed", Some(e.to_string())),
    };
    // A failed write fails the print whatever it did.
    let write_error = csv
        .error
        .as_ref()
        .map(|e| format!("writing {}: {e}", csv.path.display()));
    let status = if write_error.is_some() {
        "failed"
    } else {
        status
    };
    if let Some(run) = &run {
        // The rows of a failing step the stream has not seen.
        let mut row = vec![0.0; run.series.width()];
        for i in csv.rows..run.series.len() {
            run.series.copy_row(i, &mut row);
            csv.push(prepared, &columns, &row);
        }
    }
    Ok(Ended {
        run,
        contour,
        status,
        error: write_error.or(error),
        wall_s,
        written: csv.finish(&out.join(PRINT)),
    })
}

/// `metrics.json` of a print's ending.
fn write_metrics(
    options: &PrintOptions,
    provenance: &Provenance,
    prepared: &PreparedPrint,
    ended: &Ended,
) -> Result<()> {
    let plan = prepared.path.plan();
    let run = ended.run.as_ref();
    write_json(
        &options.out.join(crate::simulate::METRICS),
        &PrintMetricsFile {
            status: ended.status,
            error: ended.error.clone(),
            provenance,
            gcode: options.gcode.display().to_string(),
            layers: [*prepared.layers.start(), *prepared.layers.end()],
            segments: plan.segments.len(),
            print_time_s: plan.print_time,
            t_reached: run.map_or(0.0, |r| r.t_reached),
            contour: ended.contour.as_ref().map(flat).unwrap_or_default(),
            samples: run.map_or(0, |r| r.series.len()),
            cost: run.map(|r| (&r.stats).into()).unwrap_or_default(),
            wall_s: ended.wall_s,
            units: [
                ("print_time_s", "s"),
                ("t_reached", "s"),
                ("wall_s", "s"),
                ("contour_err_*", "m"),
                ("tracking_err_*", "m"),
            ]
            .into_iter()
            .collect(),
        },
    )
}
