//! The grid file: a base scenario, axes over dotted scenario keys, and how the axes combine.
//!
//! ```toml
//! [scenario]                       # a scenario file's sections (absent: the paper's)
//! model = { kind = "lumped" }
//! [axes]
//! "robot.effector_mass" = [0.5, 1.0, 2.0]                      # explicit points
//! "trajectory.t2" = { from = 0.1, to = 0.5, steps = 5 }        # a range, linear by default
//! "cable.youngs_modulus" = { from = 5e10, to = 2e11, steps = 3, scale = "log" }
//! [sweep]
//! combine = "product"              # or "zip"
//! ```
//!
//! Axes vary in the order of their keys (sorted), the last fastest; point i of a product is the
//! mixed-radix digits of i. Everything here is checked when the file is read: an axis with no
//! points, a malformed range, zip axes of different lengths are errors naming the key.

use crate::error::SweepError;
use serde::Serialize;
use toml::{Table, Value};

/// How the axes combine into points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Combine {
    /// Every combination (the axes' lengths multiplied).
    Product,
    /// The k-th value of every axis together (all axes of one length).
    Zip,
}

/// One axis: a dotted scenario key and its values, in order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Axis {
    pub key: String,
    pub values: Vec<Value>,
}

/// A parsed grid file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Grid {
    /// The base scenario's sections.
    pub base: Table,
    pub axes: Vec<Axis>,
    pub combine: Combine,
}

/// One point of the grid: its index and the value of each axis, in the axes' order.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    pub index: usize,
    pub values: Vec<(String, Value)>,
}

impl Grid {
    /// Parses a grid file's text. `origin` names the file in errors.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, SweepError> {
        let mut table: Table = toml::from_str(text).map_err(|e| SweepError::Grid {
            origin: origin.into(),
            message: e.to_string().trim_end().into(),
        })?;
        let grid_error = |message: String| SweepError::Grid {
            origin: origin.into(),
            message,
        };
        let base = match table.remove("scenario") {
            None => Table::new(),
            Some(Value::Table(t)) => t,
            Some(v) => return Err(grid_error(format!("[scenario] must be a table, not {v}"))),
        };
        let axes_table = match table.remove("axes") {
            Some(Value::Table(t)) if !t.is_empty() => t,
            Some(Value::Table(_)) | None => {
                return Err(grid_error(
                    "[axes] must name at least one scenario key".into(),
                ));
            }
            Some(v) => return Err(grid_error(format!("[axes] must be a table, not {v}"))),
        };
        let combine = match table.remove("sweep") {
            None => Combine::Product,
            Some(Value::Table(mut t)) => {
                let combine = match t.remove("combine") {
                    None => Combine::Product,
                    Some(Value::String(s)) if s == "product" => Combine::Product,
                    Some(Value::String(s)) if s == "zip" => Combine::Zip,
                    Some(v) => {
                        return Err(grid_error(format!(
                            "sweep.combine = {v}: allowed \"product\" or \"zip\""
                        )));
                    }
                };
                if let Some(key) = t.keys().next() {
                    return Err(grid_error(format!(
                        "unknown key sweep.{key}: [sweep] has only `combine`"
                    )));
                }
                combine
            }
            Some(v) => return Err(grid_error(format!("[sweep] must be a table, not {v}"))),
        };
        if let Some(key) = table.keys().next() {
            return Err(grid_error(format!(
                "unknown section [{key}]: a grid file has [scenario], [axes] and [sweep]"
            )));
        }
        let axes = axes_table
            .into_iter()
            .map(|(key, spec)| {
                let values = axis_values(&key, spec).map_err(grid_error)?;
                Ok(Axis { key, values })
            })
            .collect::<Result<Vec<_>, SweepError>>()?;
        if combine == Combine::Zip {
            let first = &axes[0];
            if let Some(other) = axes.iter().find(|a| a.values.len() != first.values.len()) {
                return Err(grid_error(format!(
                    "combine = \"zip\" needs axes of one length: `{}` has {} points, `{}` has {}",
                    first.key,
                    first.values.len(),
                    other.key,
                    other.values.len()
                )));
            }
        }
        Ok(Self {
            base,
            axes,
            combine,
        })
    }

    /// Reads and parses a grid file.
    pub fn from_file(path: &std::path::Path) -> Result<Self, SweepError> {
        let text = std::fs::read_to_string(path).map_err(|source| SweepError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        match self.combine {
            Combine::Product => self.axes.iter().map(|a| a.values.len()).product(),
            Combine::Zip => self.axes[0].values.len(),
        }
    }

    /// Whether the grid has no points (never, once parsed).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `index` (< [`Grid::len`]).
    pub fn point(&self, index: usize) -> Point {
        let mut rest = index;
        let mut values = vec![(String::new(), Value::Boolean(false)); self.axes.len()];
        for (k, axis) in self.axes.iter().enumerate().rev() {
            let j = match self.combine {
                Combine::Zip => index,
                Combine::Product => {
                    let n = axis.values.len();
                    let j = rest % n;
                    rest /= n;
                    j
                }
            };
            values[k] = (axis.key.clone(), axis.values[j].clone());
        }
        Point { index, values }
    }

    /// A digest of the grid (FNV-1a over its canonical JSON): the identity a results file is
    /// checked against on resume and merge.
    pub fn digest(&self) -> String {
        let canonical = serde_json::to_string(self).expect("a grid serialises");
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        for byte in canonical.bytes() {
            hash ^= byte as u64;
            hash = hash.wrapping_mul(0x0100_0000_01b3);
        }
        format!("{hash:016x}")
    }
}

/// The values of one axis: an array (explicit points) or a range table.
fn axis_values(key: &str, spec: Value) -> Result<Vec<Value>, String> {
    match spec {
        Value::Array(values) if values.is_empty() => Err(format!("axis `{key}` has no points")),
        Value::Array(values) => Ok(values),
        Value::Table(t) => range(key, t),
        v => Err(format!(
            "axis `{key}` = {v}: give a list of points or {{ from, to, steps, scale }}"
        )),
    }
}

/// `{ from, to, steps, scale = "linear" | "log" }`: `steps` points from `from` to `to`, both
/// included (one step: `from`).
fn range(key: &str, mut t: Table) -> Result<Vec<Value>, String> {
    let mut number = |name: &str| match t.remove(name) {
        Some(Value::Float(x)) if x.is_finite() => Ok(x),
        Some(Value::Integer(i)) => Ok(i as f64),
        Some(v) => Err(format!(
            "axis `{key}`: {name} = {v} must be a finite number"
        )),
        None => Err(format!("axis `{key}`: a range needs `{name}`")),
    };
    let (from, to) = (number("from")?, number("to")?);
    let steps = match t.remove("steps") {
        Some(Value::Integer(n)) if n >= 1 => n as usize,
        Some(v) => return Err(format!("axis `{key}`: steps = {v}, allowed an integer ≥ 1")),
        None => return Err(format!("axis `{key}`: a range needs `steps`")),
    };
    let log = match t.remove("scale") {
        None => false,
        Some(Value::String(s)) if s == "linear" => false,
        Some(Value::String(s)) if s == "log" => true,
        Some(v) => {
            return Err(format!(
                "axis `{key}`: scale = {v}, allowed \"linear\" or \"log\""
            ));
        }
    };
    if let Some(extra) = t.keys().next() {
        return Err(format!(
            "axis `{key}`: unknown range key `{extra}` (from, to, steps, scale)"
        ));
    }
    if log && (from <= 0.0 || to <= 0.0) {
        return Err(format!(
            "axis `{key}`: a log range needs from > 0 and to > 0 (from = {from}, to = {to})"
        ));
    }
    let at = |k: usize| {
        if k == 0 {
            return from;
        }
        if k + 1 == steps {
            return to;
        }
        let f = k as f64 / (steps - 1) as f64;
        if log {
            (from.ln() + f * (to.ln() - from.ln())).exp()
        } else {
            from + f * (to - from)
        }
    };
    Ok((0..steps).map(|k| Value::Float(at(k))).collect())
}
