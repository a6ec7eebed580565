//! Criterion benches of cdpr-bench live in `benches/`; this library is empty on purpose
//! (Cargo needs a target to hang the benches on).
