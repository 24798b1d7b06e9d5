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

use crate::fbm::{BASIS, LACUNARITY, OCTAVES, SEED};
use crate::noise::{BASIS_NAMES, Basis, Fbm, Noise, Ridged};
use crate::ridged::ridged_max;
pub use crate::geometry::{Camera, V3};
use crate::geometry::{add, direction, dot, mix3, normalize, scale, smoothstep};
use crate::{Kernel, Kind, ParamError, ParamSet, ParamSpec, Preset, Uniforms, render_cpu};
use vista_image::Image;

pub const VIEW_NAMES: &[&str] = &["color", "depth", "steps", "normal"];
pub const TERRAIN_NAMES: &[&str] = &["fbm", "ridged", "plane", "sine"];

/// Samples over [0, t_max] in the brute-force reference march.
pub const BRUTE_STEPS: u32 = 4096;
/// Most interpolation passes of the hit refinement.
pub const REFINE_ITERS: u32 = 16;
/// Refinement stops at |D| <= REFINE_TOL * eps * t: well inside the hit rule,
/// so at grazing incidence the hit distance also matches the true crossing.
pub const REFINE_TOL: f64 = 0.01;
/// Extinction times visibility: ln(1 / 0.02), Koschmieder's 2% contrast.
pub const KOSCHMIEDER: f64 = 3.912;

// Linear-light colours of the shading model (shared with shaders/heightfield.wgsl).
pub const SUN_COLOR: [f64; 3] = [1.0, 0.92, 0.78];
pub const AMBIENT: [f64; 3] = [0.16, 0.22, 0.32];
pub const SKY_HORIZON: [f64; 3] = [0.60, 0.70, 0.82];
pub const SKY_ZENITH: [f64; 3] = [0.18, 0.34, 0.66];
pub const ROCK: [f64; 3] = [0.36, 0.31, 0.27];
pub const GRASS: [f64; 3] = [0.16, 0.26, 0.08];
pub const SNOW: [f64; 3] = [0.85, 0.87, 0.90];
/// Snow fades in over this height (km) above `snow_line`.
pub const SNOW_FADE: f64 = 0.2;

const PARAMS: &[ParamSpec] = &[
    ParamSpec::new(
        "view",
        Kind::Enum(VIEW_NAMES),
        "color",
        "output: color | depth (t / t_max, 1 for sky) | steps (k / max_steps) | normal (n * 0.5 + 0.5, 0 for sky)",
    ),
    ParamSpec::new(
        "terrain",
        Kind::Enum(TERRAIN_NAMES),
        "fbm",
        "T: fbm / A | ridged / max | plane (h = amplitude + plane_slope . (x, z)) | sine (amplitude sin(x scale) cos(z scale)); plane and sine are analytic test terrains",
    ),
    BASIS,
    OCTAVES,
    LACUNARITY,
    ParamSpec::new("gain", Kind::float(0.0, 1.0), "0.5", "fbm amplitude ratio between octaves"),
    ParamSpec::new("octave_rotation_deg", Kind::float(-180.0, 180.0), "0", "fbm rotation between octaves (degrees)"),
    SEED,
    ParamSpec::new(
        "ridge_h",
        Kind::float(0.0, 2.0),
        "1.0",
        "ridged: fractal increment H (octave weight lacunarity^(-i H))",
    ),
    ParamSpec::new("ridge_offset", Kind::float(0.0, 2.0), "1.0", "ridged: signal = (offset - |N|)^2"),
    ParamSpec::new("ridge_gain", Kind::float(0.0, 8.0), "2.0", "ridged: feedback weight = clamp(signal * gain, 0, 1)"),
    ParamSpec::new("amplitude", Kind::float(0.0, 20.0), "2.0", "terrain height scale (km); plane: its height h0"),
    ParamSpec::new("scale", Kind::float_open(0.0, 100.0), "0.25", "horizontal frequency of T (1/km)"),
    ParamSpec::new(
        "plane_slope",
        Kind::Vector { n: 2, min: -10.0, max: 10.0 },
        "0,0",
        "terrain=plane only: slopes (s, r) of h = amplitude + s x + r z",
    ),
    ParamSpec::new("camera_pos", Kind::Vector { n: 3, min: -1000.0, max: 1000.0 }, "9,0.5,3", "camera position (km)"),
    ParamSpec::new(
        "camera_target",
        Kind::Vector { n: 3, min: -1000.0, max: 1000.0 },
        "14,0.1,12",
        "point the camera looks at (km)",
    ),
    ParamSpec::new("fov_deg", Kind::float(1.0, 150.0), "55", "vertical field of view (degrees)"),
    ParamSpec::new("t_max", Kind::float_open(0.0, 1000.0), "20", "far limit of the march (km)"),
    ParamSpec::new(
        "relax",
        Kind::float_open(0.0, 1.0),
        "0.5",
        "step factor a: t += a (p.y - h); a <= 1/sqrt(1 + L^2) never tunnels (L = slope bound)",
    ),
    ParamSpec::new("eps", Kind::float_open(0.0, 0.1), "0.001", "hit when p.y - h < eps * t (pixel-footprint rule)"),
    ParamSpec::new("max_steps", Kind::int(1, 8192), "256", "march step limit (reaching it counts as a miss)"),
    ParamSpec::new(
        "shadow_steps",
        Kind::int(0, 512),
        "32",
        "samples of the soft-shadow march toward the sun (0 = no shadow)",
    ),
    ParamSpec::new("shadow_distance", Kind::float_open(0.0, 1000.0), "4", "reach of the shadow march (km)"),
    ParamSpec::new("shadow_softness", Kind::float_open(0.0, 256.0), "8", "penumbra sharpness k: shadow = min k D / t"),
    ParamSpec::new("sun_azimuth_deg", Kind::float(-360.0, 360.0), "-60", "sun azimuth (0 = +z, 90 = +x)"),
    ParamSpec::new("sun_elevation_deg", Kind::float(0.0, 90.0), "25", "sun elevation above the horizon"),
    ParamSpec::new(
        "snow_line",
        Kind::float(-100.0, 100.0),
        "1.0",
        "altitude (km) above which flat ground turns to snow",
    ),
    ParamSpec::new(
        "visibility_km",
        Kind::float(0.001, 100000.0),
        "60",
        "meteorological visibility V (km): fog extinction 3.912 / V per km; fog < 1 km, mist 1-5 km",
    ),
];

// Presets use lacunarity 2.03 / 2.07 rather than 2: with exactly 2, every
// octave samples the lattice on the lines x * scale = integer (all of them
// integers there), which shows as straight grid-aligned ridges.
const PRESETS: &[Preset] = &[
    Preset { name: "default", doc: "fbm terrain with the parameter defaults", set: &[] },
    Preset {
        name: "valley",
        doc: "fbm hills along a valley, camera 0.7 km above its floor",
        set: &[("terrain", "fbm"), ("lacunarity", "2.03"), ("camera_pos", "9,0.5,3"), ("camera_target", "14,0.1,12")],
    },
    Preset {
        name: "ridges",
        doc: "ridged multifractal mountains from a high viewpoint, snow above 1.2 km",
        set: &[
            ("terrain", "ridged"),
            ("lacunarity", "2.07"),
            ("amplitude", "1.6"),
            ("scale", "0.3"),
            ("camera_pos", "7.3,2.4,4.1"),
            ("camera_target", "11,0.6,12"),
            ("sun_azimuth_deg", "150"),
            ("sun_elevation_deg", "30"),
            ("snow_line", "1.2"),
            ("t_max", "25"),
        ],
    },
    Preset {
        name: "grazing",
        doc: "camera 0.1 km above sharp ridged crests, near-horizontal view, t_max 60 km: the overstepping case",
        set: &[
            ("terrain", "ridged"),
            ("lacunarity", "2.07"),
            ("amplitude", "1.2"),
            ("scale", "0.5"),
            ("camera_pos", "0.25,1.3,-0.75"),
            ("camera_target", "2,1.15,10"),
            ("fov_deg", "30"),
            ("t_max", "60"),
            ("max_steps", "512"),
            ("sun_elevation_deg", "12"),
        ],
    },
    Preset {
        name: "fog",
        doc: "a hill rising out of fog (visibility 0.6 km), camera 30 m above a slope",
        set: &[
            ("terrain", "fbm"),
            ("lacunarity", "2.03"),
            ("camera_pos", "10,-0.17,3"),
            ("camera_target", "11,-0.25,5"),
            ("visibility_km", "0.6"),
        ],
    },
    Preset {
        name: "mist",
        doc: "the valley in mist (visibility 3 km), camera 0.2 km above its floor",
        set: &[
            ("terrain", "fbm"),
            ("lacunarity", "2.03"),
            ("camera_pos", "9,0,3"),
            ("camera_target", "12,0.1,7"),
            ("visibility_km", "3"),
        ],
    },
];

// ---------------------------------------------------------------- terrain

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TerrainKind {
    Fbm,
    Ridged,
    Plane,
    Sine,
}

/// h(x, z) and everything needed to evaluate it in f64.
#[derive(Debug, Clone)]
pub struct Terrain {
    pub kind: TerrainKind,
    pub amplitude: f64,
    pub scale: f64,
    /// (s, r) of the plane h = amplitude + s x + r z.
    pub slope: [f64; 2],
    pub noise: Noise,
    pub fbm: Fbm,
    pub ridged: Ridged,
    /// 1 / A (fbm) or 1 / ridged_max (ridged).
    pub inv_norm: f64,
}

impl Terrain {
    fn analytic(kind: TerrainKind, amplitude: f64, scale: f64, slope: [f64; 2]) -> Terrain {
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
    pub fn plane(h0: f64, s: f64, r: f64) -> Terrain {
        Terrain::analytic(TerrainKind::Plane, h0, 1.0, [s, r])
    }

    /// h = amplitude sin(x scale) cos(z scale); |grad h| <= amplitude * scale.
    pub fn sine(amplitude: f64, scale: f64) -> Terrain {
        Terrain::analytic(TerrainKind::Sine, amplitude, scale, [0.0, 0.0])
    }

    pub fn from_params(p: &ParamSet) -> Terrain {
        let kind = match p.choice("terrain") {
            "ridged" => TerrainKind::Ridged,
            "plane" => TerrainKind::Plane,
            "sine" => TerrainKind::Sine,
            _ => TerrainKind::Fbm,
        };
        let fbm = crate::fbm::fbm_of(p);
        let ridged = Ridged {
            octaves: p.u32("octaves"),
            lacunarity: p.f64("lacunarity"),
            h: p.f64("ridge_h"),
            offset: p.f64("ridge_offset"),
            gain: p.f64("ridge_gain"),
        };
        let inv_norm = match kind {
            TerrainKind::Fbm => 1.0 / fbm.amplitude_sum(),
            TerrainKind::Ridged => 1.0 / ridged_max(&ridged),
            _ => 1.0,
        };
        Terrain {
            kind,
            amplitude: p.f64("amplitude"),
            scale: p.f64("scale"),
            slope: p.vec2("plane_slope"),
            noise: crate::fbm::noise_of(p),
            fbm,
            ridged,
            inv_norm,
        }
    }

    /// Terrain height h(x, z).
    pub fn height(&self, x: f64, z: f64) -> f64 {
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
    pub fn height_bound(&self) -> Option<f64> {
        match self.kind {
            TerrainKind::Fbm | TerrainKind::Ridged => Some(self.noise.max_abs().max(1.0) * self.amplitude),
            TerrainKind::Sine => Some(self.amplitude),
            TerrainKind::Plane => None,
        }
    }

    /// Height of the ray point o + t d above the terrain, D(t) = p.y - h(p.xz).
    pub fn above(&self, o: V3, d: V3, t: f64) -> f64 {
        let p = add(o, scale(d, t));
        p[1] - self.height(p[0], p[2])
    }

    /// Central-difference step used for normals at distance t.
    pub fn normal_step(x: f64, z: f64, eps: f64, t: f64) -> f64 {
        (eps * t).max(1e-4 * (1.0 + x.abs().max(z.abs())))
    }

    /// normalize(-dh/dx, 1, -dh/dz) by central differences of step `delta`.
    pub fn normal(&self, x: f64, z: f64, delta: f64) -> V3 {
        let hx = (self.height(x + delta, z) - self.height(x - delta, z)) / (2.0 * delta);
        let hz = (self.height(x, z + delta) - self.height(x, z - delta)) / (2.0 * delta);
        normalize([-hx, 1.0, -hz])
    }
}

// ---------------------------------------------------------------- marching

/// Settings of the relax march (SPEC 3.4).
#[derive(Debug, Clone, Copy)]
pub struct MarchSettings {
    pub t_max: f64,
    pub relax: f64,
    pub eps: f64,
    pub max_steps: u32,
}

impl MarchSettings {
    pub fn from_params(p: &ParamSet) -> MarchSettings {
        MarchSettings { t_max: p.f64("t_max"), relax: p.f64("relax"), eps: p.f64("eps"), max_steps: p.u32("max_steps") }
    }
}

/// Outcome of one march: hit flag, (refined) distance, steps taken k.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct March {
    pub hit: bool,
    pub t: f64,
    pub steps: u32,
}

/// The relax march in f64: t_{k+1} = t_k + relax D(t_k) from t_0 = 0; hit at
/// the first D < eps t (then refined), miss when t > t_max or k = max_steps.
pub fn relax_march(terrain: &Terrain, o: V3, d: V3, s: &MarchSettings) -> March {
    let (mut t, mut prev_t, mut prev_d) = (0.0, 0.0, 0.0);
    for k in 0..s.max_steps {
        if t > s.t_max {
            return March { hit: false, t, steps: k };
        }
        let dh = terrain.above(o, d, t);
        if dh < s.eps * t {
            let t = if k == 0 { t } else { refine(terrain, o, d, s.eps, (prev_t, prev_d), (t, dh)) };
            return March { hit: true, t, steps: k };
        }
        (prev_t, prev_d) = (t, dh);
        t += s.relax * dh;
    }
    March { hit: false, t, steps: s.max_steps }
}

/// Interpolates D linearly between the last two samples a (D > 0) and b
/// (D < eps t) to its zero, and repeats with the newest two points until
/// |D| <= eps t / 100 (at most [`REFINE_ITERS`] times): secant steps while
/// both points are above the terrain (stopping if one fails to lower D),
/// Illinois false position once a point went under it, so the sign change
/// is kept. The point with the smallest |D| seen is the hit; b itself
/// already has |D| < eps t unless the last march step went under the terrain.
pub fn refine(terrain: &Terrain, o: V3, d: V3, eps: f64, a: (f64, f64), b: (f64, f64)) -> f64 {
    let ((mut ta, mut da), (mut tb, mut db)) = (a, b);
    let (mut best_t, mut best_d) = (tb, db.abs());
    // +1: the last false-position step replaced a (b kept), -1: it replaced b.
    let mut last = 0;
    for _ in 0..REFINE_ITERS {
        if da <= db || best_d <= REFINE_TOL * eps * best_t {
            break;
        }
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
    best_t
}

/// Brute-force first hit in f64 under the same hit rule as the march (the
/// pixel-footprint rule D < eps t), independent of relax and max_steps:
/// samples g(t) = D(t) - eps t every t_max / steps from t = 0 and bisects
/// its first sign change to t_g. From t_g it keeps sampling while the ray
/// stays inside the band D < eps t: if D drops below 0 there, the hit is
/// that zero of D (bisected); if the ray leaves the band first (it grazed a
/// crest within eps t), the hit stays at t_g, as the march reports it.
/// With eps = 0 this is the plain first crossing of the terrain. Rays above
/// the terrain's height bound skip ahead to where they can first enter the
/// band (exact: no terrain lies above the bound).
pub fn brute_force_hit(terrain: &Terrain, o: V3, d: V3, t_max: f64, eps: f64, steps: u32) -> Option<f64> {
    let dt = t_max / steps as f64;
    let above = |t: f64| terrain.above(o, d, t);
    let band = |t: f64| above(t) - eps * t;
    let bisect = |f: &dyn Fn(f64) -> f64, mut lo: f64, mut hi: f64| {
        while hi - lo > 1e-12 * t_max {
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
    let mut ta = i0 as f64 * dt;
    if band(ta) < 0.0 {
        // Only possible at t = 0 (g(0) = D(0)): the camera is under the terrain.
        return Some(ta);
    }
    for i in i0 + 1..=steps {
        let tb = i as f64 * dt;
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
pub fn sun_direction(azimuth_deg: f64, elevation_deg: f64) -> V3 {
    direction(azimuth_deg.to_radians(), elevation_deg.to_radians())
}

/// Fog extinction (1/km) for a meteorological visibility V (km): 3.912 / V.
pub fn fog_extinction(visibility_km: f64) -> f64 {
    KOSCHMIEDER / visibility_km
}

/// Blends a linear colour seen at distance t toward the horizon colour:
/// c T + horizon (1 - T), T = exp(-sigma t). The contrast against the fog
/// (c - horizon) therefore falls as T: to 2% at t = V.
pub fn apply_fog(c: V3, t: f64, sigma: f64) -> V3 {
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
pub fn soft_shadow(terrain: &Terrain, p: V3, sun: V3, steps: u32, distance: f64, softness: f64) -> f64 {
    let mut res: f64 = 1.0;
    for i in 0..steps {
        let f = (i + 1) as f64 / steps as f64;
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
    c.map(|x| x.clamp(0.0, 1.0).powf(1.0 / 2.2))
}

/// Everything one pixel needs, resolved from a parameter set.
#[derive(Debug, Clone)]
pub struct Scene {
    pub terrain: Terrain,
    pub camera: Camera,
    pub march: MarchSettings,
    pub view: &'static str,
    pub sun: V3,
    pub shadow_steps: u32,
    pub shadow_distance: f64,
    pub shadow_softness: f64,
    pub sigma: f64,
    pub snow_line: f64,
}

impl Scene {
    pub fn from_params(p: &ParamSet, width: u32, height: u32) -> Result<Scene, ParamError> {
        let camera = camera_of(p, width, height)?;
        Ok(Scene {
            terrain: Terrain::from_params(p),
            camera,
            march: MarchSettings::from_params(p),
            view: p.choice("view"),
            sun: sun_direction(p.f64("sun_azimuth_deg"), p.f64("sun_elevation_deg")),
            shadow_steps: p.u32("shadow_steps"),
            shadow_distance: p.f64("shadow_distance"),
            shadow_softness: p.f64("shadow_softness"),
            sigma: fog_extinction(p.f64("visibility_km")),
            snow_line: p.f64("snow_line"),
        })
    }

    /// Surface normal at the hit at distance t along d.
    pub fn normal_at(&self, d: V3, t: f64) -> V3 {
        let p = add(self.camera.pos, scale(d, t));
        self.terrain.normal(p[0], p[2], Terrain::normal_step(p[0], p[2], self.march.eps, t))
    }

    /// Linear colour of a terrain hit at distance t along d.
    pub fn shade(&self, d: V3, t: f64) -> V3 {
        let hit = add(self.camera.pos, scale(d, t));
        let (x, z) = (hit[0], hit[2]);
        let h = self.terrain.height(x, z);
        let n = self.normal_at(d, t);
        let p = [x, h, z];
        let flat = smoothstep(0.75, 0.92, n[1]);
        let snow = smoothstep(self.snow_line, self.snow_line + SNOW_FADE, h) * smoothstep(0.55, 0.75, n[1]);
        let albedo = mix3(mix3(ROCK, GRASS, flat), SNOW, snow);
        let lambert = dot(n, self.sun).max(0.0);
        let shadow = if lambert > 0.0 {
            soft_shadow(&self.terrain, p, self.sun, self.shadow_steps, self.shadow_distance, self.shadow_softness)
        } else {
            0.0
        };
        let sky_light = 0.5 + 0.5 * n[1];
        let light: V3 = std::array::from_fn(|i| SUN_COLOR[i] * lambert * shadow + AMBIENT[i] * sky_light);
        let lit = std::array::from_fn(|i| albedo[i] * light[i]);
        apply_fog(lit, t, self.sigma)
    }

    /// The raw output of one pixel, as the GPU writes it.
    pub fn pixel(&self, u: f64, v: f64) -> [f64; 4] {
        let d = self.camera.ray(u, v);
        let o = self.camera.pos;
        let rgb = match self.view {
            "steps" => {
                let m = relax_march(&self.terrain, o, d, &self.march);
                [m.steps as f64 / self.march.max_steps as f64; 3]
            }
            view => match brute_force_hit(&self.terrain, o, d, self.march.t_max, self.march.eps, BRUTE_STEPS) {
                None => match view {
                    "depth" => [1.0; 3],
                    "normal" => [0.0; 3],
                    _ => encode(sky(d)),
                },
                Some(t) => match view {
                    "depth" => [(t / self.march.t_max).clamp(0.0, 1.0); 3],
                    "normal" => self.normal_at(d, t).map(|c| c * 0.5 + 0.5),
                    _ => encode(self.shade(d, t)),
                },
            },
        };
        [rgb[0], rgb[1], rgb[2], 1.0]
    }
}

/// The camera of a parameter set for a W x H image.
pub fn camera_of(p: &ParamSet, width: u32, height: u32) -> Result<Camera, ParamError> {
    Camera::new(p.vec3("camera_pos"), p.vec3("camera_target"), p.f64("fov_deg"), width as f64 / height as f64)
}

pub struct HeightfieldKernel;

impl Kernel for HeightfieldKernel {
    fn name(&self) -> &'static str {
        "heightfield"
    }
    fn summary(&self) -> &'static str {
        "sphere-traced fbm / ridged terrain (1 unit = 1 km): sun, soft shadow, fog; views color|depth|steps|normal"
    }
    fn params(&self) -> &'static [ParamSpec] {
        PARAMS
    }
    fn presets(&self) -> &'static [Preset] {
        PRESETS
    }
    fn shader(&self) -> &'static str {
        "heightfield.wgsl"
    }
    fn check(&self, p: &ParamSet) -> Result<(), ParamError> {
        // The aspect ratio does not affect validity; 1:1 is enough here.
        camera_of(p, 1, 1).map(|_| ())
    }
    fn uniforms(&self, p: &ParamSet, width: u32, height: u32) -> Uniforms {
        let t = Terrain::from_params(p);
        // check() ran before any GPU work; fall back to a harmless camera.
        let cam = camera_of(p, width, height)
            .unwrap_or_else(|_| Camera::new([0.0; 3], [0.0, 0.0, 1.0], 60.0, 1.0).expect("valid camera"));
        let (rot_sin, rot_cos) = t.fbm.theta.sin_cos();
        let sun = sun_direction(p.f64("sun_azimuth_deg"), p.f64("sun_elevation_deg"));
        Uniforms::new(width, height)
            .u32("view", p.choice_index("view", VIEW_NAMES))
            .u32("terrain", p.choice_index("terrain", TERRAIN_NAMES))
            .u32("basis", p.choice_index("basis", BASIS_NAMES))
            .u32("octaves", p.u32("octaves"))
            .u32("seed", p.u32("seed"))
            .u32("max_steps", p.u32("max_steps"))
            .u32("shadow_steps", p.u32("shadow_steps"))
            .f32("lacunarity", t.fbm.lacunarity as f32)
            .f32("gain", t.fbm.gain as f32)
            .f32("rot_cos", rot_cos as f32)
            .f32("rot_sin", rot_sin as f32)
            .f32("ridge_h", t.ridged.h as f32)
            .f32("ridge_offset", t.ridged.offset as f32)
            .f32("ridge_gain", t.ridged.gain as f32)
            .f32("inv_norm", t.inv_norm as f32)
            .f32("amplitude", t.amplitude as f32)
            .f32("scale", t.scale as f32)
            .f32("slope_x", t.slope[0] as f32)
            .f32("slope_z", t.slope[1] as f32)
            .vec3(["cam_x", "cam_y", "cam_z"], cam.pos)
            .vec3(["fwd_x", "fwd_y", "fwd_z"], cam.forward)
            .vec3(["right_x", "right_y", "right_z"], cam.right)
            .vec3(["up_x", "up_y", "up_z"], cam.up)
            .f32("tan_half_fov", cam.tan_half as f32)
            .f32("aspect", cam.aspect as f32)
            .f32("t_max", p.f32("t_max"))
            .f32("relax", p.f32("relax"))
            .f32("eps", p.f32("eps"))
            .f32("shadow_distance", p.f32("shadow_distance"))
            .f32("shadow_softness", p.f32("shadow_softness"))
            .vec3(["sun_x", "sun_y", "sun_z"], sun)
            .f32("sigma", fog_extinction(p.f64("visibility_km")) as f32)
            .f32("snow_line", p.f32("snow_line"))
    }
    fn table(&self, p: &ParamSet) -> Vec<u32> {
        crate::fbm::noise_table(p)
    }
    fn work_per_pixel(&self, p: &ParamSet) -> f64 {
        // Heights per pixel (march + shadow + refine + 4 for the normal), each
        // `octaves` noise evaluations.
        let heights = p.f64("max_steps") + p.f64("shadow_steps") + REFINE_ITERS as f64 + 5.0;
        heights * p.f64("octaves")
    }
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        let scene = Scene::from_params(p, width, height).expect("heightfield: parameters not validated by check()");
        render_cpu(width, height, |u, v, _, _| scene.pixel(u, v))
    }
    fn high_quality(&self) -> &'static [(&'static str, &'static str)] {
        &[("relax", "0.25"), ("max_steps", "4096"), ("eps", "0.0002"), ("shadow_steps", "128")]
    }
}
