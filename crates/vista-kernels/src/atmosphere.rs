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
//! The CPU reference evaluates the same discrete scheme in f64 with explicit
//! 3D positions (|p| - R_ground for altitudes); the WGSL works in f32 from
//! camera-relative scalars (see shaders/atmosphere.wgsl), so the two meet only
//! through the math.

use std::f64::consts::PI;

use glam::DVec3;
use vista_image::Image;

use crate::phase::{hg, rayleigh};
use crate::{Kernel, Kind, Output, ParamSet, ParamSpec, Preset, Uniforms, render_cpu};

/// Ground radius (m).
pub const R_GROUND: f64 = 6_360_000.0;
/// Top-of-atmosphere radius (m).
pub const R_TOP: f64 = 6_420_000.0;
/// Rayleigh scattering = extinction (no absorption), per m, RGB.
pub const BETA_R: [f64; 3] = [5.802e-6, 13.558e-6, 33.1e-6];
/// Rayleigh scale height (m).
pub const H_R: f64 = 8000.0;
/// Mie scattering coefficient (per m).
pub const BETA_M: f64 = 3.996e-6;
/// Mie extinction = 1.11 * scattering (per m).
pub const BETA_M_EXT: f64 = 1.11 * BETA_M;
/// Mie scale height (m).
pub const H_M: f64 = 1200.0;

pub const PROJECTIONS: &[&str] = &["latlong", "fisheye"];

const PARAMS: &[ParamSpec] = &[
    ParamSpec::new(
        "view_samples",
        Kind::int(1, 1024),
        "32",
        "midpoint steps along the view ray",
    ),
    ParamSpec::new(
        "light_samples",
        Kind::int(1, 256),
        "8",
        "midpoint steps toward the sun per view step",
    ),
    ParamSpec::new(
        "sun_elevation_deg",
        Kind::float(-10.0, 90.0),
        "30",
        "sun elevation at azimuth 0 (degrees)",
    ),
    ParamSpec::new(
        "camera_altitude_m",
        Kind::float(0.0, 100_000.0),
        "1000",
        "camera height above the ground (m)",
    ),
    ParamSpec::new(
        "sun_intensity",
        Kind::float(0.0, 1000.0),
        "20",
        "E_sun, irradiance of the sun",
    ),
    ParamSpec::new(
        "mie_g",
        Kind::float(-0.99, 0.99),
        "0.8",
        "Henyey-Greenstein asymmetry g of the Mie phase",
    ),
    ParamSpec::new(
        "exposure",
        Kind::float(0.0, 1000.0),
        "1.5",
        "display = 1 - exp(-exposure * L), then sRGB",
    ),
    ParamSpec::new(
        "projection",
        Kind::Enum(PROJECTIONS),
        "latlong",
        "latlong: azimuth 2 pi u, elevation (pi/2)(1 - v); fisheye: equidistant, zenith at the centre, sun up",
    ),
];

const PRESETS: &[Preset] = &[
    Preset {
        name: "noon",
        doc: "sun at 60 deg",
        set: &[("sun_elevation_deg", "60")],
    },
    Preset {
        name: "afternoon",
        doc: "sun at 30 deg (the defaults)",
        set: &[("sun_elevation_deg", "30")],
    },
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
        set: &[
            ("camera_altitude_m", "20000"),
            ("sun_elevation_deg", "30"),
            ("exposure", "4"),
        ],
    },
];

/// Altitude above the ground of a point (m).
pub fn altitude(p: DVec3) -> f64 {
    p.length() - R_GROUND
}

/// Densities (rho_R, rho_M) = (exp(-h / H_R), exp(-h / H_M)).
pub fn densities(h: f64) -> [f64; 2] {
    [(-h / H_R).exp(), (-h / H_M).exp()]
}

/// Optical depth per RGB channel of the density integrals (Rayleigh, Mie) in m.
pub fn optical_depth_of(column: [f64; 2]) -> [f64; 3] {
    BETA_R.map(|b| b * column[0] + BETA_M_EXT * column[1])
}

/// Extinction per RGB channel at altitude h (per m).
pub fn extinction(h: f64) -> [f64; 3] {
    let [r, m] = densities(h);
    optical_depth_of([r, m])
}

/// Distances (t0, t1), t0 <= t1, where o + t d (d unit) meets the sphere of
/// radius r centred at the origin, or None when it misses.
pub fn ray_sphere(o: DVec3, d: DVec3, r: f64) -> Option<(f64, f64)> {
    let b = o.dot(d);
    let c = o.length_squared() - r * r;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    // The stable pair of roots: q avoids cancellation, c / q is the other one.
    let q = -b - b.signum() * s;
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    let (a, e) = (q, c / q);
    Some((a.min(e), a.max(e)))
}

/// Density integrals (int rho_R, int rho_M) in m over o + t d, t in [0, length],
/// by the midpoint rule with `samples` steps.
pub fn column(o: DVec3, d: DVec3, length: f64, samples: u32) -> [f64; 2] {
    let dt = length / samples as f64;
    let mut sum = [0.0; 2];
    for i in 0..samples {
        let [r, m] = densities(altitude(o + (i as f64 + 0.5) * dt * d));
        sum[0] += r;
        sum[1] += m;
    }
    sum.map(|s| s * dt)
}

/// Optical depth per RGB channel of the segment o + t d, t in [0, length].
pub fn optical_depth(o: DVec3, d: DVec3, length: f64, samples: u32) -> [f64; 3] {
    optical_depth_of(column(o, d, length, samples))
}

/// Transmittance exp(-optical depth) per RGB channel of a segment.
pub fn transmittance(o: DVec3, d: DVec3, length: f64, samples: u32) -> [f64; 3] {
    optical_depth(o, d, length, samples).map(|t| (-t).exp())
}

/// Exact density integrals (Rayleigh, Mie) straight up from altitude `alt` to
/// the top: int_0^{top - alt} exp(-(alt + t) / H) dt
/// = H exp(-alt / H) (1 - exp(-(R_top - R_ground - alt) / H)).
/// At alt = 0 this is SPEC 3.5's beta * H * (1 - exp(-(R_top - R_ground - alt) / H))
/// divided by beta; above the ground SPEC's form lacks the exp(-alt / H) factor
/// (it measures the density from the camera instead of from the ground).
pub fn zenith_column_closed_form(alt: f64) -> [f64; 2] {
    let len = R_TOP - R_GROUND - alt;
    [H_R, H_M].map(|h| h * (-alt / h).exp() * -(-len / h).exp_m1())
}

/// Latlong projection (SPEC 3.5): azimuth 2 pi u, elevation (pi / 2)(1 - v).
pub fn latlong_direction(u: f64, v: f64) -> DVec3 {
    let (phi, e) = (2.0 * PI * u, 0.5 * PI * (1.0 - v));
    DVec3::new(e.cos() * phi.sin(), e.sin(), e.cos() * phi.cos())
}

/// Equidistant fisheye of the upper hemisphere: zenith at the image centre,
/// the horizon on the circle inscribed in the shorter side, azimuth 0 (the
/// sun) at the top. None outside the circle.
pub fn fisheye_direction(u: f64, v: f64, width: u32, height: u32) -> Option<DVec3> {
    let m = width.min(height) as f64;
    let x = (2.0 * u - 1.0) * width as f64 / m;
    let y = (1.0 - 2.0 * v) * height as f64 / m;
    let r = (x * x + y * y).sqrt();
    if r > 1.0 {
        return None;
    }
    let (phi, e) = (x.atan2(y), 0.5 * PI * (1.0 - r));
    Some(DVec3::new(
        e.cos() * phi.sin(),
        e.sin(),
        e.cos() * phi.cos(),
    ))
}

/// One sky configuration: everything the radiance integral needs.
#[derive(Debug, Clone, Copy)]
pub struct Sky {
    /// Unit vector toward the sun, (0, sin e_s, cos e_s).
    pub sun: DVec3,
    pub camera_altitude: f64,
    pub sun_intensity: f64,
    pub mie_g: f64,
    pub view_samples: u32,
    pub light_samples: u32,
}

impl Sky {
    pub fn from_params(p: &ParamSet) -> Sky {
        Sky {
            sun: sun_direction(p.f64("sun_elevation_deg")),
            camera_altitude: p.f64("camera_altitude_m"),
            sun_intensity: p.f64("sun_intensity"),
            mie_g: p.f64("mie_g"),
            view_samples: p.u32("view_samples"),
            light_samples: p.u32("light_samples"),
        }
    }

    pub fn camera(&self) -> DVec3 {
        DVec3::new(0.0, R_GROUND + self.camera_altitude, 0.0)
    }

    /// Transmittance from p to the top of the atmosphere toward the sun
    /// (`light_samples` midpoint steps); 0 when the planet blocks the sun.
    pub fn sun_transmittance(&self, p: DVec3) -> [f64; 3] {
        if ray_sphere(p, self.sun, R_GROUND).is_some_and(|(_, t1)| t1 > 0.0) {
            return [0.0; 3];
        }
        let exit = ray_sphere(p, self.sun, R_TOP).map_or(0.0, |(_, t1)| t1.max(0.0));
        transmittance(p, self.sun, exit, self.light_samples)
    }

    /// The view segment [t_start, t_end] inside the atmosphere, None when the
    /// ray never enters it: entry into / exit from the top sphere, cut at the
    /// ground hit.
    pub fn view_segment(&self, dir: DVec3) -> Option<(f64, f64)> {
        let c = self.camera();
        let (a, b) = ray_sphere(c, dir, R_TOP)?;
        if b <= 0.0 {
            return None;
        }
        let mut end = b;
        // Camera above the ground: a hit ahead has both roots >= 0.
        let ground_ahead = ray_sphere(c, dir, R_GROUND).filter(|&(g0, g1)| g0 >= 0.0 && g1 > 0.0);
        if let Some((g0, _)) = ground_ahead {
            end = end.min(g0);
        }
        Some((a.max(0.0), end))
    }

    /// Radiance (RGB) arriving at the camera along the unit direction `dir`.
    pub fn radiance(&self, dir: DVec3) -> [f64; 3] {
        let Some((t0, t1)) = self.view_segment(dir) else {
            return [0.0; 3];
        };
        let c = self.camera();
        let mu = dir.dot(self.sun);
        let (pr, pm) = (rayleigh(mu), hg(mu, self.mie_g));
        let n = self.view_samples;
        let dt = (t1 - t0) / n as f64;
        let mut before = [0.0; 2]; // density integrals over the finished steps
        let mut sum = [0.0; 3];
        for i in 0..n {
            let p = c + (t0 + (i as f64 + 0.5) * dt) * dir;
            let rho = densities(altitude(p));
            let to_mid =
                optical_depth_of([before[0] + 0.5 * dt * rho[0], before[1] + 0.5 * dt * rho[1]]);
            let sun = self.sun_transmittance(p);
            for k in 0..3 {
                let scatter = BETA_R[k] * rho[0] * pr + BETA_M * rho[1] * pm;
                sum[k] += (-to_mid[k]).exp() * scatter * sun[k];
            }
            before[0] += dt * rho[0];
            before[1] += dt * rho[1];
        }
        sum.map(|s| self.sun_intensity * s * dt)
    }
}

/// Unit vector toward the sun at azimuth 0: (0, sin e_s, cos e_s).
pub fn sun_direction(elevation_deg: f64) -> DVec3 {
    let (s, c) = elevation_deg.to_radians().sin_cos();
    DVec3::new(0.0, s, c)
}

/// Largest value of the phase functions in use: Rayleigh peaks at 3 / (8 pi),
/// HG at (1 + |g|) / (4 pi (1 - |g|)^2).
pub fn max_phase(g: f64) -> f64 {
    let g = g.abs();
    (3.0 / (8.0 * PI)).max((1.0 + g) / (4.0 * PI * (1.0 - g) * (1.0 - g)))
}

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
        let sky = Sky::from_params(p);
        let fisheye = p.choice("projection") == "fisheye";
        render_cpu(width, height, |u, v, _, _| {
            let dir = if fisheye {
                fisheye_direction(u, v, width, height)
            } else {
                Some(latlong_direction(u, v))
            };
            let [r, g, b] = dir.map_or([0.0; 3], |d| sky.radiance(d));
            [r, g, b, 1.0]
        })
    }
    /// The midpoint sums are bounded by E_sun * max phase: each step adds at
    /// most sigma dt exp(-sigma dt / 2) <= 1 - exp(-sigma dt) of the remaining
    /// transmittance (scattering <= extinction, T_sun <= 1). 1% slack for f32.
    fn output_bounds(&self, p: &ParamSet) -> (f32, f32) {
        (
            0.0,
            (1.01 * p.f64("sun_intensity") * max_phase(p.f64("mie_g"))) as f32,
        )
    }
    fn high_quality(&self) -> &'static [(&'static str, &'static str)] {
        &[("view_samples", "512"), ("light_samples", "128")]
    }
}
