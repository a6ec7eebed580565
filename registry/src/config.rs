//! The scenario's `[model]` section read into a typed choice (MODELS.md §9): `kind` and the keys
//! the models own (`elements`, `fe_mass`, `fe_stored`). Every key present is validated by the
//! model that owns it, whichever kind is chosen, so a bad value is never silently ignored; the
//! chosen model also checks the rest of the scenario against its needs (modelled cable length).

use crate::kind::ModelKind;
use cdpr_core::scenario::{ModelSection, Scenario, ScenarioError};
use cdpr_fe::{FeMass, FeStored};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The `[model]` section, typed; absent keys take the owning model's default.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct ModelConfig {
    pub kind: ModelKind,
    /// Elements per cable; absent = the model's default (lumped 40, FE 10); unused by the elastic
    /// model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elements: Option<i64>,
    /// FE mass matrix (MODELS.md FE.1.5).
    pub fe_mass: FeMass,
    /// FE stored cable (MODELS.md FE.1.3).
    pub fe_stored: FeStored,
}

impl ModelConfig {
    /// The default section of `kind`.
    pub fn of_kind(kind: ModelKind) -> Self {
        Self {
            kind,
            ..Self::default()
        }
    }

    /// Reads and validates the scenario's `[model]` section.
    pub fn from_scenario(scenario: &Scenario) -> Result<Self, ScenarioError> {
        let table = toml::Value::Table(scenario.model.0.clone());
        let config = Self::deserialize(table)
            .map_err(|e| ScenarioError::Syntax(format!("[model]: {}", e.to_string().trim_end())))?;
        config.lumped()?;
        config.fe()?;
        Ok(config)
    }

    /// The section as a scenario stores it.
    pub fn section(&self) -> ModelSection {
        let table = toml::Table::try_from(self).unwrap_or_default();
        ModelSection(table)
    }

    /// The lumped model's parameters from this section.
    pub fn lumped(&self) -> Result<cdpr_lumped::Params, ScenarioError> {
        cdpr_lumped::Params::from_elements(self.elements)
    }

    /// The FE model's parameters from this section.
    pub fn fe(&self) -> Result<cdpr_fe::Params, ScenarioError> {
        cdpr_fe::Params::from_keys(self.elements, self.fe_mass, self.fe_stored)
    }
}

impl From<ModelKind> for ModelSection {
    fn from(kind: ModelKind) -> Self {
        ModelConfig::of_kind(kind).section()
    }
}

impl From<ModelConfig> for ModelSection {
    fn from(config: ModelConfig) -> Self {
        config.section()
    }
}

/// The whole scenario checked: the robot's sections (done when it was read), the `[model]`
/// section, and the chosen model's needs. Returns the model section, typed.
pub fn validate(scenario: &Scenario) -> Result<ModelConfig, ScenarioError> {
    scenario.validate()?;
    let config = ModelConfig::from_scenario(scenario)?;
    // The models' own checks are of the planar robot; a spatial one builds none yet.
    if scenario.robot.anchors.is_none() {
        crate::build::validate_for_model(scenario, &config)?;
    }
    Ok(config)
}

/// Parses and validates a scenario from TOML text (MODELS.md §9): every key, the `[model]`
/// section and the chosen model's needs.
pub fn scenario_from_toml_str(text: &str) -> Result<Scenario, ScenarioError> {
    let scenario = Scenario::from_toml_str(text)?;
    validate(&scenario)?;
    Ok(scenario)
}

/// Reads, parses and validates a scenario file (see [`scenario_from_toml_str`]).
pub fn scenario_from_file(path: &Path) -> Result<Scenario, ScenarioError> {
    let scenario = Scenario::from_file(path)?;
    validate(&scenario)?;
    Ok(scenario)
}

/// The scenario with its model replaced by `kind` (the model's keys kept), validated again.
pub fn with_model_kind(scenario: &Scenario, kind: ModelKind) -> Result<Scenario, ScenarioError> {
    let mut config = ModelConfig::from_scenario(scenario)?;
    config.kind = kind;
    let mut s = scenario.clone();
    s.model = config.section();
    validate(&s)?;
    Ok(s)
}
