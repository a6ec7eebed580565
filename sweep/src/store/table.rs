//! `results.csv`: the records of `results.jsonl` flattened into one table (nested metrics
//! dotted, lists as JSON, RFC 4180 quoting), written atomically after the records are sorted.

use super::files::write_atomic;
use super::{RESULTS, RESULTS_CSV, results_error};
use crate::error::SweepError;
use crate::record::Record;
use serde_json::{Map, Value};
use std::collections::BTreeSet;
use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// `out/results.csv` from `out/results.jsonl` (in point order): two passes, one for the columns
/// (the union over the records), one for the rows.
pub(super) fn write_csv(out: &Path, stop: Option<&AtomicBool>) -> Result<(), SweepError> {
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
