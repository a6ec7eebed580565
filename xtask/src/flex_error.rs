//! `cargo xtask flex-error --scenario FILE --box X0,X1,Y0,Y1,Z0,Z1 --out DIR`: firmware's static
//! flex compensation on sagging lines over a grid of targets ([`cdpr_studies::flex_error`]) →
//! `DIR/flex-error.json` and `DIR/flex-error.md`.

use crate::output::{write_atomic, write_json};
use anyhow::{Result, bail};
use std::path::Path;

pub fn run(
    scenario: &Path,
    bounds: &[f64],
    points: usize,
    elements: usize,
    out: &Path,
) -> Result<()> {
    let scenario = crate::simulate::load_scenario(Some(scenario), None)?;
    let &[x0, x1, y0, y1, z0, z1] = bounds else {
        bail!("--box {bounds:?}: six numbers X0,X1,Y0,Y1,Z0,Z1 [m] expected");
    };
    if !(x0 <= x1 && y0 <= y1 && z0 <= z1) {
        bail!("--box {bounds:?}: each lower bound must not exceed its upper bound");
    }
    crate::simulate::writable_out(out)?;
    let study = cdpr_studies::flex_error::over_box(
        &scenario,
        [x0, y0, z0],
        [x1, y1, z1],
        points,
        elements,
    )?;
    write_json(&out.join("flex-error.json"), &study)?;
    let table = cdpr_studies::flex_error::markdown(&study);
    write_atomic(&out.join("flex-error.md"), |w| {
        w.write_all(table.as_bytes())
    })?;
    print!("{table}");
    Ok(())
}
