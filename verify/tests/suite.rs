//! The verification suite as one test binary: each file beside this one is a module here, so the
//! suite compiles and links once, and its tests share the cores instead of running binary after
//! binary. `Cargo.toml` turns off the discovery of each file as its own test.

/// What the modules share (tests/common/mod.rs), compiled once.
mod common;
#[path = "control.rs"]
mod control;
#[path = "equilibrium_irvine.rs"]
mod equilibrium_irvine;
#[path = "fe_references.rs"]
mod fe_references;
#[path = "fe_spatial.rs"]
mod fe_spatial;
#[path = "fe_spatial_modes.rs"]
mod fe_spatial_modes;
#[path = "implicit.rs"]
mod implicit;
#[path = "implicit_adaptive.rs"]
mod implicit_adaptive;
#[path = "lqr_weights.rs"]
mod lqr_weights;
#[path = "lumped_references.rs"]
mod lumped_references;
#[path = "lumped_spatial/mod.rs"]
mod lumped_spatial;
#[path = "modes.rs"]
mod modes;
#[path = "moordyn.rs"]
mod moordyn;
#[path = "moordyn_spatial.rs"]
mod moordyn_spatial;
#[path = "paper.rs"]
mod paper;
#[path = "paper_elastic.rs"]
mod paper_elastic;
#[path = "print.rs"]
mod print;
#[path = "printing.rs"]
mod printing;
#[path = "shaping.rs"]
mod shaping;
#[path = "spatial.rs"]
mod spatial;
#[path = "spatial_printers.rs"]
mod spatial_printers;
