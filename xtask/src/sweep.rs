//! `cargo xtask sweep`: a grid file's points run metrics-only on every core (or `--jobs`), one
//! shard of them with `--shard I/N`, into DIR/results.jsonl and DIR/results.csv; `--merge`
//! combines shards. Every point is checked before any runs; SIGINT/SIGTERM stop the sweep after
//! interrupting the running points, keeping every finished record for a resume.

use crate::output::Progress;
use anyhow::{Context, Result};
use cdpr_sweep::{Grid, Options, Phase, Shard};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);

pub fn run(grid_path: &Path, out: &Path, jobs: Option<usize>, shard: Shard) -> Result<()> {
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .context("installing the SIGINT/SIGTERM handler")?;
    let grid = Grid::from_file(grid_path)?;
    let jobs = cdpr_sweep::jobs(jobs)?;
    // The check shows progress only where it takes a while (~50 µs a point).
    let mut checking: Option<Progress> = None;
    let mut running: Option<Progress> = None;
    let label = format!("sweep {shard}");
    let start = std::time::Instant::now();
    let fraction = |done: usize, total: usize| {
        if total == 0 {
            1.0
        } else {
            done as f64 / total as f64
        }
    };
    let summary = cdpr_sweep::run(
        &grid,
        out,
        Options {
            jobs,
            shard,
            stop: Some(&STOP),
        },
        &mut |phase| match phase {
            Phase::Checking(done, total) if total >= 10_000 => checking
                .get_or_insert_with(|| Progress::new("checking points"))
                .set(fraction(done, total)),
            Phase::Checking(..) => {}
            Phase::Running(done, total) => running
                .get_or_insert_with(|| Progress::new(&label))
                .set(fraction(done, total)),
        },
    )?;
    for bar in [&checking, &running].into_iter().flatten() {
        bar.finish();
    }
    let elapsed = start.elapsed().as_secs_f64();
    println!(
        "{} of {} points of shard {shard} recorded ({} resumed, {} run in {elapsed:.1} s on {jobs} \
         workers, {:.1} points/s, {} failed) → {}",
        summary.resumed + summary.ran,
        summary.shard_points,
        summary.resumed,
        summary.ran,
        summary.ran as f64 / elapsed.max(1e-9),
        summary.failed,
        out.join(cdpr_sweep::store::RESULTS).display()
    );
    if summary.interrupted {
        anyhow::bail!(
            "interrupted: run the same command again to resume the {} points left",
            summary.shard_points - summary.resumed - summary.ran
        );
    }
    Ok(())
}

pub fn merge(inputs: &[PathBuf], out: &Path) -> Result<()> {
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .context("installing the SIGINT/SIGTERM handler")?;
    let (header, n) = cdpr_sweep::merge(inputs, out, Some(&STOP))?;
    println!(
        "merged {} inputs: {n} of {} points → {}",
        inputs.len(),
        header.points,
        out.join(cdpr_sweep::store::RESULTS).display()
    );
    if n < header.points {
        eprintln!("{} points have no record yet", header.points - n);
    }
    Ok(())
}
