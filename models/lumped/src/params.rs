//! The lumped model's keys of the scenario's `[model]` section (MODELS.md §9): their defaults and
//! validation, which the registry applies when it reads the section.

use cdpr_core::model::{ModelError, ModelParams};
use cdpr_core::scenario::{Scenario, ScenarioError, count_in_range, out_of_range};

/// The paper's discretisation: 40 springs per cable (MODELS.md §4).
pub const DEFAULT_ELEMENTS: usize = 40;

/// The fewest springs a lumped cable can have: a reel end, a straddling spring and a free node.
pub const MIN_ELEMENTS: usize = 3;

/// The lumped model's parameters beyond the robot and the cable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Params {
    /// Springs per cable, N (`model.elements`); N + 1 nodes of which the effector is shared.
    pub elements: usize,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            elements: DEFAULT_ELEMENTS,
        }
    }
}

impl ModelParams for Params {
    type Model = crate::Lumped;
    /// At least [`MIN_ELEMENTS`] springs, and (MODELS.md §9) the modelled cable covers the free
    /// span the trajectory needs plus two spare stored elements, so a node is always left on the
    /// reel.
    fn validate(&self, scenario: &Scenario) -> Result<(), ScenarioError> {
        if self.elements < MIN_ELEMENTS {
            return Err(out_of_range(
                "model.elements",
                self.elements,
                format!(
                    "an integer ≥ {MIN_ELEMENTS} for the lumped model (a reel end, a straddling spring, a free node)"
                ),
            ));
        }
        let (free, chord) = scenario.free_length_needed();
        let l0 = scenario.cable.modelled_length;
        let needed = free + 2.0 * l0 / self.elements as f64;
        if l0 < needed {
            return Err(out_of_range(
                "cable.modelled_length",
                l0,
                format!(
                    "≥ {needed:.6} m for this trajectory (1.05 × (1 + ΣT/EA) × longest chord {chord:.6} m, plus two spare stored elements)"
                ),
            ));
        }
        Ok(())
    }
    fn build(&self, scenario: &Scenario) -> Result<crate::Lumped, ModelError> {
        crate::Lumped::new(scenario, *self)
    }
}

impl Params {
    /// From the section's `elements` (absent: [`DEFAULT_ELEMENTS`]), refused outside
    /// [1, [`MAX_ELEMENTS`](cdpr_core::scenario::MAX_ELEMENTS)].
    pub fn from_elements(elements: Option<i64>) -> Result<Self, ScenarioError> {
        Ok(Self {
            elements: count_in_range("model.elements", elements, DEFAULT_ELEMENTS)?,
        })
    }
}
