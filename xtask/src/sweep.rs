//! `cargo xtask sweep`: a grid file's points run metrics-only on every core (or `--jobs`), one
//! shard of them with `--shard I/N`, into DIR/results.jsonl and DIR/results.csv; `--merge`
//! combines shards. Every point is checked before any runs; SIGINT/SIGTERM stop the sweep after
//! interrupting the running points, keeping every finished record for a resume.

use crate::output::Progress;
use anyhow::{Context, Result};
use cdpr_sweep::{Grid, Options, Shard};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);

pub fn run(grid_path: &Path, out: &Path, jobs: Option<usize>, shard: Shard) -> Result<()> {
    let grid = Grid::from_file(grid_path)?;
    let jobs = cdpr_sweep::jobs(jobs)?;
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .context("installing the SIGINT/SIGTERM handler")?;
    let label = format!("sweep {shard}");
    let mut bar = Progress::new(&label);
    let start = std::time::Instant::now();
    let summary = cdpr_sweep::run(
        &grid,
        out,
        Options {
            jobs,
            shard,
            stop: Some(&STOP),
        },
        &mut |done, total| {
            bar.set(if total == 0 {
                1.0
            } else {
                done as f64 / total as f64
            })
        },
    )?;
    bar.finish();
    let elapsed = start.elapsed().as_secs_f64();
    eprintln!(
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
    let (header, n) = cdpr_sweep::merge(inputs, out)?;
    eprintln!(
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
