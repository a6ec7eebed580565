//! `cargo xtask spatial-moves --scenario FILE --out DIR`: a spatial robot's move under every
//! controller and distribution ([`cdpr_studies::spatial_moves`]) → `DIR/moves.json` and
//! `DIR/moves.md`.

use crate::output::{write_atomic, write_json};
use anyhow::Result;
use std::path::Path;

pub fn run(scenario: &Path, out: &Path) -> Result<()> {
    let scenario = crate::simulate::load_scenario(Some(scenario), None)?;
    cdpr_bench::prepare_spatial(&scenario)?;
    crate::simulate::writable_out(out)?;
    let rows = cdpr_studies::spatial_moves::table(&scenario)?;
    write_json(&out.join("moves.json"), &rows)?;
    let table = cdpr_studies::spatial_moves::markdown(&rows);
    write_atomic(&out.join("moves.md"), |w| w.write_all(table.as_bytes()))?;
    print!("{table}");
    Ok(())
}
