//! Which cable model a run uses: the registry's list of every model.

use serde::{Deserialize, Serialize};
use std::fmt;

/// A cable model of cdpr-bench (`[model] kind`, `--model`).
///
/// # Examples
///
/// ```
/// use cdpr_bench::ModelKind;
///
/// let kind: ModelKind = "fe".parse()?;
/// assert_eq!(kind, ModelKind::Fe);
/// assert_eq!(ModelKind::ALL.map(ModelKind::name), ["elastic", "lumped", "fe"]);
/// assert!("rigid".parse::<ModelKind>().unwrap_err().contains("allowed elastic, lumped, fe"));
/// # Ok::<(), String>(())
/// ```
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default, Deserialize, Serialize,
)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum ModelKind {
    /// Massless elastic springs (paper §2.1, MODELS.md §3).
    #[default]
    Elastic,
    /// Lumped mass-spring cable sliding over the pulley (paper §2.2, MODELS.md §4).
    Lumped,
    /// Variable-length finite elements (paper §2.3, MODELS.md §5).
    Fe,
}

impl ModelKind {
    /// Every model, in the order of the paper.
    pub const ALL: [ModelKind; 3] = [ModelKind::Elastic, ModelKind::Lumped, ModelKind::Fe];

    /// The models whose cables have mass (and axial modes, pulley dynamics, an implicit path).
    pub const MASSIVE: [ModelKind; 2] = [ModelKind::Lumped, ModelKind::Fe];

    /// Whether the model's cables have mass (one of [`ModelKind::MASSIVE`]).
    pub fn has_cable_mass(self) -> bool {
        Self::MASSIVE.contains(&self)
    }

    /// The model's place in [`ModelKind::ALL`] (for per-model tables such as figure colours).
    pub fn index(self) -> usize {
        Self::ALL.iter().position(|&k| k == self).unwrap_or(0)
    }

    /// The scenario file's spelling, also the model's name in files and tables.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Elastic => "elastic",
            ModelKind::Lumped => "lumped",
            ModelKind::Fe => "fe",
        }
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ModelKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                let allowed: Vec<_> = Self::ALL.map(Self::name).into();
                format!("unknown model `{s}`: allowed {}", allowed.join(", "))
            })
    }
}
