//! The crate's single error type.

use std::path::PathBuf;

/// Everything that can go wrong while creating, reading, writing or comparing
/// images. File-related variants always name the offending path.
#[derive(thiserror::Error, Debug)]
pub enum ImageError {
    /// The file could not be read, created, written or renamed into place.
    #[error("I/O error on {}: {source}", path.display())]
    Io {
        /// The file the operation was on.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file exists but is not a decodable image (or `.npy` array) of the expected format.
    #[error("{} is not a valid {format}: {msg}", path.display())]
    Decode {
        /// The file that failed to decode.
        path: PathBuf,
        /// `"PNG"`, `"EXR"` or `"NumPy .npy"`.
        format: &'static str,
        /// What was wrong with the contents.
        msg: String,
    },
    /// The encoder rejected the image (e.g. a zero-sized image).
    #[error("could not encode {} as {format}: {msg}", path.display())]
    Encode {
        /// The file that was being written.
        path: PathBuf,
        /// `"PNG"` or `"EXR"`.
        format: &'static str,
        /// Why the encoder refused.
        msg: String,
    },
    /// Two images that must have the same size do not.
    #[error(
        "image size mismatch: expected {}x{}, got {}x{}",
        expected.0, expected.1, actual.0, actual.1
    )]
    SizeMismatch {
        /// `(width, height)` of the reference image.
        expected: (u32, u32),
        /// `(width, height)` of the image compared against it.
        actual: (u32, u32),
    },
    /// [`crate::save`] / [`crate::load`] only know `.png` and `.exr`.
    #[error(
        "{}: unsupported image extension (expected .png or .exr)",
        path.display()
    )]
    UnsupportedExtension {
        /// The path whose extension is neither `.png` nor `.exr`.
        path: PathBuf,
    },
    /// A pixel buffer whose length does not match `width * height`.
    #[error("bad image dimensions {width}x{height}: expected {expected} pixels, got {len}")]
    BadDimensions {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// `width * height`, the pixel count the buffer should have.
        expected: u64,
        /// The pixel count the buffer actually has.
        len: usize,
    },
}
