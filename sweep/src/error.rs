//! What can go wrong with a sweep, each naming the file, key, point or shard at fault. All but
//! [`SweepError::Io`] while writing are found before any point runs.

/// Why a sweep could not start, resume or merge.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The OS error is part of the message (not a `source`): printed with its chain, it would
    /// otherwise appear twice.
    #[error("cannot read or write {path}: {error}")]
    Io { path: String, error: std::io::Error },
    /// The grid file is malformed: bad TOML, an axis with no points, a bad range or combine,
    /// too many points.
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
    /// A results file that is not this grid's, cannot be read, or holds a record that does not
    /// belong to it.
    #[error("results file {path}: {message}")]
    Results { path: String, message: String },
    /// Another run writes into the same directory.
    #[error(
        "--out {dir} is in use by another run ({holder}): two runs into one directory lose or mix \
         each other's records; wait for it, or choose another --out"
    )]
    Busy { dir: String, holder: String },
    /// The points would need more memory than the machine has.
    #[error("{0}")]
    Memory(String),
    /// Stopped by SIGINT/SIGTERM before any point ran.
    #[error("interrupted while {0}")]
    Interrupted(&'static str),
}

impl SweepError {
    pub(crate) fn io(path: &std::path::Path, error: std::io::Error) -> Self {
        SweepError::Io {
            path: path.display().to_string(),
            error,
        }
    }
}
