//! The crate's single error type.

use std::path::PathBuf;

/// Everything that can go wrong while creating, reading, writing or comparing
/// images. File-related variants always name the offending path.
#[derive(thiserror::Error, Debug)]
pub enum ImageError {
    /// The file could not be read, created, written or renamed into place.
    #[error("I/O error on {}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    /// The file exists but is not a decodable image of the expected format.
    #[error("{} is not a valid {format}: {msg}", path.display())]
    Decode {
        path: PathBuf,
        /// `"PNG"` or `"EXR"`.
        format: &'static str,
        msg: String,
    },
    /// The encoder rejected the image (e.g. a zero-sized image).
    #[error("could not encode {} as {format}: {msg}", path.display())]
    Encode {
        path: PathBuf,
        /// `"PNG"` or `"EXR"`.
        format: &'static str,
        msg: String,
    },
    /// Two images that must have the same size do not.
    #[error(
        "image size mismatch: expected {}x{}, got {}x{}",
        expected.0, expected.1, actual.0, actual.1
    )]
    SizeMismatch { expected: (u32, u32), actual: (u32, u32) },
    /// [`crate::save`] / [`crate::load`] only know `.png` and `.exr`.
    #[error(
        "{}: unsupported image extension (expected .png or .exr)",
        path.display()
    )]
    UnsupportedExtension { path: PathBuf },
    /// A pixel buffer whose length does not match `width * height`.
    #[error("bad image dimensions {width}x{height}: expected {expected} pixels, got {len}")]
    BadDimensions { width: u32, height: u32, expected: u64, len: usize },
}
