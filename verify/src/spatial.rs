//! The spatial examples as the tests load them, and the comparisons of modes the spatial
//! tests share.

use cdpr_bench::analysis::modes::ModeKind;
use cdpr_bench::analysis::rest_modes::RestModes;
use cdpr_bench::core::scenario::Scenario;

/// The Hangprinter example (examples/robots/hangprinter-lumped.toml) on cables of `kind`
/// (`"lumped"`, `"fe"`) with `elements` each and line density `density` [kg/m³] (the
/// example's 970).
pub fn hangprinter(kind: &str, elements: usize, density: f64) -> Scenario {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/robots/hangprinter-lumped.toml");
    let text = std::fs::read_to_string(path)
        .expect("the example is in the repository")
        .replace("kind = \"lumped\"", &format!("kind = \"{kind}\""))
        .replace("elements = 20", &format!("elements = {elements}"))
        .replace("density = 970.0", &format!("density = {density}"));
    Scenario::from_toml_str(&text).expect("the example parses")
}

/// The `count` frequencies of `modes` nearest `omega` [rad/s], ascending: what a shift-invert
/// solve around `omega` should find.
pub fn nearest(modes: &RestModes, omega: f64, count: usize) -> Vec<f64> {
    let shift = omega * omega;
    let mut found: Vec<f64> = modes.modes.iter().map(|m| m.mode.omega).collect();
    found.sort_by(|a, b| (a * a - shift).abs().total_cmp(&(b * b - shift).abs()));
    found.truncate(count);
    found.sort_by(f64::total_cmp);
    found
}

/// The effector's x, y and vertical modes among `modes` (the first of each kind), ascending
/// [rad/s]; panics naming the kind it misses.
pub fn effector_modes(modes: &RestModes) -> Vec<f64> {
    let mut effector: Vec<f64> = [ModeKind::EffectorX, ModeKind::EffectorY, ModeKind::Vertical]
        .into_iter()
        .map(|kind| {
            modes
                .modes
                .iter()
                .find(|m| m.kind == kind)
                .unwrap_or_else(|| panic!("no {kind} mode"))
                .mode
                .omega
        })
        .collect();
    effector.sort_by(f64::total_cmp);
    effector
}

/// The three frequencies [rad/s], ascending, of a point mass `mass` [kg] held by the stiffness
/// `stiffness` [N/m]: the effector of a locked robot on massless lines.
pub fn point_mass_modes(stiffness: &cdpr_bench::core::robot::Matrix<3>, mass: f64) -> Vec<f64> {
    let mut omega: Vec<f64> = stiffness
        .symmetric_eigenvalues()
        .iter()
        .map(|k| (k / mass).sqrt())
        .collect();
    omega.sort_by(f64::total_cmp);
    omega
}
