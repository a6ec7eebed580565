//! Sampled output channels of a run, stored row by row (one contiguous buffer, appended once per
//! sample) and read by column for analysis.

use crate::channel::Channel;

/// Named channels sampled on a common time grid; channel 0 is the time t [s].
#[derive(Debug, Clone, PartialEq)]
pub struct TimeSeries {
    names: Vec<String>,
    data: Vec<f64>,
}

impl TimeSeries {
    /// An empty series with room for `rows` samples, in `buffer`'s memory (e.g. from
    /// [`TimeSeries::into_buffer`] of a previous run; `Vec::new()` for fresh memory): a sweep then
    /// allocates and faults in its output memory once, not once per run.
    pub fn with_buffer(names: Vec<String>, rows: usize, mut buffer: Vec<f64>) -> Self {
        buffer.clear();
        buffer.reserve(rows * names.len());
        Self {
            names,
            data: buffer,
        }
    }

    /// The sample storage, for reuse by the next run.
    pub fn into_buffer(self) -> Vec<f64> {
        self.data
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
        self.data.len().checked_div(self.width()).unwrap_or(0)
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Appends one sample; `row` has one value per channel.
    pub fn push_row(&mut self, row: &[f64]) {
        assert_eq!(row.len(), self.width(), "row width");
        self.data.extend_from_slice(row);
    }

    /// Appends one sample written in place by `fill` (no intermediate row, no copy).
    pub fn push_row_with(&mut self, fill: impl FnOnce(&mut [f64])) {
        let start = self.data.len();
        self.data.resize(start + self.width(), 0.0);
        fill(&mut self.data[start..]);
    }

    /// Sample `i`, all channels.
    pub fn row(&self, i: usize) -> &[f64] {
        let w = self.width();
        &self.data[i * w..(i + 1) * w]
    }

    /// Index of `channel`, if the run has it.
    pub fn index(&self, channel: Channel) -> Option<usize> {
        self.index_named(channel.name())
    }

    /// Index of the channel called `name` (a model's own channel).
    pub fn index_named(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// A copy of `channel`, if the run has it (every run has [`Channel::COMMON`] and
    /// [`Channel::ENERGY`]; the massive-cable models also [`Channel::CABLE`]).
    pub fn column(&self, channel: Channel) -> Option<Vec<f64>> {
        self.column_named(channel.name())
    }

    /// A copy of the channel called `name` (a model's own channel), if there is one.
    pub fn column_named(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.index_named(name)?;
        Some(
            self.data
                .iter()
                .skip(j)
                .step_by(self.width())
                .copied()
                .collect(),
        )
    }
}
