//! A crate of WGSL kernels (under `shaders/`); `tests/golden.rs` checks them
//! against `golden/` with vista's harness.
