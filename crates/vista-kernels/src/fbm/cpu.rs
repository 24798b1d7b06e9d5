//! The `fbm` kernel's reference (SPEC 3.2): R = G = B = 0.5 + 0.5 f / A.

use super::noise::{Fbm, Noise};
use super::{Real, real, real2, render_cpu};
use crate::ParamSet;
use vista_image::Image;

/// Builds the seeded noise basis named by `basis` / `seed`.
pub fn noise_of(p: &ParamSet) -> Noise {
    Noise::new(p.choice_in("basis", crate::noise::BASES), p.u32("seed"))
}

/// The fBm octave settings of a parameter set.
pub fn fbm_of(p: &ParamSet) -> Fbm {
    Fbm {
        octaves: p.u32("octaves"),
        lacunarity: real(p, "lacunarity"),
        gain: real(p, "gain"),
        theta: real(p, "octave_rotation_deg").to_radians(),
    }
}

/// The raw output of the `fbm` kernel.
pub fn render(p: &ParamSet, width: u32, height: u32) -> Image {
    let (n, f) = (noise_of(p), fbm_of(p));
    let (freq, [ox, oy], z) = (real(p, "frequency"), real2(p, "offset"), real(p, "z_slice"));
    let inv_a: Real = 1.0 / f.amplitude_sum();
    render_cpu(width, height, |u, v, _, _| {
        let value = 0.5 + 0.5 * f.eval(&n, [freq * u + ox, freq * v + oy], z) * inv_a;
        [value, value, value, 1.0]
    })
}
