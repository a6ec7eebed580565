//! `results.jsonl` and `results.csv`. The JSONL file opens with a header naming the grid (its
//! digest, point count and canonical text); each finished point appends one line written in one
//! call, so a kill at any instant leaves complete lines and at most a torn last one, which the
//! next read drops. Every record read back is checked against the grid: its index in range, its
//! parameters those of its point, a point recorded twice only with the same results. At the end
//! of a sweep (and of a merge) the records are rewritten in point order, atomically and streamed
//! from the file (never all in memory), so a sweep, its shards merged, and a resumed sweep give
//! the same bytes but for `wall_s`.

mod files;
mod merge;
mod table;

pub use files::{DirLock, LOCK, write_atomic};
pub use merge::merge;

use crate::error::SweepError;
use crate::grid::Grid;
use crate::record::Record;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use table::write_csv;

/// The records file of a sweep directory.
pub const RESULTS: &str = "results.jsonl";
/// The flat table written beside it.
pub const RESULTS_CSV: &str = "results.csv";

/// Version of the results format (2: the header carries the grid).
pub const FORMAT: u32 = 2;

/// The first line of `results.jsonl`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Header {
    /// Format version ([`FORMAT`]).
    pub cdpr_sweep: u32,
    /// [`Grid::digest`] of the grid the records belong to.
    pub grid: String,
    /// Points in the grid (all shards).
    pub points: usize,
    /// The grid itself ([`Grid::to_toml`]), so that a merge checks every record's parameters.
    pub spec: String,
}

impl Header {
    pub fn of(grid: &Grid) -> Self {
        Self {
            cdpr_sweep: FORMAT,
            grid: grid.digest(),
            points: grid.len(),
            spec: grid.to_toml(),
        }
    }
}

/// A record's place in a results file.
#[derive(Debug, Clone, Copy)]
struct Entry {
    point: usize,
    /// Byte offset of its line and the line's length (without the newline).
    start: u64,
    len: usize,
    /// 1-based line number, for messages.
    line: usize,
}

/// A results file read and checked: its header, the grid it names, and where each point's
/// record is (once per point, in file order).
pub struct Scan {
    pub path: PathBuf,
    pub header: Header,
    pub grid: Grid,
    entries: Vec<Entry>,
    /// Length of the file up to its last complete line.
    complete: u64,
}

impl Scan {
    /// The points recorded.
    pub fn points(&self) -> impl Iterator<Item = usize> + '_ {
        self.entries.iter().map(|e| e.point)
    }

    /// Number of points recorded.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

fn results_error(path: &Path, message: String) -> SweepError {
    SweepError::Results {
        path: path.display().to_string(),
        message,
    }
}

/// Reads one line at `entry` of `file`.
fn read_line(file: &mut File, path: &Path, entry: &Entry) -> Result<String, SweepError> {
    let mut buf = vec![0; entry.len];
    file.seek(SeekFrom::Start(entry.start))
        .and_then(|_| file.read_exact(&mut buf))
        .map_err(|e| SweepError::io(path, e))?;
    String::from_utf8(buf)
        .map_err(|_| results_error(path, format!("line {} is not UTF-8", entry.line)))
}

/// The record of `line`, checked against `grid` (the file's own grid).
fn check_record(
    path: &Path,
    line_no: usize,
    line: &str,
    grid: &Grid,
) -> Result<Record, SweepError> {
    let bad = |message: String| results_error(path, format!("line {line_no}: {message}"));
    let record: Record =
        serde_json::from_str(line).map_err(|e| bad(format!("not a record: {e}")))?;
    if record.point >= grid.len() {
        return Err(bad(format!(
            "a record for point {}, but the grid has points 0 … {}",
            record.point,
            grid.len() - 1
        )));
    }
    let expected = crate::record::params(&grid.point(record.point));
    if record.params != expected {
        return Err(bad(format!(
            "point {}'s parameters are {}, the grid's are {}",
            record.point,
            Value::Object(record.params.clone()),
            Value::Object(expected)
        )));
    }
    if !["complete", "failed"].contains(&record.status.as_str()) {
        return Err(bad(format!(
            "status \"{}\": allowed \"complete\" or \"failed\"",
            record.status
        )));
    }
    Ok(record)
}

/// Two records of one point agree but for their wall time.
fn same_results(a: &Record, b: &Record) -> bool {
    let b = Record {
        wall_s: a.wall_s,
        ..b.clone()
    };
    *a == b
}

/// The header `line` of the results file at `path` read and checked: this version's format,
/// a grid it describes, and `expected`'s grid where one is given.
fn checked_header(
    path: &Path,
    line: &str,
    expected: Option<&Grid>,
) -> Result<(Header, Grid), SweepError> {
    let header: Header = (line.ends_with('\n'))
        .then(|| serde_json::from_str(line.trim_end()).ok())
        .flatten()
        .ok_or_else(|| {
            results_error(
                path,
                "not a cdpr-bench sweep's results of this version (no format-2 header line)".into(),
            )
        })?;
    if header.cdpr_sweep != FORMAT {
        return Err(results_error(
            path,
            format!(
                "results format {} (this cdpr-bench reads {FORMAT}): rerun the sweep into a new --out",
                header.cdpr_sweep
            ),
        ));
    }
    let grid = Grid::from_toml_str(&header.spec, &format!("the header of {}", path.display()))?;
    if grid.digest() != header.grid || grid.len() != header.points {
        return Err(results_error(
            path,
            "its header does not describe its grid".into(),
        ));
    }
    if let Some(g) = expected
        && Header::of(g) != header
    {
        return Err(results_error(
            path,
            format!(
                "belongs to another grid (digest {}, {} points; this grid: {}, {} points): \
                 choose another --out or remove it",
                header.grid,
                header.points,
                g.digest(),
                g.len()
            ),
        ));
    }
    Ok((header, grid))
}

/// A point's `record` on line `line_no` that was recorded before (`first`, read back from
/// `file`): kept once if the results agree, an error naming both lines if not.
fn check_repeat(
    path: &Path,
    file: &mut File,
    first: &Entry,
    record: &Record,
    line_no: usize,
) -> Result<(), SweepError> {
    let earlier: Record = serde_json::from_str(&read_line(file, path, first)?)
        .map_err(|e| results_error(path, format!("line {}: {e}", first.line)))?;
    if same_results(&earlier, record) {
        Ok(())
    } else {
        Err(results_error(
            path,
            format!(
                "point {} is recorded twice with different results (lines {} and {line_no})",
                record.point, first.line
            ),
        ))
    }
}

/// Reads a results file and checks every record (a torn last line is dropped; a point recorded
/// twice with the same results is kept once; anything else is an error naming the line).
/// `expected`: the grid the file must belong to (a sweep's; None for a merge's inputs).
pub fn scan(path: &Path, expected: Option<&Grid>) -> Result<Scan, SweepError> {
    let file = File::open(path).map_err(|e| SweepError::io(path, e))?;
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let mut line = String::new();
    let mut offset: u64 = 0;
    let read = |reader: &mut BufReader<File>, line: &mut String| {
        line.clear();
        reader.read_line(line).map_err(|e| SweepError::io(path, e))
    };
    let n = read(&mut reader, &mut line)?;
    let (header, grid) = checked_header(path, &line, expected)?;
    offset += n as u64;
    let mut seen: Vec<Option<u32>> = vec![None; grid.len()];
    let mut entries: Vec<Entry> = Vec::new();
    let mut reopened: Option<File> = None;
    let mut line_no = 1;
    loop {
        let n = read(&mut reader, &mut line)?;
        if n == 0 || !line.ends_with('\n') {
            break;
        }
        line_no += 1;
        let text = line.trim_end_matches('\n');
        let record = check_record(path, line_no, text, &grid)?;
        let entry = Entry {
            point: record.point,
            start: offset,
            len: text.len(),
            line: line_no,
        };
        offset += n as u64;
        match seen[record.point] {
            None => {
                seen[record.point] = Some(entries.len() as u32);
                entries.push(entry);
            }
            Some(k) => {
                let file = match &mut reopened {
                    Some(f) => f,
                    None => reopened.insert(File::open(path).map_err(|e| SweepError::io(path, e))?),
                };
                check_repeat(path, file, &entries[k as usize], &record, line_no)?;
            }
        }
    }
    Ok(Scan {
        path: path.to_path_buf(),
        header,
        grid,
        entries,
        complete: offset,
    })
}

/// The records already in `dir` for `grid`, checked (None if there is no results file yet).
pub fn existing(dir: &Path, grid: &Grid) -> Result<Option<Scan>, SweepError> {
    let path = dir.join(RESULTS);
    if !path.exists() {
        return Ok(None);
    }
    scan(&path, Some(grid)).map(Some)
}

/// Appends records to `dir/results.jsonl` as they finish.
pub struct Appender {
    file: File,
    path: PathBuf,
}

impl Appender {
    /// Opens the results file for appending: a new one gets `header`; an existing one (already
    /// scanned) is cut after its last complete line, dropping a torn record.
    pub fn open(dir: &Path, header: &Header, existing: Option<&Scan>) -> Result<Self, SweepError> {
        let path = dir.join(RESULTS);
        let io = |e| SweepError::io(&path, e);
        let file = match existing {
            Some(scan) => {
                let file = OpenOptions::new().write(true).open(&path).map_err(io)?;
                file.set_len(scan.complete).map_err(io)?;
                drop(file);
                OpenOptions::new().append(true).open(&path).map_err(io)?
            }
            None => {
                let mut line = serde_json::to_string(header).expect("a header serialises");
                line.push('\n');
                write_atomic(&path, |w| w.write_all(line.as_bytes()))?;
                OpenOptions::new().append(true).open(&path).map_err(io)?
            }
        };
        Ok(Self { file, path })
    }

    /// Appends one record as one line, written in one call.
    pub fn push(&mut self, record: &Record) -> Result<(), SweepError> {
        let mut line = serde_json::to_string(record).expect("a record serialises");
        line.push('\n');
        self.file
            .write_all(line.as_bytes())
            .and_then(|_| self.file.flush())
            .map_err(|e| SweepError::io(&self.path, e))
    }
}

/// Rewrites `dir/results.jsonl` in point order and writes `dir/results.csv`, each atomically,
/// streaming the records from the file; `stop` abandons the rewrite (the appended file stays as
/// it is, complete and readable).
pub fn finish(dir: &Path, grid: &Grid, stop: Option<&AtomicBool>) -> Result<(), SweepError> {
    let scan = scan(&dir.join(RESULTS), Some(grid))?;
    write_sorted(dir, &[scan], stop)
}

/// Writes the records of `scans` (one grid; each point at most once across them) in point order
/// into `out/results.jsonl`, then `out/results.csv` from it.
fn write_sorted(out: &Path, scans: &[Scan], stop: Option<&AtomicBool>) -> Result<(), SweepError> {
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let header = &scans[0].header;
    let mut order: Vec<(usize, usize, Entry)> = scans
        .iter()
        .enumerate()
        .flat_map(|(k, s)| s.entries.iter().map(move |e| (e.point, k, *e)))
        .collect();
    order.sort_by_key(|&(point, _, _)| point);
    let mut files = scans
        .iter()
        .map(|s| File::open(&s.path).map_err(|e| SweepError::io(&s.path, e)))
        .collect::<Result<Vec<_>, _>>()?;
    let path = out.join(RESULTS);
    write_atomic(&path, |w| {
        serde_json::to_writer(&mut *w, header)?;
        w.write_all(b"\n")?;
        for &(_, k, entry) in &order {
            if stopped() {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::Interrupted,
                    "interrupted",
                ));
            }
            let line =
                read_line(&mut files[k], &scans[k].path, &entry).map_err(std::io::Error::other)?;
            w.write_all(line.as_bytes())?;
            w.write_all(b"\n")?;
        }
        Ok(())
    })?;
    write_csv(out, stop)
}

/// Every record of a results file, checked, in file order (held in memory: for callers that
/// want them all, like the Python module).
pub fn read_records(path: &Path) -> Result<(Header, Vec<Record>), SweepError> {
    let scan = scan(path, None)?;
    let mut file = File::open(path).map_err(|e| SweepError::io(path, e))?;
    let records = scan
        .entries
        .iter()
        .map(|e| {
            serde_json::from_str(&read_line(&mut file, path, e)?)
                .map_err(|err| results_error(path, format!("line {}: {err}", e.line)))
        })
        .collect::<Result<Vec<Record>, _>>()?;
    Ok((scan.header, records))
}

/// Writes `records` (e.g. gathered from Dask workers) for `grid` into `out` as a sweep does,
/// each checked against the grid.
pub fn write_records(out: &Path, grid: &Grid, records: &[Record]) -> Result<(), SweepError> {
    std::fs::create_dir_all(out).map_err(|e| SweepError::io(out, e))?;
    let _lock = DirLock::acquire(out, "write_results")?;
    let header = Header::of(grid);
    let path = out.join(RESULTS);
    let mut text = serde_json::to_string(&header).expect("a header serialises");
    text.push('\n');
    for r in records {
        text.push_str(&serde_json::to_string(r).expect("a record serialises"));
        text.push('\n');
    }
    write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
    // Checked as any results file is (points in range, parameters, duplicates), then sorted.
    let scan = scan(&path, Some(grid))?;
    write_sorted(out, &[scan], None)
}
