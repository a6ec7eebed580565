//! Why a scenario was refused ([`ScenarioError`]) and the range checks every section uses.

use std::fmt;

/// Why a scenario was refused.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The OS error is part of the message, not a `source`: printed with its chain it would
    /// otherwise appear twice.
    #[error("cannot read scenario file {path}: {error}")]
    Io { path: String, error: std::io::Error },
    /// Malformed TOML, an unknown key or a value of the wrong type (the message names the key).
    #[error("invalid scenario file: {0}")]
    Syntax(String),
    /// A value outside its allowed range.
    #[error("scenario key `{key}` = {value} is out of range: allowed {allowed}")]
    OutOfRange {
        key: &'static str,
        value: String,
        allowed: String,
    },
    /// Values each in range that together cannot start a run (no start equilibrium, no
    /// controller design, no mode for an "auto" shaper), found before the run.
    #[error("scenario keys {keys}: {why}")]
    Infeasible { keys: String, why: String },
}

pub fn out_of_range(
    key: &'static str,
    value: impl fmt::Display,
    allowed: impl Into<String>,
) -> ScenarioError {
    ScenarioError::OutOfRange {
        key,
        value: value.to_string(),
        allowed: allowed.into(),
    }
}

/// Largest element count a model accepts (`model.elements`; memory and run time grow like N).
pub const MAX_ELEMENTS: usize = 100_000;

/// An element count `key` = `value` in [1, [`MAX_ELEMENTS`]], or `default` when absent.
pub fn count_in_range(
    key: &'static str,
    value: Option<i64>,
    default: usize,
) -> Result<usize, ScenarioError> {
    match value {
        None => Ok(default),
        Some(n) if (1..=MAX_ELEMENTS as i64).contains(&n) => Ok(n as usize),
        Some(n) => Err(out_of_range(
            key,
            n,
            format!("an integer in [1, {MAX_ELEMENTS}]"),
        )),
    }
}

pub fn finite(key: &'static str, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(out_of_range(key, v, "a finite number"))
    }
}

pub fn positive(key: &'static str, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(out_of_range(key, v, "finite and > 0"))
    }
}

pub fn non_negative(key: &'static str, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(out_of_range(key, v, "finite and ≥ 0"))
    }
}
