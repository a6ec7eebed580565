//! The studies the report is made of, as library functions a Rust (or, through the registry's
//! types, a Python) user can call: each computes its runs and returns data and the text of its
//! tables; the command line (`xtask`) only parses arguments, calls these, writes the files and
//! draws the figures.
//!
//! | study | module | command |
//! |---|---|---|
//! | the paper on every model, checked against MODELS.md §8 | [`paper`] | `cargo xtask report` |
//! | every controller on every model (the leaderboard) | [`control`] | `cargo xtask control` |
//! | a spatial robot's tension distributions at a pose | [`distribution`] | `cargo xtask distribution` |
//! | firmware flex compensation on sagging lines, over a grid | [`flex_error`] | `cargo xtask flex-error` |
//! | every input shaper on every model | [`shaping`] | `cargo xtask shaping` |
//! | a spatial robot's modes at a pose, with their directions | [`spatial_modes`] | `cargo xtask modes --at X,Y,Z` |
//! | a spatial robot's move, every controller × distribution | [`spatial_moves`] | `cargo xtask spatial-moves` |
//! | what the lines' mass does to a printer: mode maps, flex error, leaderboard in 3-D | [`spatial_printers`] | `cargo xtask spatial` |
//! | closed- and open-loop modes, the axial-damping sweep | [`modes`] | `cargo xtask modes` |
//! | effector mass × move time grids | [`sweeps`] | part of the report |
//!
//! Runs are independent and go to every core ([`pool::map`]); results keep the jobs' order, so
//! a study's output does not depend on the machine.

pub mod control;
pub mod distribution;
pub mod flex_error;
pub mod modes;
pub mod paper;
pub mod paper_report;
pub mod pool;
pub mod print_study;
pub mod repeated_modes;
pub mod samples;
pub mod shaping;
pub mod spatial_modes;
pub mod spatial_moves;
pub mod spatial_printers;
pub mod sweeps;

/// Why a study stopped.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A scenario the study derived was refused (the message names the key).
    #[error(transparent)]
    Scenario(#[from] cdpr_bench::core::scenario::ScenarioError),
    /// A run, an analysis or a model build of the registry failed.
    #[error(transparent)]
    Bench(#[from] cdpr_bench::Error),
    /// A named run or analysis of the study failed; the message says which and why.
    #[error("{0}")]
    Failed(String),
    /// A parameter sweep failed.
    #[error("{what}: {source}")]
    Sweep {
        what: String,
        source: cdpr_sweep::SweepError,
    },
    /// A worker thread panicked before finishing its run (its job has no result).
    #[error("a worker panicked before finishing its run")]
    WorkerPanicked,
}

/// A study's result.
pub type Result<T> = std::result::Result<T, StudyError>;
