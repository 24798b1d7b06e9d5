//! The `cloudmap` kernel's reference: Hugo Elias's cloud map. The fBm of
//! SPEC 3.2 (no rotation, no offset) at z = time, mapped to n = 0.5 + 0.5 f / A
//! and clamped to [0, 1]; density d = 1 - sharpness^(255 max(n - cover, 0)).

use super::noise::Fbm;
use super::{Real, fbm::noise_of, real, render_cpu};
use crate::ParamSet;
use vista_image::Image;

/// Cloud density for a normalised noise value `n` in [0, 1].
pub fn density(n: Real, cover: Real, sharpness: Real) -> Real {
    let x = (n - cover).max(0.0);
    1.0 - sharpness.powf(255.0 * x)
}

/// The raw output of the `cloudmap` kernel.
pub fn render(p: &ParamSet, width: u32, height: u32) -> Image {
    let noise = noise_of(p);
    let f = Fbm { octaves: p.u32("octaves"), lacunarity: real(p, "lacunarity"), gain: real(p, "gain"), theta: 0.0 };
    let (freq, time, cover, s) = (real(p, "frequency"), real(p, "time"), real(p, "cover"), real(p, "sharpness"));
    let inv_a: Real = 1.0 / f.amplitude_sum();
    render_cpu(width, height, |u, v, _, _| {
        let n = (0.5 + 0.5 * f.eval(&noise, [freq * u, freq * v], time) * inv_a).clamp(0.0, 1.0);
        let d = density(n, cover, s);
        [d, d, d, 1.0]
    })
}
