//! vista's kernels: one module per kernel with its typed parameters, presets,
//! range validation and uniform layout for its WGSL entry point; and the CPU
//! references written from the math in SPEC (`src/cpu/`), built twice: in
//! f64 as the oracles ([`cpu64`], re-exported by each kernel module) and in
//! f32 as the throughput baseline ([`cpu32`]).
//!
//! Not for: GPU work (see `vista-gpu`), files or goldens (see `vista-golden`).
//! Kernels never touch the file system.

/// Declares the CPU reference modules of `src/cpu/` for one float type: the
/// same source compiled once per precision, so the f32 baseline cannot drift
/// from the f64 oracle. Literals take the type from context; code names the
/// float type `Real` and glam's 3-vector `Vec3`.
macro_rules! cpu_references {
    ($real:ident, $vec3:ty) => {
        /// The float type this build computes in.
        pub type Real = $real;
        /// glam's 3-vector of [`Real`].
        pub type Vec3 = $vec3;
        pub use std::$real::consts;
        #[path = "cpu/common.rs"]
        mod common;
        pub use common::*;
        #[path = "cpu/atmosphere.rs"]
        pub mod atmosphere;
        #[path = "cpu/clouds.rs"]
        pub mod clouds;
        #[path = "cpu/fbm.rs"]
        pub mod fbm;
        #[path = "cpu/geometry.rs"]
        pub mod geometry;
        #[path = "cpu/heightfield.rs"]
        pub mod heightfield;
        #[path = "cpu/noise.rs"]
        pub mod noise;
        #[path = "cpu/phase.rs"]
        pub mod phase;
        #[path = "cpu/ridged.rs"]
        pub mod ridged;
    };
}

pub mod cpu32;
pub mod cpu64;

pub mod atmosphere;
pub mod clouds;
pub mod fbm;
pub mod heightfield;
pub mod noise;
pub mod params;
pub mod phase;
pub mod ridged;
mod uniforms;

pub use cpu64::geometry;
pub use cpu64::{pixel_uv, render_cpu};
pub use params::{Kind, ParamSet, ParamSpec, Preset, Value};
pub use uniforms::{Field, Uniforms};
use vista_image::Image;

/// Everything that can be wrong with a kernel, preset, parameter or size
/// request. Messages name the bad value and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    #[error("unknown kernel '{name}'; valid kernels: {valid}")]
    UnknownKernel { name: String, valid: String },
    #[error("kernel {kernel} has no preset '{name}'; valid presets: {valid}")]
    UnknownPreset { kernel: String, name: String, valid: String },
    #[error("kernel {kernel} has no parameter '{name}'; valid parameters: {valid}")]
    UnknownParam { kernel: String, name: String, valid: String },
    #[error("{param}={value} is out of range; allowed: {range}")]
    OutOfRange { param: String, value: String, range: String },
    #[error("{param}={value} is not valid; expected {expected}")]
    BadValue { param: String, value: String, expected: String },
    #[error("{0}")]
    Invalid(String),
}

/// How the raw GPU output is turned into display values for PNG goldens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// The kernel writes display values in [0, 1] directly.
    Display,
    /// The kernel writes linear radiance; display = tonemap(exposure).
    Hdr,
}

/// One kernel. Implementations are stateless unit structs in the registry.
pub trait Kernel: Send + Sync {
    fn name(&self) -> &'static str;
    /// One line for `vista list`.
    fn summary(&self) -> &'static str;
    fn params(&self) -> &'static [ParamSpec];
    fn presets(&self) -> &'static [Preset];
    /// WGSL file under `shaders/` holding the `main` compute entry point.
    fn shader(&self) -> &'static str;
    fn output(&self) -> Output {
        Output::Display
    }
    /// Cross-parameter checks beyond each value's own range.
    fn check(&self, _p: &ParamSet) -> Result<(), ParamError> {
        Ok(())
    }
    /// Uniform block (binding 0) for the WGSL `Params` struct.
    fn uniforms(&self, p: &ParamSet, width: u32, height: u32) -> Uniforms;
    /// Read-only u32 table (binding 2); the Perlin permutation for noise kernels.
    fn table(&self, _p: &ParamSet) -> Vec<u32> {
        vec![0; 4]
    }
    /// Rough count of inner-loop evaluations per pixel, used to refuse absurd
    /// dispatches before they can stall the device.
    fn work_per_pixel(&self, p: &ParamSet) -> f64;
    /// The f64 CPU reference of the raw output (what the GPU writes).
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image;
    /// The same reference computed in f32 ([`cpu32`]): a throughput
    /// baseline for benches, not an oracle.
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image;
    /// Inclusive bounds every RGB value of the raw output must respect.
    fn output_bounds(&self, _p: &ParamSet) -> (f32, f32) {
        (0.0, 1.0)
    }
    /// Settings of the high-quality reference that sweeps compare against.
    fn high_quality(&self) -> &'static [(&'static str, &'static str)] {
        &[]
    }

    /// Defaults, preset and overrides, validated (ranges and `check`).
    fn resolve(&self, preset: Option<&str>, overrides: &[(String, String)]) -> Result<ParamSet, ParamError> {
        let set = ParamSet::resolve(self.name(), self.params(), self.presets(), preset, overrides)?;
        self.check(&set)?;
        Ok(set)
    }

    /// Raw output to display values in [0, 1].
    fn display(&self, raw: &Image, p: &ParamSet) -> Image {
        match self.output() {
            Output::Display => raw.clone(),
            Output::Hdr => vista_image::tonemap(raw, p.f32("exposure")),
        }
    }
}

impl std::fmt::Debug for dyn Kernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// All kernels, in the order `vista list` shows them.
pub fn registry() -> &'static [&'static dyn Kernel] {
    &[
        &fbm::FbmKernel,
        &ridged::RidgedKernel,
        &atmosphere::AtmosphereKernel,
        &clouds::CloudsKernel,
        &heightfield::HeightfieldKernel,
    ]
}

/// Looks a kernel up by name.
pub fn find(name: &str) -> Result<&'static dyn Kernel, ParamError> {
    registry().iter().copied().find(|k| k.name() == name).ok_or_else(|| ParamError::UnknownKernel {
        name: name.to_string(),
        valid: registry().iter().map(|k| k.name()).collect::<Vec<_>>().join(", "),
    })
}

/// Largest width or height any request may ask for. Devices limit 2D storage
/// textures to 8192 by default, and the check happens before GPU work.
pub const MAX_DIMENSION: u32 = 8192;

/// Validates an image size before any GPU work.
pub fn check_size(width: u32, height: u32) -> Result<(), ParamError> {
    for (what, v) in [("width", width), ("height", height)] {
        if v == 0 || v > MAX_DIMENSION {
            return Err(ParamError::OutOfRange {
                param: what.to_string(),
                value: v.to_string(),
                range: format!("[1, {MAX_DIMENSION}]"),
            });
        }
    }
    Ok(())
}

/// Parses `WxH` (e.g. `256x256`).
pub fn parse_size(text: &str) -> Result<(u32, u32), ParamError> {
    let bad = || ParamError::BadValue {
        param: "size".into(),
        value: text.into(),
        expected: format!("WIDTHxHEIGHT with each in [1, {MAX_DIMENSION}], e.g. 256x256"),
    };
    let (w, h) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    check_size(w, h)?;
    Ok((w, h))
}
