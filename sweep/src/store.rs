//! `results.jsonl` and `results.csv`. The JSONL file opens with a header naming the grid (its
//! digest, point count and canonical text); each finished point appends one line written in one
//! call, so a kill at any instant leaves complete lines and at most a torn last one, which the
//! next read drops. Every record read back is checked against the grid: its index in range, its
//! parameters those of its point, a point recorded twice only with the same results. At the end
//! of a sweep (and of a merge) the records are rewritten in point order, atomically and streamed
//! from the file (never all in memory), so a sweep, its shards merged, and a resumed sweep give
//! the same bytes but for `wall_s`.

use crate::error::SweepError;
use crate::grid::Grid;
use crate::record::Record;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::collections::BTreeSet;
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

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

/// `out/results.csv` from `out/results.jsonl` (in point order): two passes, one for the columns
/// (the union over the records), one for the rows.
fn write_csv(out: &Path, stop: Option<&AtomicBool>) -> Result<(), SweepError> {
    let path = out.join(RESULTS);
    let records = |each: &mut dyn FnMut(Record) -> std::io::Result<()>| -> Result<(), SweepError> {
        let file = File::open(&path).map_err(|e| SweepError::io(&path, e))?;
        for (k, line) in BufReader::new(file).lines().enumerate().skip(1) {
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Err(SweepError::io(
                    &path,
                    std::io::Error::new(std::io::ErrorKind::Interrupted, "interrupted"),
                ));
            }
            let line = line.map_err(|e| SweepError::io(&path, e))?;
            let record: Record = serde_json::from_str(&line)
                .map_err(|e| results_error(&path, format!("line {}: {e}", k + 1)))?;
            each(record).map_err(|e| SweepError::io(&path, e))?;
        }
        Ok(())
    };
    let mut params = BTreeSet::new();
    let mut metrics = BTreeSet::new();
    records(&mut |r| {
        params.extend(r.params.keys().cloned());
        metrics.extend(flatten(&r).into_iter().map(|(k, _)| k));
        Ok(())
    })?;
    let csv_path = out.join(RESULTS_CSV);
    let mut rows: Vec<u8> = Vec::new();
    let mut head = String::from("point,status");
    for p in &params {
        head.push(',');
        head.push_str(&quote(p));
    }
    head.push_str(",t_reached");
    for m in &metrics {
        head.push(',');
        head.push_str(&quote(m));
    }
    head.push_str(",error,wall_s\n");
    // The rows go through a temporary file of their own: a study's table can be larger than
    // memory, and the header must come first.
    let tmp = out.join(format!(".{RESULTS_CSV}.rows-{}", std::process::id()));
    {
        let file = File::create(&tmp).map_err(|e| SweepError::io(&tmp, e))?;
        let mut w = BufWriter::with_capacity(1 << 20, file);
        records(&mut |r| {
            rows.clear();
            row(&r, &params, &metrics, &mut rows);
            w.write_all(&rows)
        })?;
        w.flush().map_err(|e| SweepError::io(&tmp, e))?;
    }
    let result = write_atomic(&csv_path, |w| {
        w.write_all(head.as_bytes())?;
        std::io::copy(&mut File::open(&tmp)?, w)?;
        Ok(())
    });
    let _ = std::fs::remove_file(&tmp);
    result
}

/// One CSV row: point, status, the parameters, t_reached, every metric (nested keys dotted,
/// lists as JSON), error, wall_s.
fn row(r: &Record, params: &BTreeSet<String>, metrics: &BTreeSet<String>, out: &mut Vec<u8>) {
    use std::io::Write as _;
    let flat: Map<String, Value> = flatten(r).into_iter().collect();
    let _ = write!(out, "{},{}", r.point, r.status);
    for p in params {
        let _ = write!(out, ",{}", cell(r.params.get(p)));
    }
    let _ = write!(out, ",{}", r.t_reached);
    for m in metrics {
        let _ = write!(out, ",{}", cell(flat.get(m)));
    }
    let _ = writeln!(
        out,
        ",{},{}",
        quote(r.error.as_deref().unwrap_or("")),
        r.wall_s
    );
}

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

fn flatten(r: &Record) -> Vec<(String, Value)> {
    fn walk(prefix: &str, v: &Value, out: &mut Vec<(String, Value)>) {
        match v {
            Value::Object(m) => {
                for (k, v) in m {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&key, v, out);
                }
            }
            v => out.push((prefix.to_string(), v.clone())),
        }
    }
    let mut out = Vec::new();
    walk("", &Value::Object(r.metrics.clone()), &mut out);
    out
}

fn cell(v: Option<&Value>) -> String {
    match v {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => quote(s),
        Some(Value::Number(n)) => n.to_string(),
        Some(Value::Bool(b)) => b.to_string(),
        Some(other) => quote(&other.to_string()),
    }
}

/// RFC 4180 quoting where needed.
fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes `path` through `fill` into a temporary file in the same directory, synced, then
/// renamed into place; a failure removes the temporary file and leaves `path` as it was.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), SweepError> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let write = || -> std::io::Result<()> {
        let mut w = BufWriter::with_capacity(1 << 20, File::create(&tmp)?);
        fill(&mut w)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)
    };
    write().map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        SweepError::io(path, e)
    })
}

/// The lock file of an output directory.
pub const LOCK: &str = ".cdpr-lock";

/// An advisory lock on an output directory, held while a run writes there: a second sweep,
/// merge or simulate into the same directory is refused before it starts, naming the holder
/// (two writers lost or mixed each other's files). The lock file is removed when the lock is
/// dropped, and the OS releases the lock of a process that dies.
pub struct DirLock {
    file: File,
    path: PathBuf,
}

impl DirLock {
    /// Takes the lock of `dir` for `what` (e.g. "sweep shard 0/2"), or says who holds it.
    pub fn acquire(dir: &Path, what: &str) -> Result<Self, SweepError> {
        let path = dir.join(LOCK);
        let io = |e| SweepError::io(&path, e);
        loop {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let mut holder = String::new();
                    let _ = file.read_to_string(&mut holder);
                    return Err(SweepError::Busy {
                        dir: dir.display().to_string(),
                        holder: holder.trim().to_string(),
                    });
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
            }
            // The holder before us may have removed the file between our open and our lock:
            // then we hold a lock nobody else can see; take the lock of the file at the path.
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0)
                .and_then(|_| {
                    file.write_all(format!("{what}, pid {}", std::process::id()).as_bytes())
                })
                .map_err(io)?;
            return Ok(Self { file, path });
        }
    }
}

impl Drop for DirLock {
    /// Removes the lock file while still holding the lock (see [`DirLock::acquire`]).
    fn drop(&mut self) {
        if same_file(&self.file, &self.path) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Whether `path` still names the open `file`.
fn same_file(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (file, path);
        true
    }
}
