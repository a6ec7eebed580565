//! Merging the shards' results files: one grid, each record checked against it, each point
//! once (a point recorded twice must agree but for `wall_s`), then sorted as a sweep's.

use super::files::DirLock;
use super::{
    Entry, Header, RESULTS, Scan, read_line, results_error, same_results, scan, write_sorted,
};
use crate::error::SweepError;
use crate::record::Record;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Combines the shards' results files into `out`: one grid (equal headers), each record checked
/// against it, each point once (a point recorded twice must agree but for `wall_s`).
pub fn merge(
    inputs: &[PathBuf],
    out: &Path,
    stop: Option<&AtomicBool>,
) -> Result<(Header, usize), SweepError> {
    if inputs.is_empty() {
        return Err(results_error(
            out,
            "--merge needs at least one results file".into(),
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| SweepError::io(out, e))?;
    let _lock = DirLock::acquire(out, "merge")?;
    let mut scans = scan_inputs(inputs)?;
    let owner = keep_each_point_once(&mut scans)?;
    let header = scans[0].header.clone();
    let n = owner.iter().filter(|o| o.is_some()).count();
    write_sorted(out, &scans, stop)?;
    Ok((header, n))
}

/// Each input (a results file, or a directory holding one) scanned; all must be of one grid.
fn scan_inputs(inputs: &[PathBuf]) -> Result<Vec<Scan>, SweepError> {
    let mut scans: Vec<Scan> = Vec::new();
    for dir in inputs {
        let path = if dir.is_dir() {
            dir.join(RESULTS)
        } else {
            dir.clone()
        };
        let scan = scan(&path, None)?;
        if let Some(first) = scans.first()
            && first.header != scan.header
        {
            return Err(results_error(
                &path,
                format!(
                    "is of another grid than {} (digest {} vs {})",
                    first.path.display(),
                    scan.header.grid,
                    first.header.grid
                ),
            ));
        }
        scans.push(scan);
    }
    Ok(scans)
}

/// Each point once: a later input's record of a point already seen must agree with it, and is
/// dropped from that input's entries. Returns each point's owner (input, entry).
fn keep_each_point_once(scans: &mut [Scan]) -> Result<Vec<Option<(usize, Entry)>>, SweepError> {
    let points = scans[0].header.points;
    let mut owner: Vec<Option<(usize, Entry)>> = vec![None; points];
    let mut files: Vec<Option<File>> = (0..scans.len()).map(|_| None).collect();
    for k in 0..scans.len() {
        let mut kept = Vec::new();
        for entry in std::mem::take(&mut scans[k].entries) {
            match owner[entry.point] {
                None => {
                    owner[entry.point] = Some((k, entry));
                    kept.push(entry);
                }
                Some((j, first)) => {
                    let a = read_entry(&scans[j], &mut files[j], &first)?;
                    let b = read_entry(&scans[k], &mut files[k], &entry)?;
                    if !same_results(&a, &b) {
                        return Err(results_error(
                            &scans[k].path,
                            format!(
                                "point {} is recorded differently in {} (line {})",
                                entry.point,
                                scans[j].path.display(),
                                first.line
                            ),
                        ));
                    }
                }
            }
        }
        scans[k].entries = kept;
    }
    Ok(owner)
}

/// The record of `entry` in `scan`'s file (opened into `file` on first use).
fn read_entry(scan: &Scan, file: &mut Option<File>, entry: &Entry) -> Result<Record, SweepError> {
    let path = &scan.path;
    let file = match file {
        Some(f) => f,
        slot => slot.insert(File::open(path).map_err(|e| SweepError::io(path, e))?),
    };
    serde_json::from_str(&read_line(file, path, entry)?)
        .map_err(|err| results_error(path, format!("line {}: {err}", entry.line)))
}
