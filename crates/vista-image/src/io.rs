//! PNG16 / EXR reading and writing. Every write encodes to memory first and
//! then goes through [`atomic_write`], so a crash never leaves a truncated file.

use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};

use image::{DynamicImage, ImageFormat};

use crate::{Image, ImageError};

/// Writes `img` as a 16-bit RGBA PNG.
///
/// Each channel is clamped to `[0, 1]` and quantised as `round(v * 65535)`;
/// NaN is written as 0. Use [`write_exr`] to keep values unchanged.
pub fn write_png16(path: &Path, img: &Image) -> Result<(), ImageError> {
    atomic_write(path, &encode_png16(path, img)?)
}

/// The 16-bit RGBA PNG bytes [`write_png16`] writes (`path` names errors),
/// with fast compression: reports write them on every run.
pub fn encode_png16(path: &Path, img: &Image) -> Result<Vec<u8>, ImageError> {
    let samples: Vec<u8> = img.data.iter().flatten().flat_map(|&v| quantize16(v).to_ne_bytes()).collect();
    encode_fast(path, img, &samples, image::ExtendedColorType::Rgba16)
}

/// PNG bytes of `samples` (`img`'s size) with fast compression.
fn encode_fast(
    path: &Path,
    img: &Image,
    samples: &[u8],
    color: image::ExtendedColorType,
) -> Result<Vec<u8>, ImageError> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut bytes = Vec::new();
    let encoder = PngEncoder::new_with_quality(&mut bytes, CompressionType::Fast, FilterType::Adaptive);
    encoder.write_image(samples, img.width, img.height, color).map_err(|e| encode_error(path, "PNG", e))?;
    Ok(bytes)
}

/// The smallest lossless 16-bit PNG of `img` the encoder makes, for
/// goldens that live in a repository: best deflate with adaptive row
/// filters, and RGB without the alpha channel where every alpha is 1
/// (a reader takes missing alpha as 1). The same values as
/// [`encode_png16`], in fewer bytes; slower to write, so bless uses it and
/// reports do not.
pub fn encode_png16_small(path: &Path, img: &Image) -> Result<Vec<u8>, ImageError> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let opaque = img.data.iter().all(|p| quantize16(p[3]) == u16::MAX);
    let channels = if opaque { 3 } else { 4 };
    let samples: Vec<u8> =
        img.data.iter().flat_map(|p| p[..channels].iter().flat_map(|&v| quantize16(v).to_ne_bytes())).collect();
    let mut bytes = Vec::new();
    let encoder = PngEncoder::new_with_quality(&mut bytes, CompressionType::Best, FilterType::Adaptive);
    let color = if opaque { image::ExtendedColorType::Rgb16 } else { image::ExtendedColorType::Rgba16 };
    encoder.write_image(&samples, img.width, img.height, color).map_err(|e| encode_error(path, "PNG", e))?;
    Ok(bytes)
}

/// Writes `img` as an 8-bit PNG (clamped to `[0, 1]`, NaN as 0; RGB where
/// every alpha is 1, else RGBA): the light display copy reports load,
/// beside the 16-bit file. Fast compression and no sync to disk, since
/// every run writes the report again ([`atomic_replace`]).
pub fn write_png8(path: &Path, img: &Image) -> Result<(), ImageError> {
    let opaque = opaque8(img);
    let channels = if opaque { 3 } else { 4 };
    let samples: Vec<u8> = img.data.iter().flat_map(|p| p[..channels].iter().map(|&v| quantize8(v))).collect();
    let color = if opaque { image::ExtendedColorType::Rgb8 } else { image::ExtendedColorType::Rgba8 };
    atomic_replace(path, &encode_fast(path, img, &samples, color)?)
}

/// Whether every alpha of `img` is 1 at 8 bits: its 8-bit PNG needs no
/// alpha channel.
pub fn opaque8(img: &Image) -> bool {
    img.data.iter().all(|p| quantize8(p[3]) == u8::MAX)
}

/// Writes `img` as the smallest 8-bit PNG this writes (clamped to
/// `[0, 1]`, NaN as 0): grey where every texel has R = G = B, without alpha
/// where every alpha is 1, each row's filter chosen by least absolute sum,
/// best deflate. For thumbnails, one per passing case: a 32 x 32 grey noise
/// render is 0.77 KB this way and 2.4 KB as [`write_png8`] writes it.
pub fn write_png8_small(path: &Path, img: &Image) -> Result<(), ImageError> {
    atomic_replace(path, &encode_png8_small(img))
}

/// The bytes [`write_png8_small`] writes. Filtered and framed here, not by
/// the png crate: with one deflate state per thread, reset instead of set
/// up anew, a 32 x 32 grey thumbnail took 43-65 us against the png crate's
/// 166-211 us at its best deflate, for the same 1124 bytes (2026-12-07), of
/// a small case's ~1 ms.
pub fn encode_png8_small(img: &Image) -> Vec<u8> {
    let texels: Vec<[u8; 4]> = img.data.iter().map(|p| p.map(quantize8)).collect();
    let opaque = texels.iter().all(|p| p[3] == u8::MAX);
    let grey = texels.iter().all(|&[r, g, b, _]| r == g && g == b);
    // PNG colour types: 0 grey, 4 grey + alpha, 2 RGB, 6 RGBA.
    let (keep, colour_type): (&[usize], u8) = match (grey, opaque) {
        (true, true) => (&[0], 0),
        (true, false) => (&[0, 3], 4),
        (false, true) => (&[0, 1, 2], 2),
        (false, false) => (&[0, 1, 2, 3], 6),
    };
    let samples: Vec<u8> = match keep.len() {
        4 => texels.into_flattened(),
        _ => texels.iter().flat_map(|p| keep.iter().map(move |&c| p[c])).collect(),
    };
    let filtered = filter_rows(&samples, img.width as usize * keep.len(), keep.len());
    let mut png = png_header(img.width, img.height, 8, colour_type);
    png_chunk(&mut png, b"IDAT", &zlib_best(&filtered));
    png_chunk(&mut png, b"IEND", &[]);
    png
}

/// PNG scanlines of `samples` (`stride` bytes a row, `bpp` bytes a texel),
/// each prefixed by its filter ([`RowFilter`]).
fn filter_rows(samples: &[u8], stride: usize, bpp: usize) -> Vec<u8> {
    let stride = stride.max(1);
    let mut out = Vec::with_capacity(samples.len() + samples.len() / stride);
    let zeros = vec![0u8; stride];
    let mut filter = RowFilter::new(stride);
    for (y, row) in samples.chunks(stride).enumerate() {
        let up = if y == 0 { &zeros[..] } else { &samples[(y - 1) * stride..y * stride] };
        out.push(filter.filter(row, up, bpp));
        out.extend_from_slice(filter.best());
    }
    out
}

/// Picks each PNG row's filter (none, sub, up, average, Paeth) as the one
/// whose output has the least sum of absolute values as signed bytes:
/// libpng's heuristic.
pub(crate) struct RowFilter {
    candidate: Vec<u8>,
    best: Vec<u8>,
}

impl RowFilter {
    pub(crate) fn new(stride: usize) -> RowFilter {
        RowFilter { candidate: vec![0; stride], best: vec![0; stride] }
    }

    /// The filtered bytes of the last row [`RowFilter::filter`] was given.
    pub(crate) fn best(&self) -> &[u8] {
        &self.best
    }

    /// Filters `row` against `up` (the row above; zeros for the first),
    /// `bpp` bytes a texel; the filter type, its bytes in [`RowFilter::best`].
    pub(crate) fn filter(&mut self, row: &[u8], up: &[u8], bpp: usize) -> u8 {
        let stride = row.len();
        let k = bpp.min(stride);
        let mut best_cost = u64::MAX;
        let mut best_filter = 0u8;
        for filter in 0..5u8 {
            // Each filter in a plain loop of its own and the cost summed
            // after, so that both vectorize.
            let candidate = &mut self.candidate[..stride];
            let (head, tail) = candidate.split_at_mut(k);
            match filter {
                0 => candidate.copy_from_slice(row),
                1 => {
                    head.copy_from_slice(&row[..k]);
                    for ((v, &r), &a) in tail.iter_mut().zip(&row[k..]).zip(row) {
                        *v = r.wrapping_sub(a);
                    }
                }
                2 => {
                    for ((v, &r), &b) in candidate.iter_mut().zip(row).zip(up) {
                        *v = r.wrapping_sub(b);
                    }
                }
                3 => {
                    for ((v, &r), &b) in head.iter_mut().zip(row).zip(up) {
                        *v = r.wrapping_sub(b / 2);
                    }
                    for (((v, &r), &a), &b) in tail.iter_mut().zip(&row[k..]).zip(row).zip(&up[k..]) {
                        *v = r.wrapping_sub(((u16::from(a) + u16::from(b)) / 2) as u8);
                    }
                }
                _ => {
                    for ((v, &r), &b) in head.iter_mut().zip(row).zip(up) {
                        *v = r.wrapping_sub(b);
                    }
                    for ((((v, &r), &a), &b), &c) in tail.iter_mut().zip(&row[k..]).zip(row).zip(&up[k..]).zip(up) {
                        *v = r.wrapping_sub(paeth(a, b, c));
                    }
                }
            }
            let cost = abs_sum(&self.candidate[..stride]);
            if cost < best_cost {
                (best_cost, best_filter) = (cost, filter);
                std::mem::swap(&mut self.best, &mut self.candidate);
            }
        }
        best_filter
    }
}

/// The sum of `bytes` read as signed magnitudes, in chunks that vectorize.
fn abs_sum(bytes: &[u8]) -> u64 {
    let mut chunks = bytes.chunks_exact(32);
    let mut sum = 0u64;
    for chunk in &mut chunks {
        // At most 32 * 128: no overflow in u32.
        sum += u64::from(chunk.iter().map(|&b| u32::from((b as i8).unsigned_abs())).sum::<u32>());
    }
    sum + chunks.remainder().iter().map(|&b| u64::from((b as i8).unsigned_abs())).sum::<u64>()
}

/// The Paeth predictor of `a` (left), `b` (up) and `c` (up-left), without
/// branches: p - a = b - c, p - b = a - c, p - c = a + b - 2c.
fn paeth(a: u8, b: u8, c: u8) -> u8 {
    let (a16, b16, c16) = (i16::from(a), i16::from(b), i16::from(c));
    let (pa, pb, pc) = ((b16 - c16).abs(), (a16 - c16).abs(), (a16 + b16 - 2 * c16).abs());
    let b_or_c = if pb <= pc { b } else { c };
    if pa <= pb && pa <= pc { a } else { b_or_c }
}

/// `data` as a zlib stream at the best level, from this thread's deflate
/// state (reset, not allocated again: setting one up was most of the cost).
fn zlib_best(data: &[u8]) -> Vec<u8> {
    use flate2::{Compress, Compression, FlushCompress, Status};
    thread_local! {
        static DEFLATE: std::cell::RefCell<Compress> = std::cell::RefCell::new(Compress::new(Compression::best(), true));
    }
    DEFLATE.with_borrow_mut(|deflate| {
        deflate.reset();
        let mut out = Vec::with_capacity(data.len() + data.len() / 64 + 64);
        loop {
            let read = deflate.total_in() as usize;
            match deflate.compress_vec(&data[read..], &mut out, FlushCompress::Finish) {
                Ok(Status::StreamEnd) => return out,
                // Only a full output stops it short: give it room and go on.
                Ok(_) => out.reserve(out.capacity().max(64)),
                Err(e) => unreachable!("deflate of a buffer in memory failed: {e}"),
            }
        }
    })
}

/// A PNG's signature and IHDR chunk (no interlace).
pub(crate) fn png_header(width: u32, height: u32, depth: u8, colour_type: u8) -> Vec<u8> {
    let mut ihdr = Vec::with_capacity(13);
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[depth, colour_type, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png_chunk(&mut png, b"IHDR", &ihdr);
    png
}

/// Appends one PNG chunk: length, type, data, CRC of type and data.
pub(crate) fn png_chunk(png: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    png.extend_from_slice(&(data.len() as u32).to_be_bytes());
    png.extend_from_slice(kind);
    png.extend_from_slice(data);
    let mut crc = crc32fast::Hasher::new();
    crc.update(kind);
    crc.update(data);
    png.extend_from_slice(&crc.finalize().to_be_bytes());
}

/// Reads any PNG (1-16 bit, grey/grey+alpha/RGB/RGBA/palette) as f32 RGBA in
/// `[0, 1]`; missing alpha becomes 1 and grey is replicated to RGB.
pub fn read_png16(path: &Path) -> Result<Image, ImageError> {
    decode_png16(path, &read_file(path)?)
}

/// One channel of `img` (alpha is 3) as a 16-bit grayscale PNG's bytes,
/// values clamped to [0, 1] (`path` names the file in errors): a channel
/// the PNG view does not show, kept beside it.
pub fn encode_png16_channel(path: &Path, img: &Image, channel: usize) -> Result<Vec<u8>, ImageError> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let samples: Vec<u8> = img.data.iter().flat_map(|p| quantize16(p[channel]).to_ne_bytes()).collect();
    let mut bytes = Vec::new();
    let encoder = PngEncoder::new_with_quality(&mut bytes, CompressionType::Best, FilterType::Adaptive);
    encoder
        .write_image(&samples, img.width, img.height, image::ExtendedColorType::L16)
        .map_err(|e| encode_error(path, "PNG", e))?;
    Ok(bytes)
}

/// [`read_png16`] of bytes already read from `path` (which errors name), for
/// callers that also hash the file.
pub fn decode_png16(path: &Path, bytes: &[u8]) -> Result<Image, ImageError> {
    let decoded =
        image::load_from_memory_with_format(bytes, ImageFormat::Png).map_err(|e| decode_error(path, "PNG", e))?;
    Ok(normalize_png(decoded))
}

/// [`decode_png16`]'s values held in 16 bits ([`Image16`]): the golden
/// view the verdict reads, at half the memory.
pub fn decode_png16_compact(path: &Path, bytes: &[u8]) -> Result<crate::Image16, ImageError> {
    let decoded =
        image::load_from_memory_with_format(bytes, ImageFormat::Png).map_err(|e| decode_error(path, "PNG", e))?;
    let (width, height) = (decoded.width(), decoded.height());
    // An 8-bit PNG's v becomes 257 v: the same value over 65535.
    Ok(crate::Image16 { width, height, data: decoded.into_rgba16().into_raw() })
}

/// Writes `img` as a ZIP-compressed f32 RGBA OpenEXR file; values (including
/// NaN, Inf and negatives) are stored bit-exactly.
pub fn write_exr(path: &Path, img: &Image) -> Result<(), ImageError> {
    atomic_write(path, &encode_exr(path, img)?)
}

/// The bytes [`write_exr`] writes (`path` names the file in errors).
pub fn encode_exr(path: &Path, img: &Image) -> Result<Vec<u8>, ImageError> {
    use exr::prelude::{Encoding, SpecificChannels, WritableImage};

    // The exr crate panics (instead of erroring) on an empty image.
    if img.width == 0 || img.height == 0 {
        let msg = format!("cannot store an empty {}x{} image", img.width, img.height);
        return Err(encode_error(path, "EXR", msg));
    }
    let (w, h) = (img.width as usize, img.height as usize);
    let channels = SpecificChannels::rgba(|pos: exr::math::Vec2<usize>| {
        let [r, g, b, a] = img.data[pos.y() * w + pos.x()];
        (r, g, b, a)
    });
    let exr_image = exr::image::Image::from_encoded_channels((w, h), Encoding::SMALL_LOSSLESS, channels);
    let mut bytes = Cursor::new(Vec::new());
    exr_image.write().non_parallel().to_buffered(&mut bytes).map_err(|e| encode_error(path, "EXR", e))?;
    Ok(bytes.into_inner())
}

/// Reads an OpenEXR file with R, G, B (and optionally A) channels as f32
/// RGBA; missing alpha becomes 1, half-float channels are widened exactly.
pub fn read_exr(path: &Path) -> Result<Image, ImageError> {
    decode_exr(path, &read_file(path)?)
}

/// [`read_exr`] of bytes already read from `path` (which errors name).
pub fn decode_exr(path: &Path, bytes: &[u8]) -> Result<Image, ImageError> {
    let decoded =
        image::load_from_memory_with_format(bytes, ImageFormat::OpenExr).map_err(|e| decode_error(path, "EXR", e))?;
    Ok(from_rgba32f(decoded.into_rgba32f()))
}

/// Writes `img` as PNG16 or EXR depending on the (case-insensitive) extension.
pub fn save(path: &Path, img: &Image) -> Result<(), ImageError> {
    match kind_of(path)? {
        Kind::Png => write_png16(path, img),
        Kind::Exr => write_exr(path, img),
    }
}

/// Reads a PNG or EXR depending on the (case-insensitive) extension.
pub fn load(path: &Path) -> Result<Image, ImageError> {
    match kind_of(path)? {
        Kind::Png => read_png16(path),
        Kind::Exr => read_exr(path),
    }
}

/// Replaces `path` with `bytes` atomically: writes a temporary file in the
/// same directory, fsyncs it and renames it over `path`. On failure the
/// temporary file is removed and any existing `path` is left untouched.
pub fn atomic_write(path: &Path, bytes: &[u8]) -> Result<(), ImageError> {
    write_via_temp(path, bytes, true)
}

/// [`atomic_write`] without syncing to disk: readers and an interrupted
/// run still see the old file or the new one, but a power cut may lose it.
/// For files every run writes again (the report): its three syncs per file
/// were a third of a small passing case's report time.
pub fn atomic_replace(path: &Path, bytes: &[u8]) -> Result<(), ImageError> {
    write_via_temp(path, bytes, false)
}

fn write_via_temp(path: &Path, bytes: &[u8], durable: bool) -> Result<(), ImageError> {
    use crate::fault::{Stop, maybe_stop};
    let io_err = |source| ImageError::Io { path: path.to_path_buf(), source };
    let n = crate::fault::next_write();
    let half = bytes.len() / 2;
    if crate::fault::plan().plain_writer {
        // The non-atomic writer a test substitutes: truncate, then write in place.
        let mut f = std::fs::File::create(path).map_err(io_err)?;
        f.write_all(&bytes[..half]).map_err(io_err)?;
        f.sync_all().map_err(io_err)?;
        maybe_stop(n, Stop::Partial, path);
        f.write_all(&bytes[half..]).map_err(io_err)?;
        f.sync_all().map_err(io_err)?;
        maybe_stop(n, Stop::BeforeRename, path);
        maybe_stop(n, Stop::After, path);
        return Ok(());
    }
    let dir = parent_dir(path);
    let mut tmp = create_temp(&dir, path).map_err(io_err)?;
    let sync = |f: &std::fs::File| if durable { f.sync_all() } else { Ok(()) };
    tmp.write_all(&bytes[..half]).map_err(io_err)?;
    sync(tmp.as_file()).map_err(io_err)?;
    maybe_stop(n, Stop::Partial, path);
    tmp.write_all(&bytes[half..]).map_err(io_err)?;
    sync(tmp.as_file()).map_err(io_err)?;
    maybe_stop(n, Stop::BeforeRename, path);
    tmp.persist(path).map_err(|e| io_err(e.error))?;
    if durable {
        sync_dir(&dir);
    }
    maybe_stop(n, Stop::After, path);
    Ok(())
}

/// Removes temp files a killed writer left in `dir` (`.<name>.XXXXXX.tmp`).
pub fn remove_stale_temps(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') && name.ends_with(".tmp") && e.path().is_file() {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

enum Kind {
    Png,
    Exr,
}

fn kind_of(path: &Path) -> Result<Kind, ImageError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(Kind::Png),
        Some("exr") => Ok(Kind::Exr),
        _ => Err(ImageError::UnsupportedExtension { path: path.to_path_buf() }),
    }
}

/// `round(clamp(v) * 255)` (the product in f32, halves away from zero),
/// NaN as 0: an 8-bit display sample.
pub fn quantize8(v: f32) -> u8 {
    if v.is_nan() {
        return 0;
    }
    // round() is a libm call on this target; x + 0.5 truncated is the same
    // for every f32 x in [0, 255]: in f64 the sum is exact wherever it is
    // near an integer (x >= 0.5 has no bit below 2^-24), so a run of 8-bit
    // copies does not spend a call per sample.
    (f64::from(v.clamp(0.0, 1.0) * 255.0) + 0.5) as u8
}

/// `round(clamp(v) * 65535)` computed in f64 so every u16 level round-trips,
/// NaN as 0: what a 16-bit PNG stores.
pub fn quantize16(v: f32) -> u16 {
    if v.is_nan() {
        return 0;
    }
    (f64::from(v.clamp(0.0, 1.0)) * 65535.0).round() as u16
}

/// Converts integer samples to `v / max` with one correctly rounded f32
/// division (image's own u8 -> f32 path is off by an ulp for some values).
fn normalize_png(decoded: DynamicImage) -> Image {
    let ct = decoded.color();
    let (width, height) = (decoded.width(), decoded.height());
    let data = if ct.bytes_per_pixel() > ct.channel_count() {
        let buf = decoded.into_rgba16();
        buf.pixels().map(|p| p.0.map(|v| f32::from(v) / 65535.0)).collect()
    } else {
        let buf = decoded.into_rgba8();
        buf.pixels().map(|p| p.0.map(|v| f32::from(v) / 255.0)).collect()
    };
    Image { width, height, data }
}

fn from_rgba32f(buf: image::Rgba32FImage) -> Image {
    let (width, height) = buf.dimensions();
    let data = buf.pixels().map(|p| p.0).collect();
    Image { width, height, data }
}

fn read_file(path: &Path) -> Result<Vec<u8>, ImageError> {
    std::fs::read(path).map_err(|source| ImageError::Io { path: path.to_path_buf(), source })
}

fn decode_error(path: &Path, format: &'static str, e: impl ToString) -> ImageError {
    ImageError::Decode { path: path.to_path_buf(), format, msg: e.to_string() }
}

fn encode_error(path: &Path, format: &'static str, e: impl ToString) -> ImageError {
    ImageError::Encode { path: path.to_path_buf(), format, msg: e.to_string() }
}

/// The directory the temp file must live in so the final rename stays on one
/// filesystem; a bare file name means the current directory.
pub(crate) fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Creates the temp file as `.<target>.XXXXXX.tmp` so a stray one (after a
/// hard kill) is recognisable and hidden.
pub(crate) fn create_temp(dir: &Path, path: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".tmp");
    // tempfile defaults to 0600; ask for 0666 so the umask decides, like File::create.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(dir)
}

/// Best effort: make the rename itself durable. Not all platforms or
/// filesystems allow syncing a directory, and the data is already safe.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// Makes `dir` a real directory for files vista owns (the report's
/// folders): a symlink in its place is removed (the link, never what it
/// points at) and a directory made instead, so no write goes through it.
/// A `thumbs.d -> ../../golden/rings` planted in the report folder leaves
/// the goldens untouched.
pub fn own_dir(dir: &Path) -> Result<(), ImageError> {
    let io_err = |source| ImageError::Io { path: dir.to_path_buf(), source };
    if std::fs::symlink_metadata(dir).is_ok_and(|m| m.file_type().is_symlink()) {
        std::fs::remove_file(dir).map_err(io_err)?;
    }
    std::fs::create_dir_all(dir).map_err(io_err)
}

/// Makes `dir` (a folder under `root`) a real directory reached from
/// `root` without a symlink, for files the user keeps (goldens): a symlink
/// on the way is refused, naming where it leads, never followed.
pub fn real_dir_under(root: &Path, dir: &Path) -> Result<(), ImageError> {
    let rel = dir.strip_prefix(root).unwrap_or(dir);
    let mut at = root.to_path_buf();
    for part in rel.components() {
        at.push(part);
        if let Ok(m) = std::fs::symlink_metadata(&at)
            && m.file_type().is_symlink()
        {
            let to = std::fs::read_link(&at).map(|t| t.display().to_string()).unwrap_or_default();
            return Err(ImageError::Io {
                path: at.clone(),
                source: std::io::Error::other(format!(
                    "is a symlink to {to}; vista writes goldens only into real folders of the project"
                )),
            });
        }
    }
    std::fs::create_dir_all(dir).map_err(|source| ImageError::Io { path: dir.to_path_buf(), source })
}

#[cfg(test)]
mod tests {
    #[test]
    fn quantize8_rounds_as_round_does_for_every_f32_near_a_half() {
        let reference = |v: f32| if v.is_nan() { 0 } else { (v.clamp(0.0, 1.0) * 255.0).round() as u8 };
        // Every f32 within 4096 ulps of each (k + 1/2) / 255 and of each
        // k / 255, the ends, out of range values and NaN.
        let mut values =
            vec![0.0f32, -0.0, 1.0, -1.0, 2.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MIN_POSITIVE];
        for k in 0..=255u32 {
            for centre in [(k as f32 + 0.5) / 255.0, k as f32 / 255.0] {
                let bits = centre.to_bits();
                values.extend((bits.saturating_sub(4096)..bits + 4096).map(f32::from_bits));
            }
        }
        for v in values {
            assert_eq!(super::quantize8(v), reference(v), "v = {v:e} ({:#x})", v.to_bits());
        }
        // And a sweep of the whole range, one f32 in 97.
        for bits in (0..=1.0f32.to_bits()).step_by(97) {
            let v = f32::from_bits(bits);
            assert_eq!(super::quantize8(v), reference(v), "v = {v:e}");
        }
    }

    #[test]
    fn paeth_is_the_png_specifications_predictor() {
        // The specification's wording: the nearest of a, b, c to a + b - c,
        // ties to a, then b.
        for (a, b, c) in (0..=255u8)
            .flat_map(|a| (0..=255u8).step_by(3).flat_map(move |b| (0..=255u8).step_by(5).map(move |c| (a, b, c))))
        {
            let p = i16::from(a) + i16::from(b) - i16::from(c);
            let (pa, pb, pc) = ((p - i16::from(a)).abs(), (p - i16::from(b)).abs(), (p - i16::from(c)).abs());
            let spec = if pa <= pb && pa <= pc {
                a
            } else if pb <= pc {
                b
            } else {
                c
            };
            assert_eq!(super::paeth(a, b, c), spec, "a {a}, b {b}, c {c}");
        }
    }
}
