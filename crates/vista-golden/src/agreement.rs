//! The one GPU-vs-CPU comparison: two raw images over R, G, B and alpha.
//! Used by the agreement tests and by `vista mutate`'s reference check.

use vista_image::Image;
use vista_kernels::{Kernel, Output};

/// Agreement of two raw images over all four channels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Agreement {
    /// PSNR with peak 1 (display kernels) or the reference's largest RGB
    /// value (HDR kernels, SPEC 5's rule); +inf when identical.
    pub psnr: f64,
    /// Largest absolute difference (+inf when either side is NaN).
    pub max_abs: f64,
}

/// `gpu` against `reference` (the CPU's raw output) for `kernel`.
pub fn agreement(kernel: &Kernel, gpu: &Image, reference: &Image) -> Agreement {
    let peak = match kernel.output() {
        Output::Display => 1.0,
        Output::Hdr => reference.data.iter().flat_map(|p| p[..3].iter()).fold(0.0f64, |m, v| m.max(*v as f64)),
    };
    let (mut se, mut max_abs) = (0.0f64, 0.0f64);
    for (g, c) in gpu.data.iter().zip(&reference.data) {
        for k in 0..4 {
            let d = (g[k] as f64 - c[k] as f64).abs();
            se += d * d;
            max_abs = if d.is_nan() { f64::INFINITY } else { max_abs.max(d) };
        }
    }
    let mse = se / (gpu.data.len() * 4) as f64;
    Agreement { psnr: if mse == 0.0 { f64::INFINITY } else { 10.0 * (peak * peak / mse).log10() }, max_abs }
}
