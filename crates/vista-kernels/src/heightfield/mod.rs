//! `heightfield`: sphere-traced terrain (SPEC 3.4).
//!
//! World unit: **1 unit = 1 km** everywhere (camera position, heights,
//! `amplitude`, `t_max`, `shadow_distance`, the fog's `visibility_km`);
//! `scale` is in 1/km. Terrain y = h(x, z) = amplitude * T(x * scale, z * scale)
//! with T = fbm / A (about [-1, 1]) or ridged / ridged_max ([0, 1]), frequency
//! 1 and z_slice 0 inside T. Two analytic terrains exist for the invariant
//! tests (SPEC 9): `plane` (h = amplitude + s x + r z) and `sine`
//! (h = amplitude * sin(x * scale) * cos(z * scale), slope bound amplitude * scale).
//!
//! The GPU marches t_{k+1} = t_k + relax * (p.y - h(p.xz)) from t_0 = 0 and
//! stops at the first sample with p.y - h < eps * t (hit), t > t_max (miss) or
//! k = max_steps (miss: so raising max_steps only ever adds hits). A hit is
//! refined by interpolating the height above the terrain, D(t), between the
//! last two samples to its zero, repeated with the newest two points until
//! |D| <= eps t / 100 (secant steps while above the terrain, Illinois false
//! position keeping the sign change once a point is under it; at most
//! [`REFINE_ITERS`] passes; the point with the smallest |D| is the hit).
//!
//! The CPU reference is independent of `relax` and `max_steps`: it samples
//! D at the fixed step t_max / [`BRUTE_STEPS`] (5 m at t_max = 20 km, 15 m at
//! the grazing preset's 60 km; 4096 samples keep a 64 x 40 reference under a
//! second, the f64 fbm being the cost) and bisects the first crossing of the
//! same hit rule, D < eps t; inside that band it bisects the zero of D if the
//! ray goes under the terrain before leaving it (the march's refined hit),
//! else keeps the band entry (a ray grazing a crest within eps t). Then it
//! shades exactly like the GPU. Only `view = steps` uses the f64 relax march,
//! since the step count is a property of that march. A "miss" on the GPU
//! when max_steps runs out is the reason the reference can see hits the
//! march does not.
//!
//! Presets: `valley` (fbm), `ridges` (ridged), `grazing` (camera 0.1 km above
//! sharp ridged crests, near-horizontal rays, t_max 60 km: relax = 1 steps
//! over crests there), `fog` (V = 0.6 km, below 1 km) and `mist` (V = 3 km,
//! in 1-5 km).
//!
//! Shading: normal from central differences of h (step max(eps t, 1e-4 (1 +
//! max(|x|, |z|))) so it stays above f32 resolution), Lambert sun with a soft
//! shadow, hemispherical sky ambient, exponential fog toward the horizon
//! colour with extinction sigma = 3.912 / visibility_km (contrast 2% at the
//! visibility distance), then a 1/2.2 display gamma. The soft shadow marches
//! from the surface point (p.x, h(p.xz), p.z) toward the sun at the fixed
//! distances t_i = shadow_distance * ((i + 1) / shadow_steps)^2 (dense near
//! the surface, where self-shadowing is decided) and takes
//! smoothstep(clamp(min_i softness * D_i / t_i, 0, 1)); fixed sample
//! positions keep the GPU and the f64 reference on the same function.

pub use crate::cpu64::geometry::{Camera, V3};
pub use crate::cpu64::heightfield::*;
use crate::{CpuReference, ParamError, ParamSet};
use vista_image::Image;

/// Samples over [0, t_max] in the brute-force reference march.
pub const BRUTE_STEPS: u32 = 4096;
/// Most interpolation passes of the hit refinement.
pub const REFINE_ITERS: u32 = 16;
// ---------------------------------------------------------------- terrain

/// The terrain's height function T (`terrain`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TerrainKind {
    /// fBm / A, A the amplitude sum: about [-1, 1].
    Fbm,
    /// Ridged multifractal / its analytic maximum: [0, 1].
    Ridged,
    /// The analytic plane h = amplitude + s x + r z (an invariant-test terrain).
    Plane,
    /// The analytic h = amplitude sin(x scale) cos(z scale) (an invariant-test terrain).
    Sine,
}

/// How a CPU pixel finds its terrain hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HitSearch {
    /// Fixed steps plus bisection, independent of relax and max_steps: the
    /// oracle the GPU is tested against.
    BruteForce,
    /// The relax march and refinement the shader runs: the CPU doing the
    /// GPU's work, the fair throughput baseline.
    RelaxMarch,
}

/// The built-in `heightfield` kernel (derefs to its [`Kernel`](crate::Kernel);
/// params, presets and layout live in `kernels/heightfield.toml`).
pub struct HeightfieldKernel;
crate::builtin_handle!(HeightfieldKernel, "heightfield");

impl CpuReference for HeightfieldKernel {
    /// The camera must have a defined basis; the aspect ratio does not
    /// affect that, so 1:1 is enough here.
    fn check(&self, p: &ParamSet) -> Result<(), ParamError> {
        camera_of(p, 1, 1).map(|_| ())
    }
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::heightfield::render(p, width, height, HitSearch::BruteForce)
            .expect("heightfield: parameters not validated by check()")
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::heightfield::render(p, width, height, HitSearch::BruteForce)
            .expect("heightfield: parameters not validated by check()")
    }
    /// Depth, steps and normal views are in [0, 1]; colour is bounded by the
    /// brightest albedo under full sun and ambient (about 0.9964, unclamped).
    fn output_bounds(&self, p: &ParamSet) -> Option<(f32, f32)> {
        let hi =
            if p.choice("view") == "color" { max_encoded_colour(p.vec3("sun_color")) as f32 * 1.0001 } else { 1.0 };
        Some((0.0, hi))
    }
    /// The oracle marches with fixed steps; the shader's relax march is the fair baseline.
    fn shader_algorithm_f32(&self, p: &ParamSet, width: u32, height: u32) -> Option<Image> {
        crate::cpu32::heightfield::render(p, width, height, HitSearch::RelaxMarch).ok()
    }
}
