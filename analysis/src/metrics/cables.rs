//! The tension metrics of cables 3…m (`t3_min` …), each cable measured as the first two.

use super::{extreme, mean};

/// One cable's commanded-tension metrics (the `tk_*` keys of cable k ≥ 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CableTensions {
    /// Minimum [N] and when [s].
    pub min: f64,
    pub min_time: f64,
    /// Maximum [N] and when [s].
    pub max: f64,
    pub max_time: f64,
    /// At t_final [N].
    pub final_value: f64,
    /// Mean over the `last` window [N].
    pub mean_last_1s: f64,
}

impl CableTensions {
    pub(super) fn of(t: &[f64], v: &[f64], last: std::ops::Range<usize>) -> Self {
        let (min_time, min) = extreme(t, v, |a, b| a < b);
        let (max_time, max) = extreme(t, v, |a, b| a > b);
        Self {
            min,
            min_time,
            max,
            max_time,
            final_value: v.last().copied().unwrap_or(f64::NAN),
            mean_last_1s: mean(&v[last]),
        }
    }
}

/// The tension metrics of cables 3…m, cable 3 first; written as the keys `t3_min` … (NaN as
/// null), none for the planar robot.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FurtherCables(pub Vec<CableTensions>);

impl serde::Serialize for FurtherCables {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(6 * self.0.len()))?;
        for (i, c) in self.0.iter().enumerate() {
            let k = i + 3;
            for (name, value) in [
                ("min", c.min),
                ("min_time", c.min_time),
                ("max", c.max),
                ("max_time", c.max_time),
                ("final", c.final_value),
                ("mean_last_1s", c.mean_last_1s),
            ] {
                let value = value.is_finite().then_some(value);
                map.serialize_entry(&format!("t{k}_{name}"), &value)?;
            }
        }
        map.end()
    }
}
