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
use crate::fbm::{BASIS, LACUNARITY, OCTAVES, SEED};
use crate::noise::BASIS_NAMES;
use crate::{Kernel, Kind, ParamError, ParamSet, ParamSpec, Preset, Uniforms};
use vista_image::Image;

pub const VIEW_NAMES: &[&str] = &["color", "depth", "steps", "normal"];
pub const TERRAIN_NAMES: &[&str] = &["fbm", "ridged", "plane", "sine"];

/// Samples over [0, t_max] in the brute-force reference march.
pub const BRUTE_STEPS: u32 = 4096;
/// Most interpolation passes of the hit refinement.
pub const REFINE_ITERS: u32 = 16;
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
        crate::cpu64::heightfield::render(p, width, height, HitSearch::BruteForce)
            .expect("heightfield: parameters not validated by check()")
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::heightfield::render(p, width, height, HitSearch::BruteForce)
            .expect("heightfield: parameters not validated by check()")
    }
    fn high_quality(&self) -> &'static [(&'static str, &'static str)] {
        &[("relax", "0.25"), ("max_steps", "4096"), ("eps", "0.0002"), ("shadow_steps", "128")]
    }
}
