//! Running a sweep: every point checked first, then the shard's points not yet recorded run on
//! `jobs` worker threads (each holds one run's state and samples at a time), their records
//! appended as they finish and, at the end, rewritten in point order.

use crate::error::SweepError;
use crate::grid::Grid;
use crate::point;
use crate::record::{Record, evaluate};
use crate::shard::Shard;
use crate::store::{self, Appender, Header};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

/// How to run a sweep.
#[derive(Debug, Clone, Copy)]
pub struct Options<'a> {
    /// Worker threads (≥ 1; 0 is an error).
    pub jobs: usize,
    pub shard: Shard,
    /// When set (a signal handler), workers take no new point and interrupt the ones running;
    /// interrupted points are not recorded, so a resumed sweep runs them.
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

/// Runs the sweep into `dir` (created if missing). `progress(done, total)` is called on the
/// calling thread after each point.
pub fn run(
    grid: &Grid,
    dir: &Path,
    options: Options,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Summary, SweepError> {
    if options.jobs == 0 {
        return Err(SweepError::Jobs);
    }
    point::check_all(grid)?;
    std::fs::create_dir_all(dir).map_err(|e| SweepError::io(dir, e))?;
    let header = Header::of(grid);
    // Every record the directory holds is kept, another shard's too: a run never drops what an
    // earlier one computed.
    let mut records = store::existing(dir, grid)?;
    let recorded: std::collections::HashSet<usize> = records.iter().map(|r| r.point).collect();
    let mut appender = Appender::open(dir, &header, &records)?;
    let shard_points = (0..grid.len()).filter(|&i| options.shard.owns(i)).count();
    let pending: Vec<usize> = (0..grid.len())
        .filter(|&i| options.shard.owns(i) && !recorded.contains(&i))
        .collect();
    let mut summary = Summary {
        shard_points,
        resumed: shard_points - pending.len(),
        ran: 0,
        failed: 0,
        interrupted: false,
    };
    let next = AtomicUsize::new(0);
    let stopped = || options.stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let mut write_error = None;
    std::thread::scope(|scope| {
        let (send, receive) = mpsc::channel::<Record>();
        for _ in 0..options.jobs.min(pending.len().max(1)) {
            let send = send.clone();
            let (next, pending) = (&next, &pending);
            scope.spawn(move || {
                loop {
                    if stopped() {
                        return;
                    }
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&index) = pending.get(k) else { return };
                    match evaluate(grid, index, options.stop) {
                        Some(record) => {
                            if send.send(record).is_err() {
                                return;
                            }
                        }
                        None => return,
                    }
                }
            });
        }
        drop(send);
        progress(summary.resumed, shard_points);
        for record in receive {
            summary.ran += 1;
            summary.failed += usize::from(record.status != "complete");
            if write_error.is_none()
                && let Err(e) = appender.push(&record)
            {
                write_error = Some(e);
            }
            records.push(record);
            progress(summary.resumed + summary.ran, shard_points);
        }
    });
    if let Some(e) = write_error {
        return Err(e);
    }
    summary.interrupted = summary.resumed + summary.ran < shard_points;
    store::finish(dir, &header, &mut records)?;
    Ok(summary)
}
