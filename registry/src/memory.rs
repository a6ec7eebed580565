//! What a run's samples and metrics need in memory, and what the machine has: the guard that
//! refuses a run (or a sweep's worker count) before it starts rather than letting the OS kill it.

use crate::build::build;
use cdpr_analysis::metrics::memory_estimate;
use cdpr_core::runner::channel_names;
use cdpr_core::scenario::Scenario;

/// Share of the machine's available memory the runs at once may take.
pub const MEMORY_SHARE: f64 = 0.5;

/// Output samples of a run of `scenario`.
pub fn samples(scenario: &Scenario) -> f64 {
    let sim = &scenario.simulation;
    (sim.t_final / sim.sample_period).round() + 1.0
}

/// Peak memory of a run of `scenario` and its metrics [B]
/// ([`cdpr_analysis::metrics::memory_estimate`] for its samples and its model's channels).
pub fn run_memory(scenario: &Scenario) -> Result<f64, crate::Error> {
    let channels = if scenario.robot.anchors.is_some() {
        crate::spatial::spatial_channels(scenario)?
    } else {
        channel_names(&*build(scenario)?).len()
    };
    Ok(memory_estimate(samples(scenario), channels))
}

/// The environment variable that caps the memory runs may plan for [B] (e.g. a batch job's
/// allocation, which the node's MemAvailable does not know).
pub const LIMIT_VARIABLE: &str = "CDPR_MEMORY_LIMIT";

/// The memory runs may plan for [B]: the smallest of the machine's MemAvailable, what the
/// process's cgroup still allows (a container or a Slurm job) and `CDPR_MEMORY_LIMIT`; None
/// where none of them can be read.
pub fn available_memory() -> Option<f64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|info| {
            let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
            let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(kib * 1024.0)
        });
    let read = |name: &str| -> Option<f64> {
        std::fs::read_to_string(format!("/sys/fs/cgroup/{name}"))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    let cgroup = read("memory.max").map(|max| max - read("memory.current").unwrap_or(0.0));
    let limit = std::env::var(LIMIT_VARIABLE)
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|v| *v > 0.0);
    [meminfo, cgroup, limit]
        .into_iter()
        .flatten()
        .min_by(f64::total_cmp)
}
