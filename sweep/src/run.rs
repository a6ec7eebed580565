//! Running a sweep: the output directory locked, every point checked first (its scenario and
//! the memory `jobs` runs at once need), then the shard's points not yet recorded run on `jobs`
//! worker threads (each holds one run's state and samples at a time), their records appended as
//! they finish and, at the end, rewritten in point order.

use crate::error::SweepError;
use crate::grid::Grid;
use crate::point;
use crate::record::{Record, evaluate_into};
use crate::shard::Shard;
use crate::store::{self, Appender, DirLock, Header};
use cdpr_bench::core::series::SeriesBuffer;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

/// How to run a sweep.
#[derive(Debug, Clone, Copy)]
pub struct Options<'a> {
    /// Worker threads (≥ 1; 0 is an error).
    pub jobs: usize,
    pub shard: Shard,
    /// When set (a signal handler), the check stops, workers take no new point and interrupt
    /// the ones running; interrupted points are not recorded, so a resumed sweep runs them.
    pub stop: Option<&'a AtomicBool>,
}

/// What a sweep did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Summary {
    /// Points of this shard.
    pub shard_points: usize,
    /// Of those, recorded by an earlier (interrupted) sweep and skipped.
    pub resumed: usize,
    /// Run now.
    pub ran: usize,
    /// Run now and failed.
    pub failed: usize,
    /// Stopped before every point was recorded.
    pub interrupted: bool,
}

/// Where a sweep is, for a progress display.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Checking the grid's points: (checked, total).
    Checking(usize, usize),
    /// Running the shard's points: (recorded, the shard's points).
    Running(usize, usize),
}

/// The number of worker threads the machine offers.
pub fn all_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Worker threads for a requested count: every core when none is asked for; 0 is refused.
pub fn jobs(requested: Option<usize>) -> Result<usize, SweepError> {
    match requested {
        Some(0) => Err(SweepError::Jobs),
        Some(j) => Ok(j),
        None => Ok(all_cores()),
    }
}

/// Runs the sweep into `dir` (created if missing). `progress` is called on the calling thread
/// as points are checked and recorded.
pub fn run(
    grid: &Grid,
    dir: &Path,
    options: Options,
    progress: &mut dyn FnMut(Phase),
) -> Result<Summary, SweepError> {
    if options.jobs == 0 {
        return Err(SweepError::Jobs);
    }
    std::fs::create_dir_all(dir).map_err(|e| SweepError::io(dir, e))?;
    let _lock = DirLock::acquire(dir, &format!("sweep shard {}", options.shard))?;
    let checked = point::check_all(grid, options.jobs, options.stop, &mut |done, total| {
        progress(Phase::Checking(done, total))
    })?;
    point::check_memory(grid, &checked, options.jobs)?;
    let header = Header::of(grid);
    // Every record the directory holds is kept, another shard's too: a run never drops what an
    // earlier one computed. Each was checked against the grid.
    let existing = store::existing(dir, grid)?;
    let mut recorded = vec![false; grid.len()];
    for p in existing.iter().flat_map(|s| s.points()) {
        recorded[p] = true;
    }
    let mut appender = Appender::open(dir, &header, existing.as_ref())?;
    drop(existing);
    let owned = |i: usize| options.shard.owns(i);
    let shard_points = (0..grid.len()).filter(|&i| owned(i)).count();
    let pending: Vec<usize> = (0..grid.len())
        .filter(|&i| owned(i) && !recorded[i])
        .collect();
    let mut summary = Summary {
        shard_points,
        resumed: shard_points - pending.len(),
        ran: 0,
        failed: 0,
        interrupted: false,
    };
    // Set by a failed write: the workers stop at once, whatever the caller's stop flag says.
    let halt = AtomicBool::new(false);
    progress(Phase::Running(summary.resumed, shard_points));
    let write_error = run_points(grid, &pending, options, &halt, &mut |record| {
        summary.ran += 1;
        summary.failed += usize::from(record.status != "complete");
        let written = appender.push(&record);
        progress(Phase::Running(summary.resumed + summary.ran, shard_points));
        written
    });
    if let Some(e) = write_error {
        // What was written stays: whole lines, read back by the next run.
        return Err(e);
    }
    summary.interrupted = summary.resumed + summary.ran < shard_points;
    match store::finish(dir, grid, options.stop) {
        Ok(()) => Ok(summary),
        // Interrupted while rewriting: the appended file is complete; a resume rewrites it.
        Err(_) if options.stop.is_some_and(|s| s.load(Ordering::Relaxed)) => {
            summary.interrupted = true;
            Ok(summary)
        }
        Err(e) => Err(e),
    }
}

/// Runs `pending` on the workers, handing each record to `record` on the calling thread; the
/// first write error halts the workers and is returned.
fn run_points(
    grid: &Grid,
    pending: &[usize],
    options: Options,
    halt: &AtomicBool,
    record: &mut dyn FnMut(Record) -> Result<(), SweepError>,
) -> Option<SweepError> {
    let next = AtomicUsize::new(0);
    // The runs watch one flag: the caller's stop, or a failed write.
    let stop_runs = AtomicBool::new(false);
    let stopped =
        || halt.load(Ordering::Relaxed) || options.stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let mut write_error = None;
    std::thread::scope(|scope| {
        let (send, receive) = mpsc::channel::<Record>();
        for _ in 0..options.jobs.min(pending.len().max(1)) {
            let send = send.clone();
            let (next, stop_runs) = (&next, &stop_runs);
            scope.spawn(move || {
                let mut buffer = SeriesBuffer::default();
                loop {
                    if stopped() {
                        return;
                    }
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&index) = pending.get(k) else { return };
                    let Some(record) = evaluate_into(grid, index, Some(stop_runs), &mut buffer)
                    else {
                        return;
                    };
                    if send.send(record).is_err() {
                        return;
                    }
                }
            });
        }
        drop(send);
        loop {
            match receive.recv_timeout(std::time::Duration::from_millis(50)) {
                Ok(r) => {
                    if write_error.is_none()
                        && let Err(e) = record(r)
                    {
                        write_error = Some(e);
                        halt.store(true, Ordering::Relaxed);
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            if stopped() {
                stop_runs.store(true, Ordering::Relaxed);
            }
        }
    });
    write_error
}
