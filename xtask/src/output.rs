//! Files written atomically (temporary file in the same directory, then rename), so a reader never
//! sees half a file and an interrupted run never leaves one; and the progress bar.

use anyhow::{Context, Result};
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

/// One CSV row of `values` appended to `line`: floats in Rust's shortest round-trip form, so the
/// file is bit-reproducible and loses nothing.
pub fn csv_row(line: &mut String, values: &[f64]) {
    use std::fmt::Write as _;
    for (k, v) in values.iter().enumerate() {
        if k > 0 {
            line.push(',');
        }
        let _ = write!(line, "{v}");
    }
    line.push('\n');
}

/// Pretty JSON of `value`, newline-terminated.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })
}

/// Progress of a long run: a bar with its ETA on a terminal; elsewhere (CI logs, batch jobs) a
/// plain line at every tenth of the work with the time to go at the rate so far, so a log shows
/// how far a run got and how long it will take.
pub struct Progress {
    label: String,
    bar: Option<ProgressBar>,
    start: std::time::Instant,
    next_tenth: u32,
}

impl Progress {
    pub fn new(label: &str) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
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
        });
        Self {
            label: label.to_owned(),
            bar,
            start: std::time::Instant::now(),
            next_tenth: 1,
        }
    }

    /// The fraction `done` of the work is done.
    pub fn set(&mut self, done: f64) {
        match &self.bar {
            Some(bar) => bar.set_position((done * 1000.0) as u64),
            None => {
                while self.next_tenth <= 10 && done >= f64::from(self.next_tenth) / 10.0 {
                    let elapsed = self.start.elapsed().as_secs_f64();
                    // At the rate so far: elapsed × (1 − f) / f to go.
                    let eta = elapsed * (1.0 - done) / done;
                    eprintln!(
                        "{}: {} % after {elapsed:.1} s, about {eta:.1} s to go",
                        self.label,
                        10 * self.next_tenth,
                    );
                    self.next_tenth += 1;
                }
            }
        }
    }

    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
