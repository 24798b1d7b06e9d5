//! `cloudmap`: Hugo Elias's 2D cloud map, a built-in added as data
//! (`kernels/cloudmap.toml`, `shaders/cloudmap.wgsl`); its only Rust is the
//! CPU reference (`cloudmap/cpu.rs`), registered by name.

pub use crate::cpu64::cloudmap::*;
use crate::{CpuReference, ParamSet};
use vista_image::Image;

/// Largest |dN/dz| of value noise: the quintic fade's slope peaks at
/// 30/16 = 1.875 and the two interpolated z planes differ by less than 2.
pub const VALUE_NOISE_DZ_BOUND: f64 = 3.75;

/// Bound on |d(time + dt) - d(time)| for value noise: |dn/dz| <= 0.5 *
/// (sum gain^i 3.75) / A = 1.875 (z is not scaled per octave, and A
/// cancels), and |dd/dn| <= 255 (-ln s), so |dd| <= 255 (-ln s) 1.875 |dt|.
pub fn frame_change_bound(sharpness: f64, dt: f64) -> f64 {
    255.0 * -sharpness.ln() * 0.5 * VALUE_NOISE_DZ_BOUND * dt.abs()
}

/// The built-in `cloudmap` kernel (derefs to its [`Kernel`](crate::Kernel)).
pub struct CloudmapKernel;
crate::builtin_handle!(CloudmapKernel, "cloudmap");

impl CpuReference for CloudmapKernel {
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::cloudmap::render(p, width, height)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::cloudmap::render(p, width, height)
    }
    /// d < 1 - s^255 < 1.
    fn output_bounds(&self, p: &ParamSet) -> Option<(f32, f32)> {
        Some((0.0, (1.0 - p.f64("sharpness").powi(255)) as f32))
    }
}
