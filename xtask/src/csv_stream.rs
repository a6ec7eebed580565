//! The time series streamed to its partial CSV while the run goes, formatted and written on a
//! thread of its own: the integration hands over each kept row's numbers in batches, so the
//! text formatting (which cost more than the FE paper run's integration at one sample per step)
//! runs beside it on the second core. A failed write stops the run ([`STOP`]) and is reported
//! with the file's path; the rows written before it are kept.

use crate::output::csv_row;
use crate::simulate::STOP;
use anyhow::{Context, Result, bail};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, SyncSender, channel, sync_channel};
use std::thread::JoinHandle;

/// Numbers per batch handed to the writer (128 KiB; ~800 rows of the paper's 20 channels).
const BATCH: usize = 16 * 1024;

/// Batches in flight: the integration waits for the writer beyond this (memory stays bounded;
/// the writer hands each written batch back, so at most this many plus two are ever allocated).
const IN_FLIGHT: usize = 4;

/// What the writer thread hands back: the file and the error that stopped its writing.
type WriterEnd = (BufWriter<File>, Option<std::io::Error>);

/// Where rows go: to the writer thread while the run goes, then straight to the file.
enum Sink {
    Thread {
        batches: SyncSender<Vec<f64>>,
        writer: JoinHandle<WriterEnd>,
    },
    Direct(BufWriter<File>),
    /// Between the two (only while settling).
    Settling,
}

/// The time series written as the run samples it, every `every`-th row.
pub(crate) struct CsvStream {
    sink: Sink,
    batch: Vec<f64>,
    /// Batches the writer has written, emptied, for reuse.
    spare: Option<Receiver<Vec<f64>>>,
    /// The text of one row, for rows written directly.
    line: String,
    width: usize,
    path: PathBuf,
    every: usize,
    rows: usize,
    error: Option<std::io::Error>,
}

impl CsvStream {
    /// The partial file at `path` with its header line, and its writer thread started.
    pub(crate) fn create(path: PathBuf, headings: &[String], every: usize) -> Result<Self> {
        let file = File::create(&path).with_context(|| format!("creating {}", path.display()))?;
        let mut writer = BufWriter::with_capacity(1 << 16, file);
        writeln!(writer, "{}", headings.join(","))
            .with_context(|| format!("writing {}", path.display()))?;
        let width = headings.len();
        let (batches, received) = sync_channel::<Vec<f64>>(IN_FLIGHT);
        let (give_back, spare) = channel::<Vec<f64>>();
        let writer = std::thread::Builder::new()
            .name("csv writer".into())
            .spawn(move || {
                let mut error = None;
                let mut line = String::with_capacity(24 * width);
                for mut batch in received {
                    for row in batch.chunks_exact(width.max(1)) {
                        if error.is_some() {
                            break;
                        }
                        line.clear();
                        csv_row(&mut line, row);
                        if let Err(e) = writer.write_all(line.as_bytes()) {
                            error = Some(e);
                            STOP.store(true, Ordering::Relaxed);
                        }
                    }
                    batch.clear();
                    // The stream may have stopped listening (it settled): nothing to reuse.
                    let _ = give_back.send(batch);
                }
                (writer, error)
            })
            .with_context(|| format!("starting the writer of {}", path.display()))?;
        Ok(Self {
            sink: Sink::Thread { batches, writer },
            batch: Vec::with_capacity(BATCH + width),
            spare: Some(spare),
            line: String::with_capacity(24 * width),
            width,
            path,
            every,
            rows: 0,
            error: None,
        })
    }

    pub(crate) fn push(&mut self, row: &[f64]) {
        if self.rows.is_multiple_of(self.every) && self.error.is_none() {
            if row.len() != self.width {
                // Not a row of this header's width: written as it is, after the rows before it.
                self.settle();
            }
            let mut writer_ended = false;
            match &mut self.sink {
                Sink::Thread { batches, .. } => {
                    self.batch.extend_from_slice(row);
                    if self.batch.len() >= BATCH {
                        let next = self
                            .spare
                            .as_ref()
                            .and_then(|s| s.try_recv().ok())
                            .unwrap_or_else(|| Vec::with_capacity(BATCH + self.width));
                        let full = std::mem::replace(&mut self.batch, next);
                        writer_ended = batches.send(full).is_err();
                    }
                }
                Sink::Direct(writer) => {
                    self.line.clear();
                    csv_row(&mut self.line, row);
                    if let Err(e) = writer.write_all(self.line.as_bytes()) {
                        self.error = Some(e);
                        STOP.store(true, Ordering::Relaxed);
                    }
                }
                Sink::Settling => {}
            }
            if writer_ended {
                // Its error is read when it is joined.
                self.settle();
            }
        }
        self.rows += 1;
    }

    /// Hands the writer its last batch and waits for it; rows are written directly after.
    fn settle(&mut self) {
        let sink = std::mem::replace(&mut self.sink, Sink::Settling);
        let Sink::Thread { batches, writer } = sink else {
            self.sink = sink;
            return;
        };
        if !self.batch.is_empty() {
            // A closed channel means the writer has stopped: its error says why.
            let _ = batches.send(std::mem::take(&mut self.batch));
        }
        drop(batches);
        self.spare = None;
        match writer.join() {
            Ok((file, error)) => {
                self.error = self.error.take().or(error);
                self.sink = Sink::Direct(file);
            }
            Err(_) => {
                self.error = Some(std::io::Error::other("the CSV writer thread panicked"));
            }
        }
    }

    /// The write error, as the run's reason (every row handed over so far written first).
    pub(crate) fn failure(&mut self) -> Option<String> {
        self.settle();
        self.error
            .as_ref()
            .map(|e| format!("writing {}: {e}", self.path.display()))
    }

    /// Writes the rows the stream has not seen (those of a failing step), then renames the file
    /// into `target`. After a failed write the partial file stays as it is.
    pub(crate) fn finish(
        mut self,
        series: &cdpr_bench::core::series::TimeSeries,
        target: &Path,
    ) -> Result<()> {
        self.settle();
        let mut row = vec![0.0; series.width()];
        for i in self.rows..series.len() {
            series.copy_row(i, &mut row);
            self.push(&row);
        }
        if let Some(e) = self.failure() {
            bail!("{e}");
        }
        let Sink::Direct(writer) = self.sink else {
            bail!("writing {}: the writer was lost", self.path.display());
        };
        let path = self.path;
        let file = writer
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all().map(|_| f))
            .with_context(|| format!("writing {}", path.display()))?;
        drop(file);
        std::fs::rename(&path, target)
            .with_context(|| format!("renaming into {}", target.display()))
    }
}
