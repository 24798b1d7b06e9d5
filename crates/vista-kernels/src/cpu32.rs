//! The same CPU references (`src/cpu/`) compiled with f32 arithmetic: the
//! CPU doing the GPU's work at the GPU's precision, the baseline of the
//! throughput benches, and a measure of what the f64 oracles buy (see
//! `tests/precision.rs`, which checks it against the f64 build). Not an
//! oracle: no GPU test compares against it, except the heightfield relax
//! march port (`HitSearch::RelaxMarch`), checked to do the GPU's work.

// Both builds load the same files, on purpose.
#![allow(clippy::duplicate_mod)]

cpu_references!(f32, glam::Vec3);
