#![deny(missing_docs)]
//! What a project says about its kernels, read against what naga reads
//! from their WGSL: a kernel's manifest (`kernels/<name>.toml`,
//! [`manifest`]) with its params ([`params`]), integer expressions
//! ([`expr`]) and pass graph ([`graph`], [`vertex`]); each entry point's
//! globals from naga's reflection ([`bindings`], [`element`]); the uniform
//! block packed from that reflection ([`layout`]); and [`Kernel`], a parsed
//! manifest with the CPU reference a registry attached (see
//! `vista-kernels`, which owns the built-ins and their references).
//!
//! Not for: GPU work (see `vista-gpu`), files or goldens (see
//! `vista-golden`). Manifests arrive as text; nothing here touches the file
//! system.

pub mod bindings;
pub mod element;
mod error;
pub mod expr;
pub mod graph;
mod kernel;
pub mod layout;
pub mod leaves;
pub mod manifest;
pub mod params;
mod size;
pub mod values;
pub mod vertex;
mod view;

pub use error::ParamError;
pub use kernel::{CpuReference, Kernel};
pub use layout::UniformLayout;
pub use manifest::HashPlane;
pub use params::{Kind, ParamSet, ParamSpec, ParamType, Preset, Value};
pub use size::{MAX_DIMENSION, check_size, parse_size};
pub use view::{DisplayMap, Output, is_integer_format, normalized};
