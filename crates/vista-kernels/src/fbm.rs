//! `fbm`: 2D fractional Brownian motion over a noise basis (SPEC 3.2).

pub use crate::cpu64::fbm::{fbm_of, noise_of};
use crate::noise::BASIS_NAMES;
use crate::{Kernel, Kind, ParamError, ParamSet, ParamSpec, Preset, Uniforms};
use vista_image::Image;

/// The noise parameters shared by `fbm`, `ridged` and the kernels built on them.
pub const BASIS: ParamSpec = ParamSpec::new("basis", Kind::Enum(BASIS_NAMES), "perlin", "noise basis N");
pub const OCTAVES: ParamSpec = ParamSpec::new("octaves", Kind::int(1, 16), "8", "number of octaves summed");
pub const LACUNARITY: ParamSpec =
    ParamSpec::new("lacunarity", Kind::float(1.0, 4.0), "2.0", "frequency ratio between octaves");
pub const SEED: ParamSpec =
    ParamSpec::new("seed", Kind::int(0, u32::MAX as i64), "0", "permutation / hash seed (0 = Perlin's table)");

const PARAMS: &[ParamSpec] = &[
    BASIS,
    OCTAVES,
    LACUNARITY,
    ParamSpec::new("gain", Kind::float(0.0, 1.0), "0.5", "amplitude ratio between octaves"),
    ParamSpec::new("frequency", Kind::float_open(0.0, 256.0), "4.0", "base frequency over the unit image"),
    ParamSpec::new(
        "offset",
        Kind::Vector { n: 2, min: -1000.0, max: 1000.0 },
        "0,0",
        "domain offset added to frequency * (u, v)",
    ),
    ParamSpec::new("octave_rotation_deg", Kind::float(-180.0, 180.0), "0", "rotation between octaves (degrees)"),
    ParamSpec::new("z_slice", Kind::float(-1000.0, 1000.0), "0.0", "z coordinate of the 2D slice"),
    SEED,
];

const PRESETS: &[Preset] = &[
    Preset { name: "default", doc: "perlin, 8 octaves", set: &[] },
    Preset { name: "value", doc: "value noise (pcg3d), 8 octaves", set: &[("basis", "value")] },
    Preset {
        name: "rotated",
        doc: "perlin with 36.87 deg octave rotation (breaks lattice alignment)",
        set: &[("octave_rotation_deg", "36.87")],
    },
    Preset { name: "smooth", doc: "3 octaves, low frequency", set: &[("octaves", "3"), ("frequency", "2.0")] },
    Preset {
        name: "rough",
        doc: "12 octaves, gain 0.65",
        set: &[("octaves", "12"), ("gain", "0.65"), ("lacunarity", "2.1")],
    },
];

/// Table binding for noise kernels: the 512-entry permutation.
pub fn noise_table(p: &ParamSet) -> Vec<u32> {
    crate::noise::permutation(p.u32("seed"))
}

pub struct FbmKernel;

impl Kernel for FbmKernel {
    fn name(&self) -> &'static str {
        "fbm"
    }
    fn summary(&self) -> &'static str {
        "2D fBm of perlin or value noise; R=G=B = 0.5 + 0.5 f / A"
    }
    fn params(&self) -> &'static [ParamSpec] {
        PARAMS
    }
    fn presets(&self) -> &'static [Preset] {
        PRESETS
    }
    fn shader(&self) -> &'static str {
        "fbm.wgsl"
    }
    fn check(&self, p: &ParamSet) -> Result<(), ParamError> {
        if fbm_of(p).amplitude_sum() <= 0.0 {
            return Err(ParamError::Invalid("fbm: amplitude sum is 0".into()));
        }
        Ok(())
    }
    fn uniforms(&self, p: &ParamSet, width: u32, height: u32) -> Uniforms {
        let f = fbm_of(p);
        let [ox, oy] = p.vec2("offset");
        let (s, c) = f.theta.sin_cos();
        Uniforms::new(width, height)
            .u32("basis", p.choice_index("basis", BASIS_NAMES))
            .u32("octaves", f.octaves)
            .u32("seed", p.u32("seed"))
            .f32("lacunarity", f.lacunarity as f32)
            .f32("gain", f.gain as f32)
            .f32("frequency", p.f32("frequency"))
            .f32("offset_x", ox as f32)
            .f32("offset_y", oy as f32)
            .f32("rot_cos", c as f32)
            .f32("rot_sin", s as f32)
            .f32("z_slice", p.f32("z_slice"))
            .f32("inv_amplitude", (1.0 / f.amplitude_sum()) as f32)
    }
    fn table(&self, p: &ParamSet) -> Vec<u32> {
        noise_table(p)
    }
    fn work_per_pixel(&self, p: &ParamSet) -> f64 {
        p.f64("octaves")
    }
    /// |f| <= A * max|N|, and 3D perlin (non-integer z_slice) exceeds 1 slightly.
    fn output_bounds(&self, p: &ParamSet) -> (f32, f32) {
        let m = noise_of(p).max_abs();
        ((0.5 - 0.5 * m) as f32, (0.5 + 0.5 * m) as f32)
    }
    /// Sweeps compare octave counts against the most octaves allowed.
    fn high_quality(&self) -> &'static [(&'static str, &'static str)] {
        &[("octaves", "16")]
    }
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::fbm::render(p, width, height)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::fbm::render(p, width, height)
    }
}
