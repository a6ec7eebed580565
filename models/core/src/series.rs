//! Sampled output channels of a run, stored column by column (each channel one contiguous
//! array, appended once per sample) so that an analysis reads a channel as a slice, without a
//! strided copy out of 22-wide rows.

use crate::channel::Channel;

/// The memory of a finished series, handed to the next run (see [`TimeSeries::with_buffer`]).
#[derive(Debug, Default)]
pub struct SeriesBuffer(Vec<Vec<f64>>);

/// Named channels sampled on a common time grid; channel 0 is the time t [s].
#[derive(Debug, Clone)]
pub struct TimeSeries {
    names: Vec<String>,
    columns: Vec<Vec<f64>>,
    /// One row being filled (see [`TimeSeries::push_row_with`]).
    scratch: Vec<f64>,
}

/// Two series are equal when their channels and samples are.
impl PartialEq for TimeSeries {
    fn eq(&self, other: &Self) -> bool {
        self.names == other.names && self.columns == other.columns
    }
}

impl TimeSeries {
    /// An empty series with room for `rows` samples, in `buffer`'s memory (from
    /// [`TimeSeries::into_buffer`] of a previous run; `SeriesBuffer::default()` for fresh
    /// memory): a sweep then allocates and faults in its output memory once, not once per run.
    pub fn with_buffer(names: Vec<String>, rows: usize, buffer: SeriesBuffer) -> Self {
        let mut columns = buffer.0;
        columns.resize_with(names.len(), Vec::new);
        for column in &mut columns {
            column.clear();
            column.reserve(rows);
        }
        let scratch = vec![0.0; names.len()];
        Self {
            names,
            columns,
            scratch,
        }
    }

    /// An empty series of these channels.
    pub fn new(names: Vec<String>) -> Self {
        Self::with_buffer(names, 0, SeriesBuffer::default())
    }

    /// The sample storage, for reuse by the next run.
    pub fn into_buffer(self) -> SeriesBuffer {
        SeriesBuffer(self.columns)
    }

    /// Channel names, in column order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Number of channels.
    pub fn width(&self) -> usize {
        self.names.len()
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends one sample; `row` has one value per channel.
    pub fn push_row(&mut self, row: &[f64]) {
        assert_eq!(row.len(), self.width(), "row width");
        for (column, &v) in self.columns.iter_mut().zip(row) {
            column.push(v);
        }
    }

    /// Appends one sample written by `fill` into a row of the series' width.
    pub fn push_row_with(&mut self, fill: impl FnOnce(&mut [f64])) {
        fill(&mut self.scratch);
        for (column, &v) in self.columns.iter_mut().zip(&self.scratch) {
            column.push(v);
        }
    }

    /// Sample `i`, all channels, copied into `row` (of the series' width).
    pub fn copy_row(&self, i: usize, row: &mut [f64]) {
        for (slot, column) in row.iter_mut().zip(&self.columns) {
            *slot = column[i];
        }
    }

    /// Sample `i`, all channels.
    pub fn row(&self, i: usize) -> Vec<f64> {
        self.columns.iter().map(|c| c[i]).collect()
    }

    /// Index of `channel`, if the run has it.
    pub fn index(&self, channel: Channel) -> Option<usize> {
        self.index_named(&channel.name())
    }

    /// Index of the channel called `name` (a model's own channel).
    pub fn index_named(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The samples of `channel`, if the run has it (every run has [`Channel::COMMON`] and
    /// [`Channel::ENERGY`]; the massive-cable models also [`Channel::CABLE`]).
    pub fn channel(&self, channel: Channel) -> Option<&[f64]> {
        self.channel_named(&channel.name())
    }

    /// The samples of the channel called `name` (a model's own channel), if there is one.
    pub fn channel_named(&self, name: &str) -> Option<&[f64]> {
        Some(&self.columns[self.index_named(name)?])
    }

    /// The samples of channel `j` (in column order).
    pub fn column_at(&self, j: usize) -> &[f64] {
        &self.columns[j]
    }

    /// A copy of `channel`, if the run has it.
    pub fn column(&self, channel: Channel) -> Option<Vec<f64>> {
        self.channel(channel).map(<[f64]>::to_vec)
    }

    /// A copy of the channel called `name` (a model's own channel), if there is one.
    pub fn column_named(&self, name: &str) -> Option<Vec<f64>> {
        self.channel_named(name).map(<[f64]>::to_vec)
    }
}
