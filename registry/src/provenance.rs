//! Where a result came from: the scenario as resolved (every default filled, the model's own
//! keys included), the model and integrator, the crate version and the project's git revision.

use crate::config::ModelConfig;
use crate::kind::ModelKind;
use cdpr_core::scenario::{IntegratorKind, Scenario, ScenarioError};
use std::path::Path;
use std::process::Command;

/// The provenance block of a result file.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Provenance {
    /// The scenario as run, with every default filled (the `[model]` section is the chosen
    /// model's kind and its own keys, e.g. `elements = 40` for the lumped model).
    pub scenario: serde_json::Value,
    pub model: ModelKind,
    pub integrator: IntegratorKind,
    /// cdpr-bench's version.
    pub version: &'static str,
    /// The project's git revision (12 hex digits, `+` when the tree had uncommitted changes),
    /// or "unknown" when the binary runs away from its source tree.
    pub revision: String,
}

impl Provenance {
    /// The provenance of a run of `scenario`.
    pub fn of(scenario: &Scenario) -> Result<Self, ScenarioError> {
        let config = ModelConfig::from_scenario(scenario)?;
        let mut value = serde_json::to_value(scenario)
            .map_err(|e| ScenarioError::Syntax(format!("scenario not serialisable: {e}")))?;
        value["model"] = crate::build::resolved_section(&config)?;
        Ok(Self {
            scenario: value,
            model: config.kind,
            integrator: scenario.simulation.integrator,
            version: env!("CARGO_PKG_VERSION"),
            revision: revision(),
        })
    }
}

/// The git revision of the project this binary was built from (not of the working directory):
/// 12 hex digits, with `+` for uncommitted changes to tracked files; "unknown" away from the
/// source tree.
pub fn revision() -> String {
    match project_revision(None) {
        Some((head, true)) => format!("{head}+"),
        Some((head, false)) => head,
        None => "unknown".into(),
    }
}

/// The project's HEAD (12 hex digits) and whether tracked files differ from it, leaving out
/// changes below `ignore` (e.g. the report's own output directory); None away from the source
/// tree.
pub fn project_revision(ignore: Option<&Path>) -> Option<(String, bool)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let git = |args: &[&str]| {
        Command::new("git")
            .arg("-C")
            .arg(&root)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim_end().to_owned())
    };
    let head = git(&["rev-parse", "--short=12", "HEAD"])?;
    // The ignored directory as git names it (relative to the root); none when it lies outside
    // the project, where every change counts.
    let ignored = ignore.and_then(|dir| {
        let (dir, root) = (dir.canonicalize().ok()?, root.canonicalize().ok()?);
        let relative = dir.strip_prefix(&root).ok()?.to_string_lossy().into_owned();
        (!relative.is_empty()).then(|| format!("{relative}/"))
    });
    let dirty = git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| {
        s.lines().any(|l| {
            let path = l.get(3..).unwrap_or("");
            ignored
                .as_ref()
                .is_none_or(|dir| !path.starts_with(dir.as_str()))
        })
    });
    Some((head, dirty))
}
