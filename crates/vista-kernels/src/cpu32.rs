//! The same CPU references (`src/cpu/`) compiled with f32 arithmetic: the
//! CPU doing the GPU's work at the GPU's precision, the baseline of the
//! throughput benches, and a measure of what the f64 oracles buy (see
//! `tests/precision.rs`). Not an oracle: nothing is checked against it.

// Both builds load the same files, on purpose.
#![allow(clippy::duplicate_mod)]

cpu_references!(f32, glam::Vec3);
