//! Parameter studies over any scenario key: a grid file of axes over dotted keys (product or
//! zip), each point run metrics-only on worker threads, one record per point appended to
//! `results.jsonl` as it finishes, interrupted sweeps resumed, deterministic shards
//! (point i → shard i mod N) merged into the same bytes as one machine's sweep.
//!
//! # Examples
//!
//! ```
//! use cdpr_sweep::{Grid, Shard};
//!
//! let grid = Grid::from_toml_str(
//!     r#"
//!     [axes]
//!     "robot.effector_mass" = [0.5, 1.0, 2.0]
//!     "trajectory.t2" = { from = 0.1, to = 0.5, steps = 5 }
//!     "#,
//!     "example",
//! )
//! .unwrap();
//! assert_eq!(grid.len(), 15);
//! // The last axis in key order varies fastest.
//! let p = grid.point(6);
//! assert_eq!(p.values[0].1.as_float(), Some(1.0));
//! assert_eq!(p.values[1].1.as_float(), Some(0.2));
//! let shard: Shard = "1/4".parse().unwrap();
//! assert!(shard.owns(5) && !shard.owns(6));
//! ```

pub mod error;
pub mod grid;
pub mod point;
pub mod record;
pub mod run;
pub mod shard;
pub mod store;

pub use error::SweepError;
pub use grid::{Axis, Combine, Grid, MAX_POINTS, Point, Values};
pub use record::{Record, evaluate, evaluate_into, metrics_map};
pub use run::{Options, Phase, Summary, all_cores, jobs, run};
pub use shard::Shard;
pub use store::{DirLock, Header, merge};
