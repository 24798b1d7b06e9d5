//! The in-memory image type.

use crate::ImageError;

/// A linear f32 RGBA image, row-major with `y = 0` at the top.
///
/// Values are stored exactly as produced (no clamping, NaN/Inf allowed), so
/// the type can hold both LDR output and raw HDR kernel results.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels (number of rows).
    pub height: u32,
    /// `width * height` pixels; pixel `(x, y)` is at `y * width + x`.
    pub data: Vec<[f32; 4]>,
}

impl Image {
    /// An all-zero (transparent black) image.
    pub fn new(width: u32, height: u32) -> Image {
        Image { width, height, data: vec![[0.0; 4]; pixel_count(width, height)] }
    }

    /// Builds an image by evaluating `f(x, y)` for every pixel in row-major order.
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> [f32; 4]) -> Image {
        let mut data = Vec::with_capacity(pixel_count(width, height));
        for y in 0..height {
            for x in 0..width {
                data.push(f(x, y));
            }
        }
        Image { width, height, data }
    }

    /// A copy at most `edge` texels on its longer side, each texel the mean
    /// of the block it covers (the image itself when it fits): what a
    /// report shows of a passing case, whose golden holds the full image.
    pub fn thumbnail(&self, edge: u32) -> Image {
        let long = self.width.max(self.height);
        if edge == 0 || long <= edge {
            return self.clone();
        }
        let f = long.div_ceil(edge);
        Image::from_fn(self.width.div_ceil(f), self.height.div_ceil(f), |x, y| {
            let (x0, y0) = (x * f, y * f);
            let (x1, y1) = ((x0 + f).min(self.width), (y0 + f).min(self.height));
            let mut sum = [0f64; 4];
            for yy in y0..y1 {
                for xx in x0..x1 {
                    let p = self.data[yy as usize * self.width as usize + xx as usize];
                    for c in 0..4 {
                        sum[c] += f64::from(p[c]);
                    }
                }
            }
            let n = f64::from((x1 - x0) * (y1 - y0));
            sum.map(|v| (v / n) as f32)
        })
    }

    /// Wraps an existing pixel buffer, checking that its length is `width * height`.
    pub fn from_raw(width: u32, height: u32, data: Vec<[f32; 4]>) -> Result<Image, ImageError> {
        let expected = u64::from(width) * u64::from(height);
        if data.len() as u64 != expected {
            return Err(ImageError::BadDimensions { width, height, expected, len: data.len() });
        }
        Ok(Image { width, height, data })
    }

    /// The `w` x `h` rectangle whose top-left pixel is `(x, y)`, or None when
    /// it is empty or reaches outside the image.
    pub fn crop(&self, x: u32, y: u32, w: u32, h: u32) -> Option<Image> {
        let inside = w > 0 && h > 0 && x.checked_add(w)? <= self.width && y.checked_add(h)? <= self.height;
        inside.then(|| Image::from_fn(w, h, |i, j| self.get(x + i, y + j)))
    }

    /// Every pixel repeated `n` x `n` times (nearest neighbour), so a crop
    /// shows its pixels, banding and noise included, without resampling.
    pub fn zoom(&self, n: u32) -> Image {
        Image::from_fn(self.width * n, self.height * n, |x, y| self.get(x / n, y / n))
    }

    /// Box blur of radius `r` (a (2r + 1)^2 mean, the window clipped at the
    /// edges), every channel. Comparing blurred images measures structured
    /// error (banding) apart from pixel noise, which the mean removes.
    pub fn box_blur(&self, r: u32) -> Image {
        let (w, h, r) = (self.width as i64, self.height as i64, r as i64);
        Image::from_fn(self.width, self.height, |x, y| {
            let (mut sum, mut n) = ([0.0f64; 4], 0.0);
            for j in (y as i64 - r).max(0)..=(y as i64 + r).min(h - 1) {
                for i in (x as i64 - r).max(0)..=(x as i64 + r).min(w - 1) {
                    let p = self.get(i as u32, j as u32);
                    for c in 0..4 {
                        sum[c] += p[c] as f64;
                    }
                    n += 1.0;
                }
            }
            sum.map(|v| (v / n) as f32)
        })
    }

    /// `(width, height)`.
    pub fn dimensions(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The pixel at `(x, y)`.
    ///
    /// # Panics
    /// If `(x, y)` is outside the image.
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        self.data[self.index(x, y)]
    }

    /// Overwrites the pixel at `(x, y)`.
    ///
    /// # Panics
    /// If `(x, y)` is outside the image.
    pub fn set(&mut self, x: u32, y: u32, v: [f32; 4]) {
        let i = self.index(x, y);
        self.data[i] = v;
    }

    /// The first pixel in row-major order with a NaN or ±Inf in any channel
    /// (alpha included).
    pub fn first_nonfinite(&self) -> Option<(u32, u32)> {
        let i = self.data.iter().position(|p| !is_finite_pixel(p))?;
        // `i < width * height`, so both coordinates fit in u32.
        let w = self.width as usize;
        Some(((i % w) as u32, (i / w) as u32))
    }

    /// Number of pixels with a NaN or ±Inf in any channel (alpha included).
    pub fn nonfinite_count(&self) -> u64 {
        self.data.iter().filter(|p| !is_finite_pixel(p)).count() as u64
    }

    /// A 16-hex-digit FNV-1a 64 hash of the width, height and the exact f32
    /// bit patterns (all little-endian), so it is stable across runs and
    /// platforms and distinguishes `0.0` from `-0.0` and NaN payloads.
    pub fn content_hash(&self) -> String {
        let mut h = Fnv1a64::new();
        h.write(&self.width.to_le_bytes());
        h.write(&self.height.to_le_bytes());
        h.write(&self.le_bytes());
        format!("{:016x}", h.finish())
    }

    /// The texels' f32 bit patterns, little-endian, RGBA, row after row
    /// (16 bytes a texel): borrowed on a little-endian machine, where that
    /// is how they lie in memory.
    pub fn le_bytes(&self) -> std::borrow::Cow<'_, [u8]> {
        if cfg!(target_endian = "little") {
            std::borrow::Cow::Borrowed(bytemuck::cast_slice(&self.data))
        } else {
            std::borrow::Cow::Owned(self.data.iter().flatten().flat_map(|c| c.to_le_bytes()).collect())
        }
    }

    /// The image [`Image::le_bytes`] gave, or `None` when `bytes` is not
    /// `width * height` texels.
    pub fn from_le_bytes(width: u32, height: u32, bytes: &[u8]) -> Option<Image> {
        if bytes.len() != width as usize * height as usize * 16 {
            return None;
        }
        let data: Vec<[f32; 4]> = if cfg!(target_endian = "little") {
            bytemuck::pod_collect_to_vec(bytes)
        } else {
            let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            bytes.chunks_exact(16).map(|t| [f(&t[0..4]), f(&t[4..8]), f(&t[8..12]), f(&t[12..16])]).collect()
        };
        Some(Image { width, height, data })
    }

    /// True if both images have the same size and every channel has the same
    /// f32 bit pattern. Unlike `==`, this treats identical NaNs as equal and
    /// `0.0` / `-0.0` as different.
    pub fn bit_identical(&self, other: &Image) -> bool {
        self.dimensions() == other.dimensions()
            && self.data.iter().zip(&other.data).all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits))
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) is outside the {}x{} image",
            self.width,
            self.height
        );
        y as usize * self.width as usize + x as usize
    }
}

fn pixel_count(width: u32, height: u32) -> usize {
    width as usize * height as usize
}

fn is_finite_pixel(p: &[f32; 4]) -> bool {
    p.iter().all(|c| c.is_finite())
}

/// Minimal FNV-1a 64; hand-rolled so the hash never changes with a dependency.
struct Fnv1a64(u64);

impl Fnv1a64 {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    fn new() -> Self {
        Fnv1a64(Self::OFFSET)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(Self::PRIME);
        }
    }

    fn finish(&self) -> u64 {
        self.0
    }
}
