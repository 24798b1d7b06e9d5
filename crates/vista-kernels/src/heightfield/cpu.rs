//! The `heightfield` kernel's reference (SPEC 3.4), written from the model
//! described in `crate::heightfield`; built in f64 (the oracle) and f32.

use super::fbm::{fbm_of, noise_of};
use super::geometry::{Camera, V3, add, direction, dot, mix3, normalize, scale, smoothstep};
use super::noise::{Fbm, Noise, Ridged};
use super::ridged::ridged_max;
use super::{Real, real, real2, real3, render_cpu};
use crate::heightfield::{BRUTE_STEPS, HitSearch, REFINE_ITERS, TerrainKind};
use crate::noise::Basis;
use crate::{ParamError, ParamSet};
use vista_image::Image;

/// Refinement stops at |D| <= REFINE_TOL * eps * t: well inside the hit rule,
/// so at grazing incidence the hit distance also matches the true crossing.
pub const REFINE_TOL: Real = 0.01;
/// Extinction times visibility: ln(1 / 0.02), Koschmieder's 2% contrast.
pub const KOSCHMIEDER: Real = 3.912;

// Linear-light colours of the shading model (shared with shaders/heightfield.wgsl
// and shaders/lib/terrain.wgsl); the sun's colour is the `sun_color` param.
/// Sky ambient light on the terrain (linear RGB), times (0.5 + 0.5 n.y).
pub const AMBIENT: [Real; 3] = [0.16, 0.22, 0.32];
/// Sky colour at and below the horizon, which fog also blends toward (linear RGB).
pub const SKY_HORIZON: [Real; 3] = [0.60, 0.70, 0.82];
/// Sky colour straight up (linear RGB).
pub const SKY_ZENITH: [Real; 3] = [0.18, 0.34, 0.66];
/// Albedo of steep ground (linear RGB).
pub const ROCK: [Real; 3] = [0.36, 0.31, 0.27];
/// Albedo of flat ground (linear RGB).
pub const GRASS: [Real; 3] = [0.16, 0.26, 0.08];
/// Albedo of snow on flat-enough ground above the snow line (linear RGB).
pub const SNOW: [Real; 3] = [0.85, 0.87, 0.90];
/// Snow fades in over this height (km) above `snow_line`.
pub const SNOW_FADE: Real = 0.2;

/// h(x, z) and everything needed to evaluate it in Real.
#[derive(Debug, Clone)]
pub struct Terrain {
    /// Which height function T the terrain is.
    pub kind: TerrainKind,
    /// Height scale (km); for a plane, its height h0 at x = z = 0.
    pub amplitude: Real,
    /// Horizontal frequency of T (1/km); 1 for a plane.
    pub scale: Real,
    /// (s, r) of the plane h = amplitude + s x + r z.
    pub slope: [Real; 2],
    /// The seeded basis of the fbm and ridged terrains.
    pub noise: Noise,
    /// The fBm octaves (fbm terrain).
    pub fbm: Fbm,
    /// The ridged octaves (ridged terrain).
    pub ridged: Ridged,
    /// 1 / A (fbm) or 1 / ridged_max (ridged).
    pub inv_norm: Real,
}

impl Terrain {
    fn analytic(kind: TerrainKind, amplitude: Real, scale: Real, slope: [Real; 2]) -> Terrain {
        Terrain {
            kind,
            amplitude,
            scale,
            slope,
            noise: Noise::new(Basis::Perlin, 0),
            fbm: Fbm { octaves: 1, lacunarity: 2.0, gain: 0.5, theta: 0.0 },
            ridged: Ridged { octaves: 1, lacunarity: 2.0, h: 1.0, offset: 1.0, gain: 2.0 },
            inv_norm: 1.0,
        }
    }

    /// h = h0 + s x + r z.
    pub fn plane(h0: Real, s: Real, r: Real) -> Terrain {
        Terrain::analytic(TerrainKind::Plane, h0, 1.0, [s, r])
    }

    /// h = amplitude sin(x scale) cos(z scale); |grad h| <= amplitude * scale.
    pub fn sine(amplitude: Real, scale: Real) -> Terrain {
        Terrain::analytic(TerrainKind::Sine, amplitude, scale, [0.0, 0.0])
    }

    /// Resolves `terrain`, `amplitude`, `scale`, `plane_slope` and the noise and
    /// octave params of a param set.
    pub fn from_params(p: &ParamSet) -> Terrain {
        let kind = p.choice_in(
            "terrain",
            &[
                ("fbm", TerrainKind::Fbm),
                ("ridged", TerrainKind::Ridged),
                ("plane", TerrainKind::Plane),
                ("sine", TerrainKind::Sine),
            ],
        );
        let fbm = fbm_of(p);
        let ridged = Ridged {
            octaves: p.u32("octaves"),
            lacunarity: real(p, "lacunarity"),
            h: real(p, "ridge_h"),
            offset: real(p, "ridge_offset"),
            gain: real(p, "ridge_gain"),
        };
        let inv_norm = match kind {
            TerrainKind::Fbm => 1.0 / fbm.amplitude_sum(),
            TerrainKind::Ridged => 1.0 / ridged_max(&ridged),
            _ => 1.0,
        };
        Terrain {
            kind,
            amplitude: real(p, "amplitude"),
            scale: real(p, "scale"),
            slope: real2(p, "plane_slope"),
            noise: noise_of(p),
            fbm,
            ridged,
            inv_norm,
        }
    }

    /// Terrain height h(x, z).
    pub fn height(&self, x: Real, z: Real) -> Real {
        let (qx, qz) = (x * self.scale, z * self.scale);
        match self.kind {
            TerrainKind::Fbm => self.amplitude * self.fbm.eval(&self.noise, [qx, qz], 0.0) * self.inv_norm,
            TerrainKind::Ridged => self.amplitude * self.ridged.eval(&self.noise, [qx, qz], 0.0) * self.inv_norm,
            TerrainKind::Plane => self.amplitude + self.slope[0] * x + self.slope[1] * z,
            TerrainKind::Sine => self.amplitude * qx.sin() * qz.cos(),
        }
    }

    /// A bound on h above which no terrain lies (None: unbounded plane):
    /// |N| <= max_abs gives |T| <= max_abs for fbm / A, and ridged / max <= 1
    /// (its maximum already allows for |N| up to max_abs). Only used to let
    /// the reference skip empty space.
    pub fn height_bound(&self) -> Option<Real> {
        match self.kind {
            TerrainKind::Fbm | TerrainKind::Ridged => Some(self.noise.max_abs().max(1.0) * self.amplitude),
            TerrainKind::Sine => Some(self.amplitude),
            TerrainKind::Plane => None,
        }
    }

    /// Height of the ray point o + t d above the terrain, D(t) = p.y - h(p.xz).
    pub fn above(&self, o: V3, d: V3, t: Real) -> Real {
        let p = add(o, scale(d, t));
        p[1] - self.height(p[0], p[2])
    }

    /// Central-difference step used for normals at distance t.
    pub fn normal_step(x: Real, z: Real, eps: Real, t: Real) -> Real {
        (eps * t).max(1e-4 * (1.0 + x.abs().max(z.abs())))
    }

    /// normalize(-dh/dx, 1, -dh/dz) by central differences of step `delta`.
    pub fn normal(&self, x: Real, z: Real, delta: Real) -> V3 {
        let hx = (self.height(x + delta, z) - self.height(x - delta, z)) / (2.0 * delta);
        let hz = (self.height(x, z + delta) - self.height(x, z - delta)) / (2.0 * delta);
        normalize([-hx, 1.0, -hz])
    }
}

// ---------------------------------------------------------------- marching

/// Settings of the relax march (SPEC 3.4).
#[derive(Debug, Clone, Copy)]
pub struct MarchSettings {
    /// Far limit of the march (km).
    pub t_max: Real,
    /// Step factor a in [0, 1]: t += a D(t).
    pub relax: Real,
    /// Hit when D(t) < eps t (the pixel-footprint rule).
    pub eps: Real,
    /// Step limit; reaching it counts as a miss.
    pub max_steps: u32,
}

impl MarchSettings {
    /// Reads `t_max`, `relax`, `eps` and `max_steps`.
    pub fn from_params(p: &ParamSet) -> MarchSettings {
        MarchSettings { t_max: real(p, "t_max"), relax: real(p, "relax"), eps: real(p, "eps"), max_steps: p.u32("max_steps") }
    }
}

/// Outcome of one march: hit flag, (refined) distance, steps taken k.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct March {
    /// Whether the march hit the terrain.
    pub hit: bool,
    /// Distance along the ray (km): the refined hit, else where the march stopped.
    pub t: Real,
    /// Steps taken, k.
    pub steps: u32,
    /// Evaluations of D the hit's refinement made (0 for a miss or a hit at k = 0).
    pub refine_iters: u32,
}

/// The relax march in Real: t_{k+1} = t_k + relax D(t_k) from t_0 = 0; hit at
/// the first D < eps t (then refined), miss when t > t_max or k = max_steps.
pub fn relax_march(terrain: &Terrain, o: V3, d: V3, s: &MarchSettings) -> March {
    let (mut t, mut prev_t, mut prev_d) = (0.0, 0.0, 0.0);
    for k in 0..s.max_steps {
        if t > s.t_max {
            return March { hit: false, t, steps: k, refine_iters: 0 };
        }
        let dh = terrain.above(o, d, t);
        if dh < s.eps * t {
            let (t, refine_iters) =
                if k == 0 { (t, 0) } else { refine(terrain, o, d, s.eps, (prev_t, prev_d), (t, dh)) };
            return March { hit: true, t, steps: k, refine_iters };
        }
        (prev_t, prev_d) = (t, dh);
        t += s.relax * dh;
    }
    March { hit: false, t, steps: s.max_steps, refine_iters: 0 }
}

/// Interpolates D linearly between the last two samples a (D > 0) and b
/// (D < eps t) to its zero, and repeats with the newest two points until
/// |D| <= eps t / 100 (at most [`REFINE_ITERS`] times): secant steps while
/// both points are above the terrain (stopping if one fails to lower D),
/// Illinois false position once a point went under it, so the sign change
/// is kept. The point with the smallest |D| seen is the hit; b itself
/// already has |D| < eps t unless the last march step went under the terrain.
/// Returns the hit and the number of evaluations of D it took.
pub fn refine(terrain: &Terrain, o: V3, d: V3, eps: Real, a: (Real, Real), b: (Real, Real)) -> (Real, u32) {
    let ((mut ta, mut da), (mut tb, mut db)) = (a, b);
    let (mut best_t, mut best_d) = (tb, db.abs());
    // +1: the last false-position step replaced a (b kept), -1: it replaced b.
    let mut last = 0;
    let mut evaluations = 0;
    for _ in 0..REFINE_ITERS {
        if da <= db || best_d <= REFINE_TOL * eps * best_t {
            break;
        }
        evaluations += 1;
        let tr = tb + db * (tb - ta) / (da - db);
        let dr = terrain.above(o, d, tr);
        if dr.abs() < best_d {
            (best_t, best_d) = (tr, dr.abs());
        }
        if db >= 0.0 {
            // Secant: the newest two points, while D keeps falling (this
            // also stops on a non-finite D far out along the ray).
            if dr.is_nan() || dr >= db {
                break;
            }
            (ta, da, tb, db) = (tb, db, tr, dr);
        } else if dr > 0.0 {
            // Illinois: an end kept twice in a row has its value halved.
            (ta, da) = (tr, dr);
            if last == 1 {
                db *= 0.5;
            }
            last = 1;
        } else {
            (tb, db) = (tr, dr);
            if last == -1 {
                da *= 0.5;
            }
            last = -1;
        }
    }
    (best_t, evaluations)
}

/// Brute-force first hit in Real under the same hit rule as the march (the
/// pixel-footprint rule D < eps t), independent of relax and max_steps:
/// samples g(t) = D(t) - eps t every t_max / steps from t = 0 and bisects
/// its first sign change to t_g. From t_g it keeps sampling while the ray
/// stays inside the band D < eps t: if D drops below 0 there, the hit is
/// that zero of D (bisected); if the ray leaves the band first (it grazed a
/// crest within eps t), the hit stays at t_g, as the march reports it.
/// With eps = 0 this is the plain first crossing of the terrain. Rays above
/// the terrain's height bound skip ahead to where they can first enter the
/// band (exact: no terrain lies above the bound).
pub fn brute_force_hit(terrain: &Terrain, o: V3, d: V3, t_max: Real, eps: Real, steps: u32) -> Option<Real> {
    let dt = t_max / steps as Real;
    let above = |t: Real| terrain.above(o, d, t);
    let band = |t: Real| above(t) - eps * t;
    // 1e-12 t_max in f64; a few ulps in f32, which cannot resolve 1e-12
    // (bisection would stall with hi and lo one ulp apart).
    let tol = (4.0 * Real::EPSILON).max(1e-12) * t_max;
    let bisect = |f: &dyn Fn(Real) -> Real, mut lo: Real, mut hi: Real| {
        while hi - lo > tol {
            let mid = 0.5 * (lo + hi);
            if f(mid) < 0.0 { hi = mid } else { lo = mid }
        }
        0.5 * (lo + hi)
    };
    let bound = terrain.height_bound();
    let mut i0 = 0u32;
    if let Some(b) = bound {
        // In the band p.y - eps t < h <= b, and p.y - eps t = o.y + t (d.y - eps).
        if o[1] > b {
            if d[1] - eps >= 0.0 {
                return None;
            }
            let t_enter = (o[1] - b) / (eps - d[1]);
            if t_enter > t_max {
                return None;
            }
            i0 = (t_enter / dt).floor() as u32;
        }
    }
    let mut ta = i0 as Real * dt;
    if band(ta) < 0.0 {
        // Only possible at t = 0 (g(0) = D(0)): the camera is under the terrain.
        return Some(ta);
    }
    for i in i0 + 1..=steps {
        let tb = i as Real * dt;
        if band(tb) < 0.0 {
            let t_g = bisect(&band, ta, tb);
            // Inside the band: look for the zero of D before the ray leaves it.
            // (A ray parallel to a plane within eps t never leaves the band:
            // the walk ends at 2 t_max, beyond what any depth can show.)
            let mut lo = t_g;
            while lo < 2.0 * t_max {
                let hi = lo + dt;
                if above(hi) < 0.0 {
                    return Some(bisect(&above, lo, hi));
                }
                if band(hi) >= 0.0 {
                    return Some(t_g);
                }
                lo = hi;
            }
            return Some(t_g);
        }
        // Rising above the bound: nothing further along can be in the band.
        if bound.is_some_and(|b| d[1] - eps >= 0.0 && o[1] + tb * (d[1] - eps) > b) {
            return None;
        }
        ta = tb;
    }
    None
}

// ---------------------------------------------------------------- shading

/// Unit direction toward the sun (azimuth 0 = +z, 90 = +x).
pub fn sun_direction(azimuth_deg: Real, elevation_deg: Real) -> V3 {
    direction(azimuth_deg.to_radians(), elevation_deg.to_radians())
}

/// Fog extinction (1/km) for a meteorological visibility V (km): 3.912 / V.
pub fn fog_extinction(visibility_km: Real) -> Real {
    KOSCHMIEDER / visibility_km
}

/// Blends a linear colour seen at distance t toward the horizon colour:
/// c T + horizon (1 - T), T = exp(-sigma t). The contrast against the fog
/// (c - horizon) therefore falls as T: to 2% at t = V.
pub fn apply_fog(c: V3, t: Real, sigma: Real) -> V3 {
    let tr = (-sigma * t).exp();
    add(scale(c, tr), scale(SKY_HORIZON, 1.0 - tr))
}

/// The fixed sky gradient: horizon colour at and below the horizon, zenith
/// colour straight up, mixed by sqrt(d.y).
pub fn sky(d: V3) -> V3 {
    mix3(SKY_HORIZON, SKY_ZENITH, d[1].clamp(0.0, 1.0).sqrt())
}

/// Soft shadow from a surface point toward the sun: fixed samples at
/// t_i = distance ((i + 1) / steps)^2, smoothstep(clamp(min k D_i / t_i)).
pub fn soft_shadow(terrain: &Terrain, p: V3, sun: V3, steps: u32, distance: Real, softness: Real) -> Real {
    let mut res: Real = 1.0;
    for i in 0..steps {
        let f = (i + 1) as Real / steps as Real;
        let t = distance * f * f;
        res = res.min(softness * terrain.above(p, sun, t) / t);
        if res <= 0.0 {
            break;
        }
    }
    smoothstep(0.0, 1.0, res)
}

/// Display encoding of a linear colour: clamp to [0, 1], gamma 1/2.2.
pub fn encode(c: V3) -> V3 {
    c.map(|x| x.max(0.0).powf(1.0 / 2.2))
}

/// The largest encoded colour channel the shading can produce: the
/// brightest albedo under full sun plus full ambient, per channel (fog mixes
/// toward the dimmer horizon colour). No clamp hides it, so the raw-output
/// guard checks the shading itself.
pub fn max_encoded_colour(sun_color: V3) -> Real {
    (0..3)
        .map(|c| [ROCK[c], GRASS[c], SNOW[c]].into_iter().fold(0.0, Real::max) * (sun_color[c] + AMBIENT[c]))
        .chain(SKY_HORIZON.into_iter().chain(SKY_ZENITH))
        .fold(0.0, Real::max)
        .powf(1.0 / 2.2)
}

/// The soft shadow's fixed samples (see [`soft_shadow`]).
#[derive(Debug, Clone, Copy)]
pub struct ShadowSettings {
    /// Samples toward the sun (0: no shadow, fully lit).
    pub steps: u32,
    /// Reach of the shadow march (km).
    pub distance: Real,
    /// Penumbra sharpness k: shadow = smoothstep(min_i k D_i / t_i).
    pub softness: Real,
}

/// What lights a terrain point: the direction toward the sun, the sun's
/// colour arriving there, the sky's ambient colour (x (0.5 + 0.5 n.y)).
#[derive(Debug, Clone, Copy)]
pub struct SurfaceLight {
    /// Unit direction toward the sun.
    pub sun_dir: V3,
    /// The sun's colour arriving at the point (linear RGB).
    pub sun: V3,
    /// The sky's ambient colour (linear RGB), times (0.5 + 0.5 n.y).
    pub ambient: V3,
}

/// Radiance leaving the terrain hit at distance t along o + t d, before any
/// fog or aerial perspective: albedo (rock, grass where flat, snow above the
/// snow line) x (sun x Lambert x soft shadow + ambient x (0.5 + 0.5 n.y)).
#[allow(clippy::too_many_arguments)]
pub fn surface_radiance(
    terrain: &Terrain,
    eps: Real,
    shadow: &ShadowSettings,
    snow_line: Real,
    o: V3,
    d: V3,
    t: Real,
    light: &SurfaceLight,
) -> V3 {
    let hit = add(o, scale(d, t));
    let (x, z) = (hit[0], hit[2]);
    let h = terrain.height(x, z);
    let n = terrain.normal(x, z, Terrain::normal_step(x, z, eps, t));
    let p = [x, h, z];
    let flat = smoothstep(0.75, 0.92, n[1]);
    let snow = smoothstep(snow_line, snow_line + SNOW_FADE, h) * smoothstep(0.55, 0.75, n[1]);
    let albedo = mix3(mix3(ROCK, GRASS, flat), SNOW, snow);
    let lambert = dot(n, light.sun_dir).max(0.0);
    let shadow =
        if lambert > 0.0 { soft_shadow(terrain, p, light.sun_dir, shadow.steps, shadow.distance, shadow.softness) } else { 0.0 };
    let sky_light = 0.5 + 0.5 * n[1];
    std::array::from_fn(|i| albedo[i] * (light.sun[i] * lambert * shadow + light.ambient[i] * sky_light))
}

/// Everything one pixel needs, resolved from a parameter set.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The terrain h(x, z).
    pub terrain: Terrain,
    /// The pinhole camera (km).
    pub camera: Camera,
    /// The relax march settings (also `t_max` and `eps` of the oracle).
    pub march: MarchSettings,
    /// The `view` param: `color`, `depth`, `steps`, `normal` or `refine`.
    pub view: &'static str,
    /// Unit direction toward the sun.
    pub sun: V3,
    /// Soft-shadow samples toward the sun (0: no shadow).
    pub shadow_steps: u32,
    /// Reach of the shadow march (km).
    pub shadow_distance: Real,
    /// Penumbra sharpness k of the soft shadow.
    pub shadow_softness: Real,
    /// Fog extinction (1/km): 3.912 / visibility_km.
    pub sigma: Real,
    /// Altitude (km) above which flat ground turns to snow.
    pub snow_line: Real,
    /// Sun colour (linear RGB), times Lambert and the soft shadow.
    pub sun_color: V3,
}

impl Scene {
    /// Resolves a `heightfield` param set for a `width` x `height` image; an
    /// error when the camera's view direction is undefined ([`Camera::new`]).
    pub fn from_params(p: &ParamSet, width: u32, height: u32) -> Result<Scene, ParamError> {
        let camera = camera_of(p, width, height)?;
        Ok(Scene {
            terrain: Terrain::from_params(p),
            camera,
            march: MarchSettings::from_params(p),
            // Every view the manifest lists; "color" is the match arms' last.
            view: p.choice_in("view", &[("color", "color"), ("depth", "depth"), ("steps", "steps"), ("normal", "normal"), ("refine", "refine")]),
            sun: sun_direction(real(p, "sun_azimuth_deg"), real(p, "sun_elevation_deg")),
            shadow_steps: p.u32("shadow_steps"),
            shadow_distance: real(p, "shadow_distance"),
            shadow_softness: real(p, "shadow_softness"),
            sigma: fog_extinction(real(p, "visibility_km")),
            snow_line: real(p, "snow_line"),
            sun_color: real3(p, "sun_color"),
        })
    }

    /// Surface normal at the hit at distance t along d.
    pub fn normal_at(&self, d: V3, t: Real) -> V3 {
        let p = add(self.camera.pos, scale(d, t));
        self.terrain.normal(p[0], p[2], Terrain::normal_step(p[0], p[2], self.march.eps, t))
    }

    /// Linear colour of a terrain hit at distance t along d.
    pub fn shade(&self, d: V3, t: Real) -> V3 {
        let shadow = ShadowSettings {
            steps: self.shadow_steps,
            distance: self.shadow_distance,
            softness: self.shadow_softness,
        };
        let light = SurfaceLight { sun_dir: self.sun, sun: self.sun_color, ambient: AMBIENT };
        let lit = surface_radiance(&self.terrain, self.march.eps, &shadow, self.snow_line, self.camera.pos, d, t, &light);
        apply_fog(lit, t, self.sigma)
    }

    /// The raw output of one pixel, as the GPU writes it (oracle hits).
    pub fn pixel(&self, u: Real, v: Real) -> [Real; 4] {
        self.pixel_with(u, v, HitSearch::BruteForce)
    }

    /// The raw output of one pixel with hits found by `search`. The `steps`
    /// and `refine` views always show the relax march, whose costs they are.
    pub fn pixel_with(&self, u: Real, v: Real, search: HitSearch) -> [Real; 4] {
        let d = self.camera.ray(u, v);
        let o = self.camera.pos;
        if self.view == "steps" || self.view == "refine" {
            let m = relax_march(&self.terrain, o, d, &self.march);
            let s = match self.view {
                "steps" => m.steps as Real / self.march.max_steps as Real,
                _ => m.refine_iters as Real / REFINE_ITERS as Real,
            };
            return [s, s, s, 1.0];
        }
        let hit = match search {
            HitSearch::BruteForce => {
                brute_force_hit(&self.terrain, o, d, self.march.t_max, self.march.eps, BRUTE_STEPS)
            }
            HitSearch::RelaxMarch => Some(relax_march(&self.terrain, o, d, &self.march)).filter(|m| m.hit).map(|m| m.t),
        };
        let rgb = match hit {
            None => match self.view {
                "depth" => [1.0; 3],
                "normal" => [0.0; 3],
                _ => encode(sky(d)),
            },
            Some(t) => match self.view {
                "depth" => [(t / self.march.t_max).clamp(0.0, 1.0); 3],
                "normal" => self.normal_at(d, t).map(|c| c * 0.5 + 0.5),
                _ => encode(self.shade(d, t)),
            },
        };
        [rgb[0], rgb[1], rgb[2], 1.0]
    }
}

/// The camera of a parameter set for a W x H image.
pub fn camera_of(p: &ParamSet, width: u32, height: u32) -> Result<Camera, ParamError> {
    Camera::new(real3(p, "camera_pos"), real3(p, "camera_target"), real(p, "fov_deg"), width as Real / height as Real)
}

/// The raw output of the `heightfield` kernel, hits found by `search`.
pub fn render(p: &ParamSet, width: u32, height: u32, search: HitSearch) -> Result<Image, ParamError> {
    let scene = Scene::from_params(p, width, height)?;
    Ok(render_cpu(width, height, |u, v, _, _| scene.pixel_with(u, v, search)))
}
