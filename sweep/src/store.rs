//! `results.jsonl` and `results.csv`. The JSONL file opens with a header naming the grid (its
//! digest and point count); each finished point appends one line written in one call, so a kill
//! at any instant leaves complete lines and at most a torn last one, which the next read drops.
//! At the end of a sweep (and of a merge) the records are rewritten in point order, atomically,
//! so a sweep, its shards merged, and a resumed sweep give the same bytes but for `wall_s`.

use crate::error::SweepError;
use crate::grid::Grid;
use crate::record::Record;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The records file of a sweep directory.
pub const RESULTS: &str = "results.jsonl";
/// The flat table written beside it.
pub const RESULTS_CSV: &str = "results.csv";

/// The first line of `results.jsonl`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Header {
    /// Format version.
    pub cdpr_sweep: u32,
    /// [`Grid::digest`] of the grid the records belong to.
    pub grid: String,
    /// Points in the grid (all shards).
    pub points: usize,
}

impl Header {
    pub fn of(grid: &Grid) -> Self {
        Self {
            cdpr_sweep: 1,
            grid: grid.digest(),
            points: grid.len(),
        }
    }
}

/// Reads a results file: its header and records (a torn last line dropped). Any other line that
/// is not a record is an error naming the line.
pub fn read(path: &Path) -> Result<(Header, Vec<Record>), SweepError> {
    let text = std::fs::read_to_string(path).map_err(|e| SweepError::io(path, e))?;
    let bad = |message: String| SweepError::Results {
        path: path.display().to_string(),
        message,
    };
    let complete = match text.rfind('\n') {
        Some(end) => &text[..=end],
        None => "",
    };
    let mut lines = complete.lines();
    let header: Header = lines
        .next()
        .and_then(|l| serde_json::from_str(l).ok())
        .ok_or_else(|| bad("not a cdpr-bench sweep's results (no header line)".into()))?;
    let records = lines
        .enumerate()
        .map(|(k, line)| {
            serde_json::from_str::<Record>(line)
                .map_err(|e| bad(format!("line {} is not a record: {e}", k + 2)))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((header, records))
}

/// The records already in `dir` for `grid` (none if the file does not exist); a results file of
/// another grid is an error.
pub fn existing(dir: &Path, grid: &Grid) -> Result<Vec<Record>, SweepError> {
    let path = dir.join(RESULTS);
    if !path.exists() {
        return Ok(Vec::new());
    }
    let (header, records) = read(&path)?;
    let expected = Header::of(grid);
    if header != expected {
        return Err(SweepError::Results {
            path: path.display().to_string(),
            message: format!(
                "belongs to another grid (digest {}, {} points; this grid: {}, {} points): \
                 choose another --out or remove it",
                header.grid, header.points, expected.grid, expected.points
            ),
        });
    }
    Ok(records)
}

/// Appends records to `dir/results.jsonl` as they finish.
pub struct Appender {
    file: File,
    path: PathBuf,
}

impl Appender {
    /// Rewrites the file with `header` and `records` (dropping a torn line), then opens it for
    /// appending.
    pub fn open(dir: &Path, header: &Header, records: &[Record]) -> Result<Self, SweepError> {
        let path = dir.join(RESULTS);
        write_atomic(&path, &jsonl(header, records))?;
        let file = OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| SweepError::io(&path, e))?;
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

/// Writes `dir/results.jsonl` in point order and `dir/results.csv`, each atomically.
pub fn finish(dir: &Path, header: &Header, records: &mut [Record]) -> Result<(), SweepError> {
    records.sort_by_key(|r| r.point);
    write_atomic(&dir.join(RESULTS), &jsonl(header, records))?;
    write_atomic(&dir.join(RESULTS_CSV), &csv(records))
}

/// Combines the shards' results files into `out`: one grid (equal headers), each point once
/// (a point recorded twice must agree but for `wall_s`).
pub fn merge(inputs: &[PathBuf], out: &Path) -> Result<(Header, usize), SweepError> {
    let mut header: Option<(Header, PathBuf)> = None;
    let mut merged: BTreeMap<usize, Record> = BTreeMap::new();
    for dir in inputs {
        let path = if dir.is_dir() {
            dir.join(RESULTS)
        } else {
            dir.clone()
        };
        let (h, records) = read(&path)?;
        match &header {
            None => header = Some((h, path.clone())),
            Some((first, first_path)) if *first != h => {
                return Err(SweepError::Results {
                    path: path.display().to_string(),
                    message: format!(
                        "is of another grid than {} (digest {} vs {})",
                        first_path.display(),
                        h.grid,
                        first.grid
                    ),
                });
            }
            Some(_) => {}
        }
        for r in records {
            if let Some(seen) = merged.get(&r.point) {
                let same = Record {
                    wall_s: seen.wall_s,
                    ..r.clone()
                };
                if same != *seen {
                    return Err(SweepError::Results {
                        path: path.display().to_string(),
                        message: format!(
                            "point {} is recorded differently in another input",
                            r.point
                        ),
                    });
                }
                continue;
            }
            merged.insert(r.point, r);
        }
    }
    let Some((header, _)) = header else {
        return Err(SweepError::Results {
            path: out.display().to_string(),
            message: "--merge needs at least one results file".into(),
        });
    };
    std::fs::create_dir_all(out).map_err(|e| SweepError::io(out, e))?;
    let mut records: Vec<Record> = merged.into_values().collect();
    finish(out, &header, &mut records)?;
    Ok((header, records.len()))
}

fn jsonl(header: &Header, records: &[Record]) -> String {
    let mut text = serde_json::to_string(header).expect("a header serialises");
    text.push('\n');
    for r in records {
        text.push_str(&serde_json::to_string(r).expect("a record serialises"));
        text.push('\n');
    }
    text
}

/// The flat table: point, status, the parameters, t_reached, every scalar metric (nested ones
/// dotted; lists as JSON), error, wall_s. Columns are the union over the records, in key order.
fn csv(records: &[Record]) -> String {
    let flat: Vec<Map<String, Value>> = records.iter().map(flatten).collect();
    let mut params: Vec<&String> = records.iter().flat_map(|r| r.params.keys()).collect();
    params.sort();
    params.dedup();
    let mut metrics: Vec<&String> = flat.iter().flat_map(|m| m.keys()).collect();
    metrics.sort();
    metrics.dedup();
    let mut out = String::from("point,status");
    for p in &params {
        out.push(',');
        out.push_str(&quote(p));
    }
    out.push_str(",t_reached");
    for m in &metrics {
        out.push(',');
        out.push_str(&quote(m));
    }
    out.push_str(",error,wall_s\n");
    for (r, f) in records.iter().zip(&flat) {
        out.push_str(&format!("{},{}", r.point, r.status));
        for p in &params {
            out.push(',');
            out.push_str(&cell(r.params.get(*p)));
        }
        out.push_str(&format!(",{}", r.t_reached));
        for m in &metrics {
            out.push(',');
            out.push_str(&cell(f.get(*m)));
        }
        out.push(',');
        out.push_str(&quote(r.error.as_deref().unwrap_or("")));
        out.push_str(&format!(",{}\n", r.wall_s));
    }
    out
}

fn flatten(r: &Record) -> Map<String, Value> {
    fn walk(prefix: &str, v: &Value, out: &mut Map<String, Value>) {
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
            v => {
                out.insert(prefix.to_string(), v.clone());
            }
        }
    }
    let mut out = Map::new();
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

/// Writes `text` to `path` through a temporary file in the same directory and a rename.
fn write_atomic(path: &Path, text: &str) -> Result<(), SweepError> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let write = || -> std::io::Result<()> {
        let mut f = File::create(&tmp)?;
        f.write_all(text.as_bytes())?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    };
    write().map_err(|e| SweepError::io(path, e))
}
