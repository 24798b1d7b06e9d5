//! `ridged`: Musgrave's ridged multifractal (SPEC 3.3), normalised to [0, 1].
//! Params, presets and layout live in `kernels/ridged.toml`.

pub use crate::cpu64::ridged::{ridged_max, ridged_of};
use crate::{CpuReference, ParamSet};
use vista_image::Image;

/// The built-in `ridged` kernel (derefs to its [`Kernel`](crate::Kernel)).
pub struct RidgedKernel;
crate::builtin_handle!(RidgedKernel, "ridged");

impl CpuReference for RidgedKernel {
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::ridged::render(p, width, height)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::ridged::render(p, width, height)
    }
}
