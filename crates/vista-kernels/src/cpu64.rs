//! The CPU references in f64: the oracles every GPU test compares against.
//! Source: each kernel's `cpu.rs` and `src/cpu/`, shared with `crate::cpu32`.

// Both builds load the same files, on purpose.
#![allow(clippy::duplicate_mod)]

cpu_references!(f64, glam::DVec3);
