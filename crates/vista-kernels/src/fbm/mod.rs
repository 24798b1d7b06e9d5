//! `fbm`: 2D fractional Brownian motion over a noise basis (SPEC 3.2).
//! Params, presets and layout live in `kernels/fbm.toml`; this module is
//! the Rust side that data cannot say.

pub use crate::cpu64::fbm::{fbm_of, noise_of};
use crate::{CpuReference, ParamError, ParamSet};
use vista_image::Image;

/// The built-in `fbm` kernel (derefs to its [`Kernel`](crate::Kernel)).
pub struct FbmKernel;
crate::builtin_handle!(FbmKernel, "fbm");

impl CpuReference for FbmKernel {
    fn check(&self, p: &ParamSet) -> Result<(), ParamError> {
        if fbm_of(p).amplitude_sum() <= 0.0 {
            return Err(ParamError::Invalid("fbm: amplitude sum is 0".into()));
        }
        Ok(())
    }
    /// |f| <= A * max|N|, and 3D perlin (non-integer z_slice) exceeds 1 slightly.
    fn output_bounds(&self, p: &ParamSet) -> Option<(f32, f32)> {
        let m = noise_of(p).max_abs();
        Some(((0.5 - 0.5 * m) as f32, (0.5 + 0.5 * m) as f32))
    }
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::fbm::render(p, width, height)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::fbm::render(p, width, height)
    }
}
