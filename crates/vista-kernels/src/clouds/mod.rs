//! `clouds`: a volumetric cloud layer, ray marched (SPEC 3.6).
//!
//! Geometry (`layer`): a flat-earth slab between `cloud_base_km` and
//! `cloud_top_km`, y up, or a shell between the spheres of radius R + base
//! and R + top around the atmosphere's planet (R = 6360 km, centred under
//! the camera: the camera stands at the planet's top as in the sky), where a
//! point's height in the layer is its altitude |p - centre| - R; all
//! lengths in kilometres (extinction in 1/km). A pinhole camera
//! (SPEC 3.4 conventions: forward from yaw/pitch, vertical fov) looks into a
//! sky gradient (horizon + (zenith - horizon) clamp(d.y, 0, 1)); every ray
//! that meets the slab is marched in `steps` equal steps of length dt over
//! its part inside the slab (cut at `max_distance_km`), sample k at
//! t0 + (k + xi) dt with xi = 0.5 (midpoint rule) or a per-pixel jitter
//! hash. Two options move the samples: `step_spread` > 1 makes
//! the steps grow geometrically from t0 (step k spans the fractions
//! (r^k - 1) / (r^n - 1) to (r^(k+1) - 1) / (r^n - 1) of the segment,
//! r = step_spread^(1 / (n - 1)), each sample xi of its step in), and
//! `jitter_steps = golden` offsets step k by fract(xi + k / phi) instead of
//! xi; a third, `step_km` > 0, gives each ray ceil(segment / step_km) steps
//! (at most `steps`) instead of `steps`. At every sample that holds cloud a `light_steps` midpoint march
//! toward the sun, up to the slab top, gives tau_sun; its steps grow
//! geometrically (last / first = `light_spread`, 1 = uniform), see
//! [`light_step_layout`]. Azimuths (yaw, sun) run from +z toward +x.
//!
//! Density d(p) = density_scale * height_profile(h) *
//! max(0, remap(G(q), 1 - coverage, 1, 0, 1)), q = p * noise_scale *
//! noise_stretch + wind_offset, G = 0.5 + 0.5 fbm3(q) / A: the 3D fBm of
//! `basis` (perlin or value noise) normalised by its amplitude sum A and mapped to [0, 1] exactly like
//! the `fbm` kernel's output, so `coverage` means the same at every octave
//! count and reads as a cloud fraction (0.5: about half of the volume is
//! cloud, 1: all of it, 0: none). sigma_s = d, sigma_t = (1 + absorption) d.
//!
//! In-scattered radiance per unit sigma_s at a sample:
//! Lin = E_sun * P(mu) * T_sun * (1 - powder * exp(-2 tau_sun)) + ambient *
//! (ambient_bottom + (1 - ambient_bottom) h), with P the dual-lobe HG phase
//! and mu = cos(view direction, direction to the sun). Output: rgb =
//! L_cloud + T * background, alpha = 1 - T (linear radiance, Output::Hdr;
//! the PNG display is opaque, see `display`).
//!
//! Per step: riemann adds T sigma_s Lin dt; analytic adds T sigma_s Lin
//! (1 - exp(-sigma_t dt)) / sigma_t (Hillaire 2016; -> dt as sigma_t -> 0);
//! then T *= exp(-sigma_t dt). A ray stops (T = 0) once T < [`T_CUTOFF`].
//!
//! The CPU reference, written from these formulas, is `clouds/cpu.rs`
//! (its f64 build is re-exported here); the WGSL in `shaders/clouds.wgsl`
//! does the same in f32.

pub use crate::cpu64::clouds::*;
pub use crate::cpu64::geometry::direction;
use crate::{CpuReference, ParamError, ParamSet};
use vista_image::Image;

/// How a primary step's in-scattering is integrated (`integrator`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integrator {
    /// T sigma_s Lin dt per step.
    Riemann,
    /// T sigma_s Lin (1 - exp(-sigma_t dt)) / sigma_t per step (Hillaire 2016):
    /// exact when density and Lin are constant over the step.
    Analytic,
}

/// The first-sample offset xi of a pixel's ray, in steps (`jitter`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Jitter {
    /// xi = 0.5 for every pixel: the midpoint rule.
    None,
    /// White noise in [0, 1): pcg3d of (x, y, jitter_seed).
    White,
    /// Interleaved gradient noise (Jimenez 2014), shifted by jitter_seed.
    Ign,
}

/// Where in its step each primary sample sits: the same offset xi for every
/// step, or fract(xi + k / phi) for step k (golden-ratio offsets).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JitterSteps {
    /// Every step's sample at xi.
    Shared,
    /// Step k's sample at fract(xi + k / phi).
    Golden,
}

/// Each `integrator` value's meaning (for [`ParamSet::choice_in`]).
pub const INTEGRATORS: &[(&str, Integrator)] = &[("riemann", Integrator::Riemann), ("analytic", Integrator::Analytic)];
/// Each `jitter` value's meaning.
pub const JITTERS: &[(&str, Jitter)] = &[("none", Jitter::None), ("white", Jitter::White), ("ign", Jitter::Ign)];
/// Each `jitter_steps` value's meaning.
pub const JITTER_STEPS: &[(&str, JitterSteps)] = &[("shared", JitterSteps::Shared), ("golden", JitterSteps::Golden)];
/// Each `profile` value's meaning.
pub const PROFILES: &[(&str, Profile)] =
    &[("stratiform", Profile::Stratiform), ("cumuliform", Profile::Cumuliform), ("anvil", Profile::Anvil)];

/// The cloud layer's geometry: a flat slab between the altitudes base and
/// top (y), or a shell between the spheres of radius R + base and R + top
/// around the atmosphere's planet (R = 6360 km, centre (camera x, -R,
/// camera z): the camera stands at the planet's top, as in the sky).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layer {
    /// Flat, between the altitudes base and top (y).
    Slab,
    /// Between the spheres of radius R + base and R + top.
    Shell,
}

impl Layer {
    /// The layer named by an enum param's value; `None` for any other name.
    pub fn from_name(name: &str) -> Option<Layer> {
        match name {
            "slab" => Some(Layer::Slab),
            "shell" => Some(Layer::Shell),
            _ => None,
        }
    }
}

/// The cloud's height profile (`profile`): a rounded plateau over the
/// normalised height h in the layer, shaped as [`height_profile`] says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Profile {
    /// The plateau alone.
    Stratiform,
    /// The plateau times (1 - 0.5 h): dense base, thinner top.
    Cumuliform,
    /// The plateau times 0.45 + 0.55 smoothstep(0.5, 0.7, h): a dense upper band.
    Anvil,
}

/// The [`Layer`] an enum param names, or the error naming its value and
/// the allowed ones.
pub fn layer_of(p: &ParamSet, param: &str) -> Result<Layer, ParamError> {
    let name = p.choice(param);
    Layer::from_name(name)
        .ok_or_else(|| ParamError::Invalid(format!("{param}={name} is not a cloud layer; allowed: slab, shell")))
}

/// The `cloud` group of built-in kernel `kernel`'s manifest (the params
/// that fill its uniform's `CloudParams`): the CPU references read the
/// group's leaves through the same rule as the GPU's packing. A project
/// manifest gets a built-in's reference only with the built-in's groups.
///
/// # Panics
/// If the built-in manifest has no `cloud` group.
pub fn cloud_group(kernel: &str) -> &'static crate::manifest::ParamGroup {
    crate::Registry::builtin()
        .find(kernel)
        .ok()
        .and_then(|k| k.group("cloud"))
        .unwrap_or_else(|| panic!("built-in kernel {kernel} has no [[group]] field = \"cloud\""))
}

/// The built-in `clouds` kernel (derefs to its [`Kernel`](crate::Kernel);
/// params, presets and layout live in `kernels/clouds.toml`).
pub struct CloudsKernel;
crate::builtin_handle!(CloudsKernel, "clouds");

/// The longest primary step any ray can take (km). A ray of n steps spans at
/// most max_distance, and with step_km > 0 and n < steps at most n step_km;
/// its last step is the longest, the part of it past the first n - 1.
fn longest_step(c: &Clouds) -> f64 {
    let n_all = if c.step_km > 0.0 { 1..=c.steps } else { c.steps..=c.steps };
    n_all
        .map(|n| {
            let span =
                if c.step_km > 0.0 && n < c.steps { c.max_distance.min(n as f64 * c.step_km) } else { c.max_distance };
            span * (1.0 - StepLayout::new(n, c.step_spread).end(n - 1))
        })
        .fold(0.0, f64::max)
}

impl CpuReference for CloudsKernel {
    fn check(&self, p: &ParamSet) -> Result<(), ParamError> {
        let (base, top) = (p.f64("cloud_base_km"), p.f64("cloud_top_km"));
        if top <= base {
            return Err(ParamError::Invalid(format!("clouds: cloud_top_km={top} must be above cloud_base_km={base}")));
        }
        layer_of(p, "layer").map(|_| ())
    }
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::clouds::render(p, width, height)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::clouds::render(p, width, height)
    }
    fn mean_work_per_pixel(&self, p: &ParamSet, width: u32, height: u32) -> Option<f64> {
        Some(Clouds::from_params(p).mean_work(width, height))
    }
    fn output_bounds(&self, p: &ParamSet) -> Option<(f32, f32)> {
        // Analytic: L <= max Lin. Riemann: sum T_k x_k <= X / (1 - e^-X) <=
        // 1 + X with X the largest optical depth of one step.
        let c = Clouds::from_params(p);
        let x_max = c.density_scale * (1.0 + c.absorption) * longest_step(&c);
        let bg = c.sky_zenith.iter().chain(&c.sky_horizon).cloned().fold(0.0, f64::max);
        let hi = c.max_l_in() * (1.0 + x_max) + bg;
        Some((0.0, (hi * 1.001 + 1e-6) as f32))
    }
}
