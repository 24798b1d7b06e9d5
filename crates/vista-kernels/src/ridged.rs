//! `ridged`: Musgrave's ridged multifractal (SPEC 3.3), normalised to [0, 1].

pub use crate::cpu64::ridged::{ridged_max, ridged_of};
use crate::fbm::{BASIS, LACUNARITY, OCTAVES, SEED, noise_table};
use crate::noise::BASIS_NAMES;
use crate::{Kernel, Kind, ParamSet, ParamSpec, Preset, Uniforms};
use vista_image::Image;

const PARAMS: &[ParamSpec] = &[
    BASIS,
    OCTAVES,
    LACUNARITY,
    ParamSpec::new("h", Kind::float(0.0, 2.0), "1.0", "fractal increment H: octave i weighs lacunarity^(-i H)"),
    ParamSpec::new("offset", Kind::float(0.0, 2.0), "1.0", "ridge offset: signal = (offset - |N|)^2"),
    ParamSpec::new("gain", Kind::float(0.0, 8.0), "2.0", "feedback gain: weight = clamp(signal * gain, 0, 1)"),
    ParamSpec::new("frequency", Kind::float_open(0.0, 256.0), "4.0", "base frequency over the unit image"),
    ParamSpec::new("z_slice", Kind::float(-1000.0, 1000.0), "0.0", "z coordinate of the 2D slice"),
    SEED,
];

const PRESETS: &[Preset] = &[
    Preset { name: "default", doc: "perlin, 8 octaves, H 1, offset 1, gain 2", set: &[] },
    Preset { name: "value", doc: "value-noise ridges", set: &[("basis", "value")] },
    Preset { name: "sharp", doc: "H 0.5 keeps high octaves strong", set: &[("h", "0.5"), ("octaves", "10")] },
    Preset { name: "soft", doc: "offset 1.2, gain 1", set: &[("offset", "1.2"), ("gain", "1.0")] },
];

pub struct RidgedKernel;

impl Kernel for RidgedKernel {
    fn name(&self) -> &'static str {
        "ridged"
    }
    fn summary(&self) -> &'static str {
        "Musgrave ridged multifractal, normalised by its analytic maximum to [0, 1]"
    }
    fn params(&self) -> &'static [ParamSpec] {
        PARAMS
    }
    fn presets(&self) -> &'static [Preset] {
        PRESETS
    }
    fn shader(&self) -> &'static str {
        "ridged.wgsl"
    }
    fn uniforms(&self, p: &ParamSet, width: u32, height: u32) -> Uniforms {
        let r = ridged_of(p);
        Uniforms::new(width, height)
            .u32("basis", p.choice_index("basis", BASIS_NAMES))
            .u32("octaves", r.octaves)
            .u32("seed", p.u32("seed"))
            .f32("lacunarity", r.lacunarity as f32)
            .f32("h", r.h as f32)
            .f32("offset", r.offset as f32)
            .f32("gain", r.gain as f32)
            .f32("frequency", p.f32("frequency"))
            .f32("z_slice", p.f32("z_slice"))
            .f32("inv_max", (1.0 / ridged_max(&r)) as f32)
    }
    fn table(&self, p: &ParamSet) -> Vec<u32> {
        noise_table(p)
    }
    fn work_per_pixel(&self, p: &ParamSet) -> f64 {
        p.f64("octaves")
    }
    /// Sweeps compare octave counts against the most octaves allowed.
    fn high_quality(&self) -> &'static [(&'static str, &'static str)] {
        &[("octaves", "16")]
    }
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu64::ridged::render(p, width, height)
    }
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        crate::cpu32::ridged::render(p, width, height)
    }
}
