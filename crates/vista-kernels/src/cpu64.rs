//! The CPU references in f64: the oracles every GPU test compares against.
//! Source: `src/cpu/`, shared with [`crate::cpu32`].

cpu_references!(f64, glam::DVec3);
