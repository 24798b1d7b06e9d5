//! Display transforms for HDR previews.

use crate::Image;

/// Maps linear HDR values to displayable sRGB-encoded values in `[0, 1)`.
///
/// Per RGB channel: `L` is clamped to `>= 0` (NaN → 0), then
/// `display = 1 - exp(-exposure * L)` (computed with `exp_m1` for accuracy
/// near 0), clamped to `[0, 1]` (so `exposure <= 0` gives black), then
/// encoded with [`srgb_encode`]. Alpha is copied unchanged.
pub fn tonemap(img: &Image, exposure: f32) -> Image {
    let data = img
        .data
        .iter()
        .map(|&[r, g, b, a]| {
            let map = |l: f32| srgb_encode(-(-exposure * l.max(0.0)).exp_m1());
            [map(r), map(g), map(b), a]
        })
        .collect();
    Image { width: img.width, height: img.height, data }
}

/// The exact piecewise sRGB OETF: `12.92 x` below 0.0031308, otherwise
/// `1.055 x^(1/2.4) - 0.055`. Input is clamped to `[0, 1]` (NaN → 0).
/// Evaluated in f64 so the endpoints come out exactly 0 and 1.
pub fn srgb_encode(x: f32) -> f32 {
    let x = if x.is_nan() { 0.0 } else { f64::from(x.clamp(0.0, 1.0)) };
    let y = if x < 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
    y.clamp(0.0, 1.0) as f32
}
