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
//! The CPU reference (`src/cpu/atmosphere.rs`, re-exported here in its f64
//! build) evaluates the same discrete scheme with explicit 3D positions
//! (|p| - R_ground for altitudes); the WGSL works in f32 from camera-relative
//! scalars (see shaders/atmosphere.wgsl), so the two meet only through the
//! math.

use vista_image::Image;

pub use crate::cpu64::atmosphere::*;
use crate::{Kernel, Kind, Output, ParamSet, ParamSpec, Preset, Uniforms};

pub const PROJECTIONS: &[&str] = &["latlong", "fisheye"];

const PARAMS: &[ParamSpec] = &[
    ParamSpec::new("view_samples", Kind::int(1, 1024), "32", "midpoint steps along the view ray"),
    ParamSpec::new("light_samples", Kind::int(1, 256), "8", "midpoint steps toward the sun per view step"),
    ParamSpec::new("sun_elevation_deg", Kind::float(-10.0, 90.0), "30", "sun elevation at azimuth 0 (degrees)"),
    ParamSpec::new("camera_altitude_m", Kind::float(0.0, 100_000.0), "1000", "camera height above the ground (m)"),
    ParamSpec::new("sun_intensity", Kind::float(0.0, 1000.0), "20", "E_sun, irradiance of the sun"),
    ParamSpec::new("mie_g", Kind::float(-0.99, 0.99), "0.8", "Henyey-Greenstein asymmetry g of the Mie phase"),
    ParamSpec::new("exposure", Kind::float(0.0, 1000.0), "1.5", "display = 1 - exp(-exposure * L), then sRGB"),
    ParamSpec::new(
        "projection",
        Kind::Enum(PROJECTIONS),
        "latlong",
        "latlong: azimuth 2 pi u, elevation (pi/2)(1 - v); fisheye: equidistant, zenith at the centre, sun up",
    ),
];

const PRESETS: &[Preset] = &[
    Preset { name: "noon", doc: "sun at 60 deg", set: &[("sun_elevation_deg", "60")] },
    Preset { name: "afternoon", doc: "sun at 30 deg (the defaults)", set: &[("sun_elevation_deg", "30")] },
    Preset {
        name: "sunset",
        doc: "sun at 2 deg: red horizon toward the sun, exposure 2.5",
        set: &[("sun_elevation_deg", "2"), ("exposure", "2.5")],
    },
    Preset {
        name: "twilight",
        doc: "sun 4 deg below the horizon (Earth shadow), exposure raised",
        set: &[("sun_elevation_deg", "-4"), ("exposure", "40")],
    },
    Preset {
        name: "high_altitude",
        doc: "camera at 20 km, sun at 30 deg: darker, deeper blue sky",
        set: &[("camera_altitude_m", "20000"), ("sun_elevation_deg", "30"), ("exposure", "4")],
    },
];

pub struct AtmosphereKernel;

impl Kernel for AtmosphereKernel {
    fn name(&self) -> &'static str {
        "atmosphere"
    }
    fn summary(&self) -> &'static str {
        "single-scattering Rayleigh + Mie sky (linear radiance, HDR)"
    }
    fn params(&self) -> &'static [ParamSpec] {
        PARAMS
    }
    fn presets(&self) -> &'static [Preset] {
        PRESETS
    }
    fn shader(&self) -> &'static str {
        "atmosphere.wgsl"
    }
    fn output(&self) -> Output {
        Output::Hdr
    }
    fn uniforms(&self, p: &ParamSet, width: u32, height: u32) -> Uniforms {
        let sky = Sky::from_params(p);
        let alt = sky.camera_altitude;
        Uniforms::new(width, height)
            .u32("projection", p.choice_index("projection", PROJECTIONS))
            .u32("view_samples", sky.view_samples)
            .u32("light_samples", sky.light_samples)
            .f32("camera_radius", (R_GROUND + alt) as f32)
            // |c|^2 - R_ground^2, exact here; f32 on the GPU could not form it.
            .f32("camera_k", (alt * (2.0 * R_GROUND + alt)) as f32)
            .f32("sun_y", sky.sun.y as f32)
            .f32("sun_z", sky.sun.z as f32)
            .f32("sun_intensity", sky.sun_intensity as f32)
            .f32("mie_g", sky.mie_g as f32)
    }
    fn work_per_pixel(&self, p: &ParamSet) -> f64 {
        p.f64("view_samples") * (1.0 + p.f64("light_samples"))
    }
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::atmosphere::render(p, width, height)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::atmosphere::render(p, width, height)
    }
    /// The midpoint sums are bounded by E_sun * max phase: each step adds at
    /// most sigma dt exp(-sigma dt / 2) <= 1 - exp(-sigma dt) of the remaining
    /// transmittance (scattering <= extinction, T_sun <= 1). 1% slack for f32.
    fn output_bounds(&self, p: &ParamSet) -> (f32, f32) {
        (0.0, (1.01 * p.f64("sun_intensity") * max_phase(p.f64("mie_g"))) as f32)
    }
    fn high_quality(&self) -> &'static [(&'static str, &'static str)] {
        &[("view_samples", "512"), ("light_samples", "128")]
    }
}
