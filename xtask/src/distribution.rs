//! `cargo xtask distribution --scenario FILE --at X,Y,Z --out DIR`: a spatial robot's tension
//! distributions at one pose ([`cdpr_studies::distribution`]) → `DIR/distribution.json`.

use crate::output::write_json;
use anyhow::{Result, bail};
use std::path::Path;

pub fn run(scenario: &Path, at: &[f64], out: &Path) -> Result<()> {
    let scenario = crate::simulate::load_scenario(Some(scenario), None)?;
    let &[x, y, z] = at else {
        bail!("--at {at:?}: three coordinates X,Y,Z [m] expected");
    };
    crate::simulate::writable_out(out)?;
    let report = cdpr_studies::distribution::at_pose(&scenario, [x, y, z])?;
    write_json(&out.join("distribution.json"), &report)?;
    for (name, m) in &report.methods {
        let tensions: Vec<String> = m.tensions.iter().map(|t| format!("{t:.3}")).collect();
        println!(
            "{name:>22}: [{}] N{}",
            tensions.join(", "),
            if m.feasible { "" } else { "  (infeasible)" }
        );
    }
    println!(
        "margin {:.3} N → {}",
        report.margin,
        out.join("distribution.json").display()
    );
    Ok(())
}
