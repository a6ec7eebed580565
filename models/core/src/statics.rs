//! The robot's side of the static equilibrium (MODELS.md §2): a model's static problem takes its
//! Jacobian pattern from the model's second-order pattern plus the column of the PID force F0,
//! and is solved by the Newton service of `cdpr-numerics`.

/// A static problem's Jacobian pattern, from [`pattern_from_dynamics`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct StaticPattern {
    /// (equation, unknown): the dynamic pattern's entries whose row and column both map, in its
    /// order, then the column of the PID force F0.
    pub entries: Vec<(usize, usize)>,
    /// The index in the dynamic pattern of each mapped entry (the first `kept.len()` of
    /// `entries`): a problem whose Jacobian comes from the model's matrix values (in the dynamic
    /// order) takes them through these, without repeating the mapping.
    pub kept: Vec<usize>,
}

/// A static problem's Jacobian pattern from its model's second-order pattern (`dynamic`, over q):
/// rows and columns of q mapped to the problem's equations and unknowns (None: not one), and the
/// column of the PID force F0 (unknown `force`) in the rows of q where the commanded tensions act.
pub fn pattern_from_dynamics(
    dynamic: &[(usize, usize)],
    row_of: impl Fn(usize) -> Option<usize>,
    col_of: impl Fn(usize) -> Option<usize>,
    tension_rows: &[usize],
    force: usize,
) -> StaticPattern {
    let (kept, mut entries): (Vec<usize>, Vec<(usize, usize)>) = dynamic
        .iter()
        .enumerate()
        .filter_map(|(p, &(r, c))| Some((p, (row_of(r)?, col_of(c)?))))
        .unzip();
    entries.extend(
        tension_rows
            .iter()
            .filter_map(|&r| Some((row_of(r)?, force))),
    );
    StaticPattern { entries, kept }
}
