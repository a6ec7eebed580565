//! The FE model's keys of the scenario's `[model]` section (MODELS.md §9): element count, mass
//! matrix and stored-cable variants, with their defaults and validation, which the registry
//! applies when it reads the section.

use cdpr_core::model::{ModelError, ModelParams};
use cdpr_core::scenario::{Scenario, ScenarioError, count_in_range, out_of_range};
use serde::{Deserialize, Serialize};

/// The paper's discretisation: 10 elements per free span (MODELS.md §5).
pub const DEFAULT_ELEMENTS: usize = 10;

/// Mass matrix variant (MODELS.md FE.1.5), `model.fe_mass`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FeMass {
    /// The consistent mass of the element integrals (FE.4).
    #[default]
    Consistent,
    /// Half of each element's mass at each of its nodes.
    Lumped,
}

/// Stored-cable variant (MODELS.md FE.1.3), `model.fe_stored`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FeStored {
    /// An elastic stored element pulled at the reel, with its own length ρ_i.
    #[default]
    Elastic,
    /// A rigid stored cable (no ρ_i unknowns).
    Rigid,
}

/// The FE model's parameters beyond the robot and the cable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Params {
    /// Elements per free span, N (`model.elements`).
    pub elements: usize,
    #[serde(rename = "fe_mass")]
    pub mass: FeMass,
    #[serde(rename = "fe_stored")]
    pub stored: FeStored,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            elements: DEFAULT_ELEMENTS,
            mass: FeMass::default(),
            stored: FeStored::default(),
        }
    }
}

impl ModelParams for Params {
    type Model = crate::Fe;
    /// MODELS.md §9: the modelled cable covers the free span the trajectory needs with a stored
    /// length of at least 5 % of it left at all times.
    fn validate(&self, scenario: &Scenario) -> Result<(), ScenarioError> {
        let (free, chord) = scenario.free_length_needed();
        let l0 = scenario.cable.modelled_length;
        let needed = free / 0.95;
        if l0 < needed {
            return Err(out_of_range(
                "cable.modelled_length",
                l0,
                format!(
                    "≥ {needed:.6} m for this trajectory (1.05 × (1 + ΣT/EA) × longest chord {chord:.6} m, plus a stored length ≥ 5 % of it)"
                ),
            ));
        }
        Ok(())
    }
    fn build(&self, scenario: &Scenario) -> Result<crate::Fe, ModelError> {
        crate::Fe::new(scenario, *self)
    }
}

impl Params {
    /// From the section's keys (absent: the defaults); `elements` is refused outside
    /// [1, [`MAX_ELEMENTS`](cdpr_core::scenario::MAX_ELEMENTS)].
    pub fn from_keys(
        elements: Option<i64>,
        mass: FeMass,
        stored: FeStored,
    ) -> Result<Self, ScenarioError> {
        Ok(Self {
            elements: count_in_range("model.elements", elements, DEFAULT_ELEMENTS)?,
            mass,
            stored,
        })
    }
}
