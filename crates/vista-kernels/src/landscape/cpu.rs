//! The `landscape` kernel's reference: the heightfield, atmosphere and
//! clouds references composed as `crate::landscape` describes; built in f64
//! (the oracle) and f32. Nothing here re-derives a piece: the terrain hit and
//! shading are the heightfield reference's, the sky segments the atmosphere
//! reference's, the cloud march the clouds reference's.

use super::atmosphere::{Sky, latlong_direction};
use super::clouds::{CloudFrame, Clouds};
use super::consts::PI;
use super::geometry::{Camera, V3, add, direction, scale};
use super::heightfield::{
    MarchSettings, ShadowSettings, SurfaceLight, Terrain, brute_force_hit, relax_march, surface_radiance,
};
use super::{Real, Vec3, pixel_uv, real, real3, render_cpu};
use crate::ParamSet;
use crate::heightfield::{BRUTE_STEPS, HitSearch, REFINE_ITERS};
use vista_image::Image;

/// Metres per kilometre: the scene is in km, the atmosphere in m.
const KM: Real = 1000.0;

/// Everything one pixel needs, resolved from a parameter set.
#[derive(Debug, Clone)]
pub struct Landscape {
    /// The terrain h(x, z) (km).
    pub terrain: Terrain,
    /// The terrain's relax march settings (`t_max` and `eps` also rule the oracle's hits).
    pub march: MarchSettings,
    /// The terrain's soft-shadow samples.
    pub shadow: ShadowSettings,
    /// Altitude (km) above which flat ground turns to snow.
    pub snow_line: Real,
    /// Sky light on the terrain (linear RGB), times (0.5 + 0.5 n.y).
    pub ground_ambient: V3,
    /// The atmosphere (m), its camera at the view's altitude.
    pub sky: Sky,
    /// The cloud layer (km), lit through the atmosphere (its own `sun` and sky colours unused).
    pub clouds: Clouds,
    /// Position and basis; the aspect is set per image.
    pub view: Camera,
    /// `projection = latlong`: the atmosphere kernel's upper hemisphere instead of the pinhole view.
    pub latlong: bool,
    /// The `view` param: `color`, `depth` (t / t_max of the terrain hit, 1
    /// without one) or `refine` (the relax march's refinement evaluations / 16).
    pub view_output: &'static str,
    /// Unit direction toward the sun (azimuth from +z toward +x, elevation above the horizon).
    pub sun_dir: V3,
    /// E_sun: the sun's irradiance above the atmosphere.
    pub sun_intensity: Real,
}

impl Landscape {
    /// Resolves a `landscape` param set (angles in degrees become radians; the
    /// atmosphere's camera altitude in m comes from camera_pos's y in km).
    ///
    /// # Panics
    /// If `cloud_layer` names no cloud layer (`LandscapeKernel::check` refuses that).
    pub fn from_params(p: &ParamSet) -> Landscape {
        let sun_dir = direction(real(p, "sun_azimuth_deg").to_radians(), real(p, "sun_elevation_deg").to_radians());
        let pos = real3(p, "camera_pos");
        // pitch is within +-89 deg, so forward is never vertical.
        let forward = direction(real(p, "yaw_deg").to_radians(), real(p, "pitch_deg").to_radians());
        let view = Camera::looking(pos, forward, real(p, "fov_deg"), 1.0);
        let sun_intensity = real(p, "sun_intensity");
        let sky = Sky {
            sun: Vec3::from_array(sun_dir),
            camera_altitude: KM * pos[1],
            sun_intensity,
            mie_g: real(p, "mie_g"),
            view_samples: p.u32("view_samples"),
            light_samples: p.u32("light_samples"),
            density_scale: [real(p, "rayleigh_density"), real(p, "mie_density")],
        };
        let clouds = Clouds::from_group(
            p,
            CloudFrame {
                view,
                sun_dir,
                // Unused: the landscape lights its clouds through the atmosphere.
                sun: [0.0; 3],
                sky_zenith: [0.0; 3],
                sky_horizon: [0.0; 3],
                jitter: p.choice_in("cloud_jitter", crate::clouds::JITTERS),
                jitter_seed: p.u32("cloud_jitter_seed"),
            },
        );
        Landscape {
            terrain: Terrain::from_params(p),
            march: MarchSettings::from_params(p),
            shadow: ShadowSettings {
                steps: p.u32("shadow_steps"),
                distance: real(p, "shadow_distance"),
                softness: real(p, "shadow_softness"),
            },
            snow_line: real(p, "snow_line"),
            ground_ambient: real3(p, "ground_ambient"),
            sky,
            clouds,
            view,
            latlong: p.choice_in("projection", &[("pinhole", false), ("latlong", true)]),
            view_output: p.choice_in("view", &[("color", "color"), ("depth", "depth"), ("refine", "refine")]),
            sun_dir,
            sun_intensity,
        }
    }

    /// Whether the slab holds any cloud at all.
    pub fn has_clouds(&self) -> bool {
        self.clouds.coverage > 0.0 && self.clouds.density_scale > 0.0
    }

    /// The view ray of pixel (x, y).
    pub fn ray(&self, x: u32, y: u32, width: u32, height: u32) -> (V3, V3) {
        let (u, v) = pixel_uv(x, y, width, height);
        if self.latlong {
            return (self.view.pos, latlong_direction(u, v).to_array());
        }
        let camera = Camera { aspect: width as Real / height as Real, ..self.view };
        (camera.pos, camera.ray(u, v))
    }

    /// The atmosphere's point at distance t (km) along d, in its frame (m).
    fn air_point(&self, d: V3, t: Real) -> Vec3 {
        self.sky.camera() + (KM * t) * Vec3::from_array(d)
    }

    /// The terrain's radiance at the hit at distance t (km) along o + t d:
    /// the heightfield shading (albedo / pi x irradiance) under the sun seen
    /// through the air and the cloud layer, plus the ground ambient.
    pub fn surface(&self, o: V3, d: V3, t: Real) -> V3 {
        let t_sun = self.sky.sun_transmittance(self.air_point(d, t));
        let mut cloud = 1.0;
        if self.has_clouds() {
            let hit = add(o, scale(d, t));
            let p = [hit[0], self.terrain.height(hit[0], hit[2]), hit[2]];
            cloud = (-self.clouds.sun_optical_depth(p)).exp();
        }
        let sun = t_sun.map(|c| self.sun_intensity / PI * c * cloud);
        let light = SurfaceLight { sun_dir: self.sun_dir, sun, ambient: self.ground_ambient };
        surface_radiance(&self.terrain, self.march.eps, &self.shadow, self.snow_line, o, d, t, &light)
    }

    /// The raw output of pixel (x, y) with terrain hits found by `search`.
    pub fn pixel(&self, x: u32, y: u32, width: u32, height: u32, search: HitSearch) -> [Real; 4] {
        let (o, d) = self.ray(x, y, width, height);
        if self.view_output == "refine" {
            let r = relax_march(&self.terrain, o, d, &self.march).refine_iters as Real / REFINE_ITERS as Real;
            return [r, r, r, 1.0];
        }
        let hit = match search {
            HitSearch::BruteForce => brute_force_hit(&self.terrain, o, d, self.march.t_max, self.march.eps, BRUTE_STEPS),
            HitSearch::RelaxMarch => Some(relax_march(&self.terrain, o, d, &self.march)).filter(|m| m.hit).map(|m| m.t),
        };
        self.pixel_with_hit(x, y, width, height, hit)
    }

    /// The raw output of pixel (x, y) given its terrain hit distance (km),
    /// wherever it came from: the GPU's own hits, decoded from its depth
    /// view, let a test judge the shading and composition apart from the
    /// hit search.
    pub fn pixel_with_hit(&self, x: u32, y: u32, width: u32, height: u32, hit: Option<Real>) -> [Real; 4] {
        let (o, d) = self.ray(x, y, width, height);
        if self.view_output == "depth" {
            let z = hit.map_or(1.0, |t| (t / self.march.t_max).clamp(0.0, 1.0));
            return [z, z, z, 1.0];
        }
        let dir = Vec3::from_array(d);
        let (start, exit) = self.sky.view_segment(dir).unwrap_or((0.0, 0.0));
        let (end, surface) = match hit {
            Some(t) => (KM * t, self.surface(o, d, t)),
            None => (exit.max(start), [0.0; 3]),
        };
        let cloud_seg = self.clouds.layer_segment(o, d).map(|(c0, c1)| (c0, hit.map_or(c1, |t| c1.min(t))));
        let rgb: V3 = match cloud_seg {
            Some((c0, c1)) if self.has_clouds() && c1 > c0 => {
                let (front_l, front_t) = self.sky.segment(dir, start, (KM * c0).max(start));
                let (back_l, back_t) = self.sky.segment(dir, (KM * c1).max(start), end);
                let t_sun = self.sky.sun_transmittance(self.air_point(d, 0.5 * (c0 + c1)));
                let sun = t_sun.map(|c| self.sun_intensity * c);
                let xi = self.clouds.jitter_offset(x, y);
                let cloud = self.clouds.march_segment(o, d, c0, c1, xi, sun, false);
                std::array::from_fn(|i| {
                    let behind = back_l[i] + back_t[i] * surface[i];
                    front_l[i] + front_t[i] * (cloud.radiance[i] + cloud.transmittance * behind)
                })
            }
            _ => {
                let (l, t) = self.sky.segment(dir, start, end);
                std::array::from_fn(|i| l[i] + t[i] * surface[i])
            }
        };
        [rgb[0], rgb[1], rgb[2], 1.0]
    }
}

/// The raw output (linear radiance) of the `landscape` kernel.
pub fn render(p: &ParamSet, width: u32, height: u32, search: HitSearch) -> Image {
    let l = Landscape::from_params(p);
    render_cpu(width, height, |_, _, x, y| l.pixel(x, y, width, height, search))
}
