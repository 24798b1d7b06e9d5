//! The pixel loop every reference shares, and parameter values converted
//! to this build's precision.

use super::Real;
use crate::ParamSet;
use rayon::prelude::*;
use vista_image::Image;

/// Pixel-centre coordinates (SPEC 3): u = (x + 0.5) / W, v = (y + 0.5) / H.
pub fn pixel_uv(x: u32, y: u32, width: u32, height: u32) -> (Real, Real) {
    ((x as Real + 0.5) / width as Real, (y as Real + 0.5) / height as Real)
}

/// Evaluates `f(u, v, x, y)` at every pixel on all cores, storing f32.
// The cast to f32 is a no-op in the f32 build.
#[allow(clippy::unnecessary_cast)]
pub fn render_cpu(width: u32, height: u32, f: impl Fn(Real, Real, u32, u32) -> [Real; 4] + Sync) -> Image {
    let data: Vec<[f32; 4]> = (0..width * height)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let (u, v) = pixel_uv(x, y, width, height);
            f(u, v, x, y).map(|c| c as f32)
        })
        .collect();
    Image::from_raw(width, height, data).expect("render_cpu fills every pixel")
}

/// A float parameter in this precision.
pub(crate) fn real(p: &ParamSet, name: &str) -> Real {
    p.f64(name) as Real
}

pub(crate) fn real2(p: &ParamSet, name: &str) -> [Real; 2] {
    p.vec2(name).map(|c| c as Real)
}

pub(crate) fn real3(p: &ParamSet, name: &str) -> [Real; 3] {
    p.vec3(name).map(|c| c as Real)
}
