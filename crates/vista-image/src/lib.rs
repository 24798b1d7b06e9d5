#![deny(missing_docs)]
//! Image handling for vista.
//!
//! This crate owns the [`Image`] type (row-major f32 RGBA, `y = 0` is the top
//! row), lossless-enough file I/O (16-bit PNG and f32 OpenEXR, always written
//! atomically via [`atomic_write`]), comparison [`metrics`] (MSE, PSNR, SSIM,
//! max abs error, bad-pixel and NaN counts), diff heat maps
//! ([`diff_heatmap`]) and display tone mapping ([`tonemap`]).
//!
//! Not for: GPU work, kernels or golden-image bookkeeping; those live in the
//! other vista crates and call into this one.
//!
//! ```
//! use vista_image::{Image, metrics};
//!
//! let reference = Image::from_fn(16, 16, |x, y| [x as f32 / 16.0, y as f32 / 16.0, 0.5, 1.0]);
//! let mut actual = reference.clone();
//! actual.set(3, 4, [1.0, 0.0, 0.0, 1.0]);
//! let m = metrics::compare(&reference, &actual)?;
//! assert_eq!(m.bad_pixels, 1);
//! assert!(m.psnr > 20.0 && m.ssim < 1.0);
//! println!("PSNR {}", metrics::format_psnr(m.psnr));
//! # Ok::<(), vista_image::ImageError>(())
//! ```

mod buffer;
mod error;
pub mod fault;
mod heatmap;
mod io;
pub mod metrics;
pub mod npy;
mod png_stream;
mod ssim;
mod texels;
mod threads;
mod tonemap;

pub use buffer::Image;
pub use error::ImageError;
pub use heatmap::{
    LOG_FLOOR, STOPS as HEATMAP_STOPS, diff_heatmap, diff_heatmap_log, diff_heatmap_log_row, log_position,
};
pub use io::{
    atomic_replace, atomic_write, decode_exr, decode_png16, decode_png16_compact, encode_exr, encode_png8_small,
    encode_png16, encode_png16_channel, encode_png16_small, load, opaque8, own_dir, quantize8, quantize16, read_exr,
    read_png16, real_dir_under, remove_stale_temps, save, write_exr, write_png8, write_png8_small, write_png16,
};
pub use png_stream::{PngFile, PngKind, atomic_replace_with};
pub use texels::{Image16, Texels};
pub use threads::{case_threads, one_arena, release_after_case, set_case_threads, threads_for};
pub use tonemap::{srgb_encode, tonemap};
