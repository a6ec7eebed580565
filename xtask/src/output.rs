//! Files written atomically (temporary file in the same directory, then rename), so a reader never
//! sees half a file and an interrupted run never leaves one; and the progress bar.

use anyhow::{Context, Result};
use cdpr_bench::core::series::TimeSeries;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{BufWriter, IsTerminal, Write};
use std::path::Path;

/// Writes `path` through `fill` into a temporary sibling, then renames it into place.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .context("output path has no file name")?
        .to_string_lossy();
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| -> std::io::Result<()> {
        let mut w = BufWriter::with_capacity(1 << 20, std::fs::File::create(&tmp)?);
        fill(&mut w)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e).with_context(|| format!("writing {}", path.display()));
    }
    std::fs::rename(&tmp, path).with_context(|| format!("renaming into {}", path.display()))
}

/// The series as CSV: a header row, then every `every`-th sample; floats in Rust's shortest
/// round-trip form, so the file is bit-reproducible and loses nothing.
pub fn write_csv(path: &Path, series: &TimeSeries, every: usize) -> Result<()> {
    write_atomic(path, |w| {
        writeln!(w, "{}", series.names().join(","))?;
        for i in (0..series.len()).step_by(every.max(1)) {
            let mut first = true;
            for v in series.row(i) {
                if !first {
                    w.write_all(b",")?;
                }
                first = false;
                write!(w, "{v}")?;
            }
            w.write_all(b"\n")?;
        }
        Ok(())
    })
}

/// Pretty JSON of `value`, newline-terminated.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })
}

/// A progress bar on a terminal, hidden otherwise (CI logs stay clean).
pub fn progress_bar(label: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template(
            "{prefix:>8} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_prefix(label.to_owned());
    bar
}
