//! The lumped cable tests as one test binary: each file beside this one is a module here, so they
//! compile and link once and share the cores. `Cargo.toml` turns off the discovery of each file
//! as its own test; the allocation test stays a binary of its own, as it installs a counting
//! global allocator.

#[path = "damping.rs"]
mod damping;
#[path = "equilibrium_balance.rs"]
mod equilibrium_balance;
#[path = "lumped.rs"]
mod lumped;
#[path = "pulley_events.rs"]
mod pulley_events;
