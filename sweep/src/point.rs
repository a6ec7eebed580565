//! A point's scenario: the grid's base with each axis key set by its dotted path, then read and
//! checked whole by the registry exactly as a scenario file is (so an unknown key or a value out
//! of its range is the same named error as in `cargo xtask simulate`, prefixed with the point).

use crate::error::SweepError;
use crate::grid::{Grid, Point};
use cdpr_bench::core::scenario::Scenario;
use toml::{Table, Value};

/// The scenario of `point`, validated.
pub fn scenario(grid: &Grid, point: &Point) -> Result<Scenario, SweepError> {
    let mut table = grid.base.clone();
    for (key, value) in &point.values {
        set(&mut table, key, value.clone()).map_err(|message| SweepError::Point {
            index: point.index,
            params: describe(point),
            message,
        })?;
    }
    let text = toml::to_string(&table).expect("a TOML table prints");
    cdpr_bench::scenario_from_toml_str(&text).map_err(|e| SweepError::Point {
        index: point.index,
        params: describe(point),
        message: e.to_string(),
    })
}

/// Every point's scenario checked, before any work starts; the first bad point is the error.
pub fn check_all(grid: &Grid) -> Result<(), SweepError> {
    (0..grid.len()).try_for_each(|i| scenario(grid, &grid.point(i)).map(|_| ()))
}

/// `key = value, …` of a point, for messages.
pub fn describe(point: &Point) -> String {
    point
        .values
        .iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Sets `section.key` (or deeper) in `table`; the key must name a section and a key in it.
fn set(table: &mut Table, dotted: &str, value: Value) -> Result<(), String> {
    let parts: Vec<&str> = dotted.split('.').collect();
    if parts.len() < 2 || parts.iter().any(|p| p.is_empty()) {
        return Err(format!(
            "axis key `{dotted}` must be a dotted path `section.key` (e.g. robot.effector_mass)"
        ));
    }
    let mut at = table;
    for part in &parts[..parts.len() - 1] {
        let entry = at
            .entry(part.to_string())
            .or_insert_with(|| Value::Table(Table::new()));
        at = match entry {
            Value::Table(t) => t,
            other => {
                return Err(format!(
                    "axis key `{dotted}`: `{part}` is a value ({other}), not a section"
                ));
            }
        };
    }
    at.insert(parts[parts.len() - 1].to_string(), value);
    Ok(())
}
