//! A point's scenario: the grid's base with each axis key set by its dotted path, then read and
//! checked whole by the registry exactly as a scenario file is (so an unknown key or a value out
//! of its range is the same named error as in `cargo xtask simulate`, prefixed with the point).

use crate::error::SweepError;
use crate::grid::{Grid, Point};
use cdpr_bench::core::scenario::Scenario;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use toml::{Table, Value};

/// The scenario of `point`, validated.
pub fn scenario(grid: &Grid, point: &Point) -> Result<Scenario, SweepError> {
    let mut table = grid.base.clone();
    for (key, value) in &point.values {
        set(&mut table, key, value.clone()).map_err(|message| SweepError::Point {
            index: point.index,
            params: describe(point),
            message,
        })?;
    }
    let text = toml::to_string(&table).expect("a TOML table prints");
    cdpr_bench::scenario_from_toml_str(&text).map_err(|e| SweepError::Point {
        index: point.index,
        params: describe(point),
        message: e.to_string(),
    })
}

/// What checking every point found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Checked {
    /// The point whose run needs the most memory, and how much [B]
    /// ([`cdpr_bench::memory::run_memory`]).
    pub largest: usize,
    pub largest_bytes: f64,
}

/// Every point's scenario checked on `jobs` threads, before any work starts, and each point's
/// memory estimated: the lowest bad point is the error. `stop` interrupts the check (within a
/// point's check, ~50 µs); `progress(checked, total)` is called on the calling thread.
pub fn check_all(
    grid: &Grid,
    jobs: usize,
    stop: Option<&AtomicBool>,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Checked, SweepError> {
    let total = grid.len();
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    // The lowest failing index so far: workers take no point above it.
    let first_bad = AtomicUsize::new(usize::MAX);
    let failure: Mutex<Option<SweepError>> = Mutex::new(None);
    // Per model section (kind, elements, …), the point with the most samples: the memory of
    // a run is its samples times its model's channels.
    let largest: Mutex<Vec<(String, f64, usize)>> = Mutex::new(Vec::new());
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let workers = jobs.clamp(1, total.max(1));
    let running = AtomicUsize::new(workers);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                let mut mine: Vec<(String, f64, usize)> = Vec::new();
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= total || i > first_bad.load(Ordering::Relaxed) || stopped() {
                        break;
                    }
                    match scenario(grid, &grid.point(i)) {
                        Ok(s) => {
                            let section = toml::to_string(&s.model).unwrap_or_default();
                            let samples = cdpr_bench::memory::samples(&s);
                            keep_largest(&mut mine, (section, samples, i));
                        }
                        Err(e) => {
                            let mut f = failure.lock().expect("no worker panics");
                            if i < first_bad.load(Ordering::Relaxed) {
                                first_bad.store(i, Ordering::Relaxed);
                                *f = Some(e);
                            }
                        }
                    }
                    done.fetch_add(1, Ordering::Relaxed);
                }
                running.fetch_sub(1, Ordering::Relaxed);
                let mut all = largest.lock().expect("no worker panics");
                for candidate in mine {
                    keep_largest(&mut all, candidate);
                }
            });
        }
        while running.load(Ordering::Relaxed) > 0 {
            progress(done.load(Ordering::Relaxed), total);
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
    });
    if let Some(e) = failure.into_inner().expect("no worker panics") {
        return Err(e);
    }
    if stopped() {
        return Err(SweepError::Interrupted("checking the grid's points"));
    }
    progress(total, total);
    hungriest(grid, largest.into_inner().expect("no worker panics"))
}

/// Per model section, the point with the most samples (section, samples, point): `candidate`
/// replaces its section's entry when it has more samples, or as many at a lower point (so the
/// choice does not depend on which worker checked which point).
fn keep_largest(largest: &mut Vec<(String, f64, usize)>, candidate: (String, f64, usize)) {
    let (section, samples, i) = candidate;
    match largest.iter_mut().find(|(m, _, _)| *m == section) {
        Some(slot) if slot.1 > samples || (slot.1 == samples && slot.2 < i) => {}
        Some(slot) => *slot = (section, samples, i),
        None => largest.push((section, samples, i)),
    }
}

/// Of each section's largest point, the one whose run needs the most memory.
fn hungriest(grid: &Grid, largest: Vec<(String, f64, usize)>) -> Result<Checked, SweepError> {
    let mut checked = Checked {
        largest: 0,
        largest_bytes: 0.0,
    };
    for (_, _, i) in largest {
        let s = scenario(grid, &grid.point(i))?;
        let bytes = cdpr_bench::memory::run_memory(&s).map_err(|e| SweepError::Point {
            index: i,
            params: describe(&grid.point(i)),
            message: e.to_string(),
        })?;
        if bytes > checked.largest_bytes {
            checked = Checked {
                largest: i,
                largest_bytes: bytes,
            };
        }
    }
    Ok(checked)
}

/// Refuses `jobs` runs at once of the grid's hungriest point when they would take more than
/// [`cdpr_bench::memory::MEMORY_SHARE`] of the available memory, naming the point, its sample
/// period and the worker count that fits.
pub fn check_memory(grid: &Grid, checked: &Checked, jobs: usize) -> Result<(), SweepError> {
    let Some(available) = cdpr_bench::memory::available_memory() else {
        return Ok(());
    };
    let at_once = jobs.min(grid.len()) as f64;
    let budget = cdpr_bench::memory::MEMORY_SHARE * available;
    if checked.largest_bytes * at_once <= budget {
        return Ok(());
    }
    let point = grid.point(checked.largest);
    let s = scenario(grid, &point)?;
    let fits = (budget / checked.largest_bytes).floor() as usize;
    Err(SweepError::Memory(format!(
        "point {} ({}) needs about {:.1} GB for its samples and metrics          (simulation.sample_period = {} s, t_final = {} s); {} at once need {:.1} GB, more than          half of the {:.1} GB available: {}",
        checked.largest,
        describe(&point),
        checked.largest_bytes / 1e9,
        s.simulation.sample_period,
        s.simulation.t_final,
        at_once,
        checked.largest_bytes * at_once / 1e9,
        available / 1e9,
        if fits >= 1 {
            format!("run with --jobs {fits} or fewer, or raise simulation.sample_period")
        } else {
            "raise simulation.sample_period or shorten simulation.t_final".to_string()
        }
    )))
}

/// `key = value, …` of a point, for messages.
pub fn describe(point: &Point) -> String {
    point
        .values
        .iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Sets `section.key` (or deeper) in `table`; the key must name a section and a key in it. An
/// array element is named by 0-based indices after the key: `robot.anchors[3][2]` is the z of
/// the fourth anchor, `trajectory.end[0]` the end's x (the array must be in the base scenario).
fn set(table: &mut Table, dotted: &str, value: Value) -> Result<(), String> {
    let parts: Vec<&str> = dotted.split('.').collect();
    if parts.len() < 2 || parts.iter().any(|p| p.is_empty()) {
        return Err(format!(
            "axis key `{dotted}` must be a dotted path `section.key` (e.g. robot.effector_mass)"
        ));
    }
    let mut at = table;
    for part in &parts[..parts.len() - 1] {
        let entry = at
            .entry(part.to_string())
            .or_insert_with(|| Value::Table(Table::new()));
        at = match entry {
            Value::Table(t) => t,
            other => {
                return Err(format!(
                    "axis key `{dotted}`: `{part}` is a value ({other}), not a section"
                ));
            }
        };
    }
    let (name, indices) = indexed(dotted, parts[parts.len() - 1])?;
    if indices.is_empty() {
        at.insert(name.to_string(), value);
        return Ok(());
    }
    let mut slot = at.get_mut(name).ok_or_else(|| {
        format!(
            "axis key `{dotted}`: `{name}` is not in the grid's scenario, so it has no elements"
        )
    })?;
    for &k in &indices {
        let Value::Array(items) = slot else {
            return Err(format!("axis key `{dotted}`: `{slot}` is not an array"));
        };
        let len = items.len();
        slot = items.get_mut(k).ok_or_else(|| {
            format!("axis key `{dotted}`: index {k} outside an array of {len} (0-based)")
        })?;
    }
    *slot = value;
    Ok(())
}

/// A key and its 0-based indices: `anchors[3][2]` → (`anchors`, [3, 2]).
fn indexed<'a>(dotted: &str, part: &'a str) -> Result<(&'a str, Vec<usize>), String> {
    let Some(open) = part.find('[') else {
        return Ok((part, Vec::new()));
    };
    let (name, mut rest) = part.split_at(open);
    let mut indices = Vec::new();
    while !rest.is_empty() {
        let index = rest
            .strip_prefix('[')
            .and_then(|r| r.split_once(']'))
            .and_then(|(k, tail)| Some((k.parse::<usize>().ok()?, tail)));
        let Some((k, tail)) = index else {
            return Err(format!(
                "axis key `{dotted}`: `{part}` must be a key followed by 0-based indices, \
                 e.g. robot.anchors[3][2]"
            ));
        };
        indices.push(k);
        rest = tail;
    }
    Ok((name, indices))
}
