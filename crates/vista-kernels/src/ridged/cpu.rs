//! The `ridged` kernel's reference (SPEC 3.3), normalised to [0, 1].

use super::fbm::noise_of;
use super::noise::{PERLIN_MAX_ABS, Ridged};
use super::{Real, real, render_cpu};
use crate::ParamSet;
use vista_image::Image;

/// The ridged octave settings of a param set (`octaves`, `lacunarity`, `h`, `offset`, `gain`).
pub fn ridged_of(p: &ParamSet) -> Ridged {
    Ridged {
        octaves: p.u32("octaves"),
        lacunarity: real(p, "lacunarity"),
        h: real(p, "h"),
        offset: real(p, "offset"),
        gain: real(p, "gain"),
    }
}

/// Normaliser: the largest raw value possible. With |N| <= M (M =
/// PERLIN_MAX_ABS bounds both bases) each signal is at most
/// max(offset, M - offset)^2 (offset^2 when offset >= 1, SPEC 3.3) and each
/// weight at most 1.
pub fn ridged_max(r: &Ridged) -> Real {
    let peak = r.offset.max(PERLIN_MAX_ABS - r.offset);
    peak * peak * (0..r.octaves).map(|i| r.weight(i)).sum::<Real>()
}

/// The raw output of the `ridged` kernel.
pub fn render(p: &ParamSet, width: u32, height: u32) -> Image {
    let (n, r) = (noise_of(p), ridged_of(p));
    let (freq, z, inv) = (real(p, "frequency"), real(p, "z_slice"), 1.0 / ridged_max(&r));
    render_cpu(width, height, |u, v, _, _| {
        let value = r.eval(&n, [freq * u, freq * v], z) * inv;
        [value, value, value, 1.0]
    })
}
