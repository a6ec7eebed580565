//! Building the scenario's cable model: the one place that turns a model kind into a model.
//!
//! Generic code runs on any model through a [`ModelVisitor`], monomorphised for each (the
//! benches and the statics sweep need the concrete type); code that only needs *a* model takes
//! the boxed one from [`build`].

use crate::config::ModelConfig;
use crate::kind::ModelKind;
use cdpr_core::model::{CableModel, ModelError, ModelParams};
use cdpr_core::scenario::{Scenario, ScenarioError};

/// Why a model could not be built.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// Generic work on a model of any kind (see [`with_model`]).
pub trait ModelVisitor {
    type Output;
    fn visit<M: CableModel<2> + Clone + Send + 'static>(self, model: M) -> Self::Output;
}

/// Generic work on the chosen model's parameters.
trait ParamsVisitor {
    type Output;
    fn visit<P: ModelParams>(self, params: P) -> Self::Output;
}

/// The chosen model's parameters, handed to `visitor`: the kind is matched here and nowhere else.
fn with_params<V: ParamsVisitor>(
    config: &ModelConfig,
    visitor: V,
) -> Result<V::Output, ScenarioError> {
    Ok(match config.kind {
        ModelKind::Elastic => visitor.visit(cdpr_elastic::Params {}),
        ModelKind::Lumped => visitor.visit(config.lumped()?),
        ModelKind::Fe => visitor.visit(config.fe()?),
    })
}

/// Builds the scenario's model (after the model's own checks of the scenario) and hands it to
/// `visitor`.
///
/// # Examples
///
/// The number of state components of each model, computed on the concrete model types:
///
/// ```
/// use cdpr_bench::core::model::CableModel;
/// use cdpr_bench::core::scenario::Scenario;
/// use cdpr_bench::{ModelKind, ModelVisitor, with_model};
///
/// struct StateLen;
/// impl ModelVisitor for StateLen {
///     type Output = usize;
///     fn visit<M: CableModel<2> + Clone + Send + 'static>(self, model: M) -> usize {
///         model.state_len()
///     }
/// }
///
/// let mut scenario = Scenario::paper();
/// let mut lengths = Vec::new();
/// for kind in ModelKind::ALL {
///     scenario.model = kind.into();
///     lengths.push(with_model(&scenario, StateLen)?);
/// }
/// // Elastic: (x, z, ẋ, ż); lumped N = 40: 2 (4N + 2); FE N = 10: 2 (4(N − 1) + 6).
/// assert_eq!(lengths, [4, 324, 84]);
/// # Ok::<(), cdpr_bench::BuildError>(())
/// ```
pub fn with_model<V: ModelVisitor>(
    scenario: &Scenario,
    visitor: V,
) -> Result<V::Output, BuildError> {
    if let Some(anchors) = &scenario.robot.anchors {
        return Err(cdpr_core::scenario::out_of_range(
            "robot.anchors",
            format!("{} anchors in space", anchors.len()),
            "absent for the planar studies: a spatial robot runs `cargo xtask simulate` (the \
             elastic model, `simulate_spatial`), its statics `cargo xtask distribution`",
        )
        .into());
    }
    struct Build<'a, V>(&'a Scenario, V);
    impl<V: ModelVisitor> ParamsVisitor for Build<'_, V> {
        type Output = Result<V::Output, BuildError>;
        fn visit<P: ModelParams>(self, params: P) -> Self::Output {
            params.validate(self.0)?;
            Ok(self.1.visit(params.build(self.0)?))
        }
    }
    with_params(
        &ModelConfig::from_scenario(scenario)?,
        Build(scenario, visitor),
    )?
}

/// The `[model]` section as the chosen model reads it: its kind and its own keys, defaults filled.
pub(crate) fn resolved_section(config: &ModelConfig) -> Result<serde_json::Value, ScenarioError> {
    struct Resolve(ModelKind);
    impl ParamsVisitor for Resolve {
        type Output = Result<serde_json::Value, ScenarioError>;
        fn visit<P: ModelParams>(self, params: P) -> Self::Output {
            let mut section = serde_json::to_value(&params).map_err(|e| {
                ScenarioError::Syntax(format!("[model] of {} not serialisable: {e}", self.0))
            })?;
            section["kind"] = serde_json::Value::from(self.0.name());
            Ok(section)
        }
    }
    with_params(config, Resolve(config.kind))?
}

/// A cable model, whichever the scenario names: what the closed loop runs.
pub type DynModel = Box<dyn CableModel<2> + Send>;

/// The scenario's cable model.
///
/// # Examples
///
/// ```
/// use cdpr_bench::core::scenario::Scenario;
/// use cdpr_bench::{ModelConfig, ModelKind, build};
///
/// let mut scenario = Scenario::paper();
/// scenario.model = ModelConfig { elements: Some(2), ..ModelConfig::of_kind(ModelKind::Lumped) }.into();
/// let Err(err) = build(&scenario) else { panic!("two springs cannot make a lumped cable") };
/// assert!(err.to_string().contains("model.elements"));
/// ```
pub fn build(scenario: &Scenario) -> Result<DynModel, BuildError> {
    struct Boxed;
    impl ModelVisitor for Boxed {
        type Output = DynModel;
        fn visit<M: CableModel<2> + Clone + Send + 'static>(self, model: M) -> DynModel {
            Box::new(model)
        }
    }
    with_model(scenario, Boxed)
}

/// The chosen model's own checks of the scenario (MODELS.md §9: enough modelled cable for the
/// trajectory; the elastic model stores no cable and has none).
pub(crate) fn validate_for_model(
    scenario: &Scenario,
    config: &ModelConfig,
) -> Result<(), ScenarioError> {
    struct Validate<'a>(&'a Scenario);
    impl ParamsVisitor for Validate<'_> {
        type Output = Result<(), ScenarioError>;
        fn visit<P: ModelParams>(self, params: P) -> Self::Output {
            params.validate(self.0)
        }
    }
    with_params(config, Validate(scenario))?
}
