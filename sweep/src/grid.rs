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

/// Most points a grid may have: each is checked before any work starts (~50 µs) and recorded
/// in ~2.5 kB, so a million points are ~25 s of checks on two cores and ~2.5 GB of records;
/// split a larger study into several grids.
pub const MAX_POINTS: usize = 1_000_000;

/// How the axes combine into points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Combine {
    /// Every combination (the axes' lengths multiplied).
    Product,
    /// The k-th value of every axis together (all axes of one length).
    Zip,
}

impl Combine {
    fn name(self) -> &'static str {
        match self {
            Combine::Product => "product",
            Combine::Zip => "zip",
        }
    }
}

/// The values of an axis: listed, or a range computed point by point (never materialised).
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    List(Vec<Value>),
    /// `steps` points from `from` to `to`, both included, evenly spaced (in ln on a log range).
    Range {
        from: f64,
        to: f64,
        steps: usize,
        log: bool,
    },
}

impl Values {
    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            Values::List(v) => v.len(),
            Values::Range { steps, .. } => *steps,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value k (< [`Values::len`]).
    pub fn get(&self, k: usize) -> Value {
        match self {
            Values::List(v) => v[k].clone(),
            &Values::Range {
                from,
                to,
                steps,
                log,
            } => {
                let x = if k == 0 {
                    from
                } else if k + 1 == steps {
                    to
                } else {
                    let f = k as f64 / (steps - 1) as f64;
                    if log {
                        (from.ln() + f * (to.ln() - from.ln())).exp()
                    } else {
                        from + f * (to - from)
                    }
                };
                Value::Float(x)
            }
        }
    }

    /// As the grid file writes it.
    fn to_toml(&self) -> Value {
        match self {
            Values::List(v) => Value::Array(v.clone()),
            &Values::Range {
                from,
                to,
                steps,
                log,
            } => {
                let mut t = Table::new();
                t.insert("from".into(), Value::Float(from));
                t.insert("to".into(), Value::Float(to));
                t.insert("steps".into(), Value::Integer(steps as i64));
                let scale = if log { "log" } else { "linear" };
                t.insert("scale".into(), Value::String(scale.into()));
                Value::Table(t)
            }
        }
    }
}

/// One axis: a dotted scenario key and its values, in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    pub key: String,
    pub values: Values,
}

/// A parsed grid file.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// The base scenario's sections.
    pub base: Table,
    pub axes: Vec<Axis>,
    pub combine: Combine,
    /// Points in the grid (≤ [`MAX_POINTS`]).
    len: usize,
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
        let len = count(&axes, combine).map_err(grid_error)?;
        Ok(Self {
            base,
            axes,
            combine,
            len,
        })
    }

    /// Reads and parses a grid file.
    pub fn from_file(path: &std::path::Path) -> Result<Self, SweepError> {
        let text = std::fs::read_to_string(path).map_err(|source| SweepError::io(path, source))?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the grid has no points (never, once parsed).
    pub fn is_empty(&self) -> bool {
        self.len == 0
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
            values[k] = (axis.key.clone(), axis.values.get(j));
        }
        Point { index, values }
    }

    /// The grid as a canonical grid file (sections and keys sorted, ranges as ranges): what a
    /// results file's header carries, so that a merge can check each record against its point.
    pub fn to_toml(&self) -> String {
        let mut axes = Table::new();
        for axis in &self.axes {
            axes.insert(axis.key.clone(), axis.values.to_toml());
        }
        let mut sweep = Table::new();
        sweep.insert("combine".into(), Value::String(self.combine.name().into()));
        let mut table = Table::new();
        table.insert("scenario".into(), Value::Table(self.base.clone()));
        table.insert("axes".into(), Value::Table(axes));
        table.insert("sweep".into(), Value::Table(sweep));
        toml::to_string(&table).expect("a TOML table prints")
    }

    /// A digest of the grid (FNV-1a over [`Grid::to_toml`]): the identity a results file is
    /// checked against on resume and merge.
    pub fn digest(&self) -> String {
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        for byte in self.to_toml().bytes() {
            hash ^= byte as u64;
            hash = hash.wrapping_mul(0x0100_0000_01b3);
        }
        format!("{hash:016x}")
    }
}

/// The number of points of `axes` combined, refused above [`MAX_POINTS`] (before anything is
/// materialised) and for zip axes of different lengths.
fn count(axes: &[Axis], combine: Combine) -> Result<usize, String> {
    let too_many = |what: String| {
        format!(
            "{what}: more than the {MAX_POINTS} points a grid may have (each is checked before \
             work and recorded); split the study into several grids"
        )
    };
    match combine {
        Combine::Zip => {
            let first = &axes[0];
            if let Some(other) = axes.iter().find(|a| a.values.len() != first.values.len()) {
                return Err(format!(
                    "combine = \"zip\" needs axes of one length: `{}` has {} points, `{}` has {}",
                    first.key,
                    first.values.len(),
                    other.key,
                    other.values.len()
                ));
            }
            let n = first.values.len();
            if n > MAX_POINTS {
                return Err(too_many(format!("the zipped axes have {n} points each")));
            }
            Ok(n)
        }
        Combine::Product => {
            let mut n: usize = 1;
            for axis in axes {
                n = n
                    .checked_mul(axis.values.len())
                    .filter(|&n| n <= MAX_POINTS)
                    .ok_or_else(|| {
                        let lengths: Vec<String> = axes
                            .iter()
                            .map(|a| format!("`{}` {}", a.key, a.values.len()))
                            .collect();
                        too_many(format!(
                            "the product of the axes ({}) is {:e} points",
                            lengths.join(" × "),
                            axes.iter().map(|a| a.values.len() as f64).product::<f64>()
                        ))
                    })?;
            }
            Ok(n)
        }
    }
}

/// The values of one axis: an array (explicit points) or a range table.
fn axis_values(key: &str, spec: Value) -> Result<Values, String> {
    match spec {
        Value::Array(values) if values.is_empty() => Err(format!("axis `{key}` has no points")),
        Value::Array(values) => Ok(Values::List(values)),
        Value::Table(t) => range(key, t),
        v => Err(format!(
            "axis `{key}` = {v}: give a list of points or {{ from, to, steps, scale }}"
        )),
    }
}

/// `{ from, to, steps, scale = "linear" | "log" }`: `steps` points from `from` to `to`, both
/// included (one step: `from`).
fn range(key: &str, mut t: Table) -> Result<Values, String> {
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
        Some(Value::Integer(n)) if n >= 1 && n as u64 <= MAX_POINTS as u64 => n as usize,
        Some(v) => {
            return Err(format!(
                "axis `{key}`: steps = {v}, allowed an integer in [1, {MAX_POINTS}]"
            ));
        }
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
    Ok(Values::Range {
        from,
        to,
        steps,
        log,
    })
}
