//! `atmosphere`: single-scattering Rayleigh + Mie sky (SPEC 3.5).
//!
//! Planet centred at the origin, y up, camera at (0, R_ground + altitude, 0).
//! Radiance toward the camera along v:
//!
//! L = E_sun * int_{t0}^{t1} T(c, c + t v) (beta_R rho_R P_R + beta_M rho_M P_HG) T_sun(c + t v) dt
//!
//! discretised with the midpoint rule: `view_samples` steps along the view
//! ray, `light_samples` steps toward the sun at every view sample. The view
//! transmittance to the midpoint t_i uses the sums of the previous steps plus
//! half of step i, so the whole scheme is second order in the step length.
//! The CPU reference (`atmosphere/cpu.rs`, re-exported here in its f64
//! build) evaluates the same discrete scheme with explicit 3D positions
//! (|p| - R_ground for altitudes); the WGSL works in f32 from camera-relative
//! scalars it derives from the params itself (see shaders/atmosphere.wgsl),
//! so the two meet only through the math.

use vista_image::Image;

pub use crate::cpu64::atmosphere::*;
use crate::{CpuReference, ParamSet};

/// The built-in `atmosphere` kernel (derefs to its [`Kernel`](crate::Kernel);
/// params, presets and layout live in `kernels/atmosphere.toml`).
pub struct AtmosphereKernel;
crate::builtin_handle!(AtmosphereKernel, "atmosphere");

impl CpuReference for AtmosphereKernel {
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::atmosphere::render(p, width, height)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::atmosphere::render(p, width, height)
    }
    /// The midpoint sums are bounded by E_sun * max phase: each step adds at
    /// most sigma dt exp(-sigma dt / 2) <= 1 - exp(-sigma dt) of the remaining
    /// transmittance (scattering <= extinction, T_sun <= 1). 1% slack for f32.
    fn output_bounds(&self, p: &ParamSet) -> Option<(f32, f32)> {
        Some((0.0, (1.01 * p.f64("sun_intensity") * max_phase(p.f64("mie_g"))) as f32))
    }
}
