//! What can go wrong with a sweep, each naming the file, key, point or shard at fault. All but
//! [`SweepError::Io`] while writing are found before any point runs.

/// Why a sweep could not start, resume or merge.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error("cannot read or write {path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// The grid file is malformed: bad TOML, an axis with no points, a bad range or combine.
    #[error("grid {origin}: {message}")]
    Grid { origin: String, message: String },
    /// A point's scenario is invalid (unknown key, value outside its range).
    #[error("point {index} ({params}): {message}")]
    Point {
        index: usize,
        params: String,
        message: String,
    },
    /// `--shard I/N` outside 0 ≤ I < N, N ≥ 1.
    #[error("--shard {given}: {message}")]
    Shard { given: String, message: String },
    /// No worker thread asked for.
    #[error("--jobs 0: allowed an integer ≥ 1")]
    Jobs,
    /// A results file that is not this grid's, or cannot be read.
    #[error("results file {path}: {message}")]
    Results { path: String, message: String },
}

impl SweepError {
    pub(crate) fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        SweepError::Io {
            path: path.display().to_string(),
            source,
        }
    }
}
