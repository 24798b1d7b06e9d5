//! `landscape`: the seed's whole frame as one kernel.
//!
//! The scene is the heightfield kernel's terrain (ridged by default; same
//! march, refinement, normals, soft shadow and surface shading), under the
//! atmosphere kernel's sky, with the clouds kernel's slab, composed along
//! each view ray in depth order. Lengths in km (y up, sea level = the
//! terrain's 0 = the planet's ground); the atmosphere in m, its camera at
//! altitude 1000 camera_pos.y with the same direction vectors (flat terrain
//! and slab, spherical planet).
//!
//! With the terrain hit at t_hit (else the end of the atmosphere's view
//! segment) and the slab's part [c0, c1] of the ray cut at t_hit:
//!
//! L = A[0, c0] + T[0, c0] (L_cloud + T_cloud (A[c1, end] + T[c1, end] L_surface))
//!
//! where A and T are the atmosphere reference's in-scatter and transmittance
//! of that part of the ray (`view_samples` midpoint steps each; seed 002 eq.
//! 3.25: aerial perspective is the sky integral ending at the hit) and
//! L_surface = the heightfield shading with sun colour E_sun / pi x T_sun(x)
//! x T_slab(x) (T_sun: the atmosphere's transmittance toward the sun from the
//! hit; T_slab = exp(-tau) of the clouds' light march from it: the cloud
//! shadow) and ambient `ground_ambient`. The clouds are lit by E_sun x T_sun
//! at the middle of their segment. Without clouds (coverage or density 0, or
//! no slab segment) a ray is one atmosphere segment, so with zero terrain
//! amplitude and `projection = latlong` the kernel is the atmosphere kernel
//! above the horizon, and without air or clouds it is the heightfield
//! kernel's shading under a white sun (`sun_intensity` = pi).
//!
//! The CPU reference (`landscape/cpu.rs`, its f64 build re-exported
//! here) composes the three references; the WGSL (`shaders/landscape.wgsl`)
//! composes the three `shaders/lib` modules the kernels share.

pub use crate::cpu64::landscape::*;
use crate::heightfield::HitSearch;
use crate::{CpuReference, ParamError, ParamSet};
use vista_image::Image;

/// The built-in `landscape` kernel (derefs to its [`Kernel`](crate::Kernel);
/// params, presets and layout live in `kernels/landscape.toml`).
pub struct LandscapeKernel;
crate::builtin_handle!(LandscapeKernel, "landscape");

impl CpuReference for LandscapeKernel {
    /// The slab must have thickness, and the camera must sit in the
    /// atmosphere kernel's range of altitudes (0 to 100 km above sea level):
    /// below the ground sphere the sky integral has no meaning.
    fn check(&self, p: &ParamSet) -> Result<(), ParamError> {
        let y = p.vec3("camera_pos")[1];
        if !(0.0..=100.0).contains(&y) {
            return Err(ParamError::Invalid(format!(
                "landscape: camera_pos y = {y} km is outside [0, 100] (altitude above sea level, the atmosphere's range)"
            )));
        }
        let (base, top) = (p.f64("cloud_base_km"), p.f64("cloud_top_km"));
        if top <= base {
            return Err(ParamError::Invalid(format!(
                "landscape: cloud_top_km={top} must be above cloud_base_km={base}"
            )));
        }
        crate::clouds::layer_of(p, "cloud_layer").map(|_| ())
    }
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::landscape::render(p, width, height, HitSearch::BruteForce)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::landscape::render(p, width, height, HitSearch::BruteForce)
    }
    /// The oracle finds terrain hits by a fixed-step search; the shader's
    /// relax march is the fair baseline.
    fn shader_algorithm_f32(&self, p: &ParamSet, width: u32, height: u32) -> Option<Image> {
        Some(crate::cpu32::landscape::render(p, width, height, HitSearch::RelaxMarch))
    }
}
