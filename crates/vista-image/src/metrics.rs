//! Image comparison metrics.
//!
//! All metrics look at R, G and B only (alpha is excluded) and use the values
//! as stored, accumulated in f64. They agree with scikit-image to well below
//! 1e-3 (see `tests/skimage_agreement.rs`).
//!
//! # Non-finite values
//! A channel pair whose f32 bit patterns are identical (including identical
//! NaNs) counts as no difference, so bit-identical images always give
//! `mse == 0` and `psnr == inf`. Any other pair whose difference is NaN or
//! ±Inf counts as
//! * an error of `+inf` for [`max_abs`] (the pixel is also a bad pixel), and
//! * a squared error of `1.0` (a full-scale LDR error) for [`mse`]/[`psnr`],
//!   so PSNR stays finite and meaningful instead of collapsing to NaN/-inf;
//! * for [`ssim`], non-finite channels are replaced by 0 before the luma is
//!   computed, so a few bad pixels lower SSIM locally instead of poisoning it.
//!
//! [`Metrics::nan`] reports how many pixels of the actual image are
//! non-finite, so these substitutions never hide a problem.

use serde::{Deserialize, Serialize};

use crate::{Image, ImageError, Texels, ssim as ssim_impl};

/// A pixel is "bad" when any RGB channel differs by more than one 8-bit step.
pub const BAD_PIXEL_THRESHOLD: f64 = 1.0 / 255.0;

/// Every metric for one reference/actual pair.
///
/// Serialises non-finite floats (`psnr` of identical images is `+inf`) as the
/// strings `"inf"`, `"-inf"` and `"nan"`, because JSON has no such numbers
/// and serde_json would otherwise write `null` and fail to read it back.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct Metrics {
    /// dB; `+inf` when the images are identical.
    #[serde(with = "float_repr")]
    pub psnr: f64,
    /// Mean SSIM of the luma, in [-1, 1]; 1 when identical (see [`ssim`]).
    #[serde(with = "float_repr")]
    pub ssim: f64,
    /// Largest absolute RGB channel difference; `+inf` if a differing pair is
    /// non-finite.
    #[serde(with = "float_repr")]
    pub max_abs: f64,
    /// Pixels where any RGB channel differs by more than 1/255.
    pub bad_pixels: u64,
    /// Pixels of the actual image with a NaN/Inf in any channel (RGBA).
    pub nan: u64,
    /// Mean squared RGB error, a non-finite difference counting as 1.
    #[serde(with = "float_repr")]
    pub mse: f64,
    /// Mean LDR-FLIP error in [0, 1] (NVIDIA's FLIP at
    /// [`FLIP_PIXELS_PER_DEGREE`] on the display values as 8-bit sRGB);
    /// `None` for HDR comparisons.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flip_mean: Option<f64>,
}

/// FLIP's viewing condition: a 0.7 m distance from a 24" 4K monitor.
pub const FLIP_PIXELS_PER_DEGREE: f32 = 67.0;

/// Mean LDR-FLIP error of `actual` against `reference` (display values in
/// [0, 1], sRGB-encoded, alpha ignored; NaN counts as 0): 0 for identical
/// images, 1 at most.
///
/// # Panics
/// If the images differ in size.
pub fn flip_mean(reference: &(impl Texels + ?Sized), actual: &(impl Texels + ?Sized)) -> f64 {
    assert_same_size(reference, actual);
    let (w, h) = reference.size();
    if w == 0 || h == 0 {
        return 0.0;
    }
    // A strip's rows as FLIP reads them, made per strip: both images whole
    // in 8-bit RGB were 24 MiB more at 2048 x 2048.
    fn rgb8(img: &(impl Texels + ?Sized), y0: usize, y1: usize) -> Vec<u8> {
        let (mut out, mut buf) = (Vec::with_capacity((y1 - y0) * img.size().0 as usize * 3), Vec::new());
        for y in y0..y1 {
            for p in img.row(y as u32, &mut buf) {
                out.extend_from_slice(&[crate::quantize8(p[0]), crate::quantize8(p[1]), crate::quantize8(p[2])]);
            }
        }
        out
    }
    let (reference_rows, actual_rows) = (|y0, y1| rgb8(reference, y0, y1), |y0, y1| rgb8(actual, y0, y1));
    let threads = crate::threads_for(w as usize * h as usize);
    let errors = flip_error_sums(w, h, &reference_rows, &actual_rows, threads);
    // Summed in f64 (FLIP's own pool sums in f32, which drifts over millions
    // of pixels).
    errors.iter().sum::<f64>() / (f64::from(w) * f64::from(h))
}

/// Rows of context a strip of [`flip_strips`] takes past each of its ends.
/// FLIP's widest filter (its colour CSF) reaches ceil(3 sqrt(0.04 / (2
/// pi^2)) ppd) = 10 pixels at 67 pixels per degree, its feature filters 9
/// (measured: 10 rows is the least that keeps every bit).
const FLIP_HALO: usize = 16;

/// Most rows per FLIP strip: FLIP holds about 76 bytes per pixel of its
/// own, so a 2048 x 2048 image in one piece took 320 MB; strips of at most
/// 256 rows, two at once, take about 90 MB, for 11-18% more rows computed
/// (576-row strips took 180 MB and were a failing case's peak; at 1920 x
/// 1080 these cost 0.01-0.03 s more per case and peak 120 MB lower).
const FLIP_STRIP: usize = 256;

/// What FLIP holds per pixel of a strip (measured: 76 bytes).
const FLIP_BYTES_PER_PIXEL: usize = 76;

/// What FLIP's strips at once may hold together: a fixed amount, not a
/// share of the image, so a wide image gets shorter strips. 256-row strips
/// of a 2048-wide image were 90 MB, the peak of a failing 2048 x 2048
/// case; 48 MiB lets them be 129 rows (50 MB) there and 140 at 1920 wide.
const FLIP_BUDGET: usize = 48 << 20;

/// The most rows a strip of a `width`-wide image may have when `threads`
/// strips are computed at once: [`FLIP_BUDGET`] less their halos, at most
/// [`FLIP_STRIP`], at least 4 halos' worth (narrower strips compute more
/// halo than image).
fn flip_strip_rows(width: usize, threads: usize) -> usize {
    let rows = FLIP_BUDGET / (threads.max(1) * width.max(1) * FLIP_BYTES_PER_PIXEL);
    rows.saturating_sub(2 * FLIP_HALO).clamp(4 * FLIP_HALO, FLIP_STRIP)
}

/// Rows `y0..y1` of an image as FLIP reads them: 8-bit RGB, row after row.
type Rows<'a> = &'a (dyn Fn(usize, usize) -> Vec<u8> + Sync);

/// FLIP's per-pixel errors of two `w` x `h` RGB8 images, computed in
/// horizontal strips of at most [`FLIP_STRIP`] rows, `threads` at once
/// (FLIP is single-threaded C++; a failing 1080p case spent most of its own
/// time here), each handed to `take`, the results top to bottom. Each strip
/// is computed with [`FLIP_HALO`] rows of context at each end, whose errors
/// are dropped, so every pixel's error is bit for bit the one of the whole
/// image.
fn flip_strips<T: Send>(
    w: u32,
    h: u32,
    reference: Rows<'_>,
    actual: Rows<'_>,
    threads: usize,
    take: impl Fn(&[f32]) -> T + Sync,
) -> Vec<T> {
    // Equal strips, a multiple of the threads: no thread waits on a short one.
    let (height, threads) = (h as usize, threads.max(1));
    let strips = threads * height.div_ceil(threads * flip_strip_rows(w as usize, threads));
    flip_strips_of(w, h, reference, actual, height.div_ceil(strips.max(1)), threads, take)
}

fn flip_strips_of<T: Send>(
    w: u32,
    h: u32,
    reference: Rows<'_>,
    actual: Rows<'_>,
    rows: usize,
    threads: usize,
    take: impl Fn(&[f32]) -> T + Sync,
) -> Vec<T> {
    let (width, height) = (w as usize, h as usize);
    let strip = |y0: usize| {
        let y1 = (y0 + rows).min(height);
        let (c0, c1) = (y0.saturating_sub(FLIP_HALO), (y1 + FLIP_HALO).min(height));
        let image = |d: Rows<'_>| nv_flip::FlipImageRgb8::with_data(w, (c1 - c0) as u32, &d(c0, c1));
        let errors = nv_flip::flip(image(reference), image(actual), FLIP_PIXELS_PER_DEGREE).to_vec();
        take(&errors[(y0 - c0) * width..(y1 - c0) * width])
    };
    let starts: Vec<usize> = (0..height.max(1)).step_by(rows.max(1)).collect();
    let mut out = Vec::with_capacity(starts.len());
    crate::threads::in_groups(&starts, threads, |&y0| strip(y0), |r| out.push(r));
    if threads > 1 {
        crate::threads::release_freed_memory();
    }
    out
}

/// The sum of FLIP's per-pixel errors in each row, top to bottom (see
/// [`flip_strips`]; by row, so that the mean does not depend on the strips).
fn flip_error_sums(w: u32, h: u32, reference: Rows<'_>, actual: Rows<'_>, threads: usize) -> Vec<f64> {
    let row_sums = |e: &[f32]| -> Vec<f64> {
        e.chunks(w.max(1) as usize).map(|row| row.iter().map(|&v| f64::from(v)).sum()).collect()
    };
    flip_strips(w, h, reference, actual, threads, row_sums).concat()
}

/// All metrics with a PSNR peak of 1 (LDR data in `[0, 1]`).
pub fn compare(reference: &(impl Texels + ?Sized), actual: &Image) -> Result<Metrics, ImageError> {
    check_same_size(reference, actual)?;
    if let Some(m) = identical(reference, actual, true) {
        return Ok(m);
    }
    Ok(Metrics { flip_mean: Some(flip_mean(reference, actual)), ..all_metrics(reference, actual, 1.0) })
}

/// The metrics of two images with the same bits, all finite, without the
/// passes that compute them (a passing check's render is usually its
/// golden bit for bit, and SSIM and FLIP cost most of a check): PSNR +inf,
/// SSIM 1, no difference, FLIP 0 where asked. `None` where any bit differs
/// or a value is not finite.
fn identical(reference: &(impl Texels + ?Sized), actual: &Image, flip: bool) -> Option<Metrics> {
    let bits = |p: &[f32; 4]| p.map(f32::to_bits);
    let mut buf = Vec::new();
    let same = reference.size() == actual.size()
        && (0..actual.height).all(|y| {
            reference
                .row(y, &mut buf)
                .iter()
                .zip(actual.row(y, &mut Vec::new()))
                .all(|(r, a)| bits(r) == bits(a) && a.iter().all(|v| v.is_finite()))
        });
    same.then_some(Metrics {
        psnr: f64::INFINITY,
        ssim: 1.0,
        max_abs: 0.0,
        bad_pixels: 0,
        nan: 0,
        mse: 0.0,
        flip_mean: flip.then_some(0.0),
    })
}

/// All metrics for HDR data: PSNR uses peak = [`hdr_peak`] of the reference.
/// SSIM is still computed on the raw values with dynamic range 1.
pub fn compare_hdr(reference: &Image, actual: &Image) -> Result<Metrics, ImageError> {
    check_same_size(reference, actual)?;
    if let Some(m) = identical(reference, actual, false) {
        return Ok(m);
    }
    Ok(all_metrics(reference, actual, hdr_peak(reference)))
}

/// The largest finite RGB value of `reference`, or 1 when there is no
/// positive finite value (an all-black reference would otherwise give peak 0).
pub fn hdr_peak(reference: &Image) -> f64 {
    let peak = rgb_values(reference).filter(|v| v.is_finite()).fold(f64::NEG_INFINITY, f64::max);
    if peak > 0.0 { peak } else { 1.0 }
}

/// Mean squared error over all pixels and the three RGB channels (0 for an
/// empty image).
///
/// # Panics
/// If the images differ in size; [`compare`] returns an error instead.
pub fn mse(a: &Image, b: &Image) -> f64 {
    assert_same_size(a, b);
    let n = a.data.len() * 3;
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = channel_pairs(a, b).map(|(x, y)| squared_error(x, y)).sum();
    sum / n as f64
}

/// PSNR in dB with peak 1; `+inf` when the images are identical.
///
/// # Panics
/// If the images differ in size.
pub fn psnr(a: &Image, b: &Image) -> f64 {
    psnr_with_peak(a, b, 1.0)
}

/// `10 log10(peak² / MSE)`; `+inf` when MSE is 0.
///
/// # Panics
/// If the images differ in size.
pub fn psnr_with_peak(a: &Image, b: &Image, peak: f64) -> f64 {
    psnr_from_mse(mse(a, b), peak)
}

/// Mean SSIM of the Rec. 709 luma (`0.2126 R + 0.7152 G + 0.0722 B`) of both
/// images: 11x11 Gaussian window (sigma 1.5), population statistics,
/// dynamic range 1, averaged over pixels whose whole window is inside the
/// image (a 5-pixel border is cropped), like scikit-image's
/// `structural_similarity(gaussian_weights=True, sigma=1.5,
/// use_sample_covariance=False, data_range=1.0)`.
///
/// Images smaller than 11 pixels in either direction (where scikit-image
/// raises an error) use one global window with uniform weights instead; an
/// empty image scores 1.
///
/// # Panics
/// If the images differ in size.
pub fn ssim(a: &(impl Texels + ?Sized), b: &(impl Texels + ?Sized)) -> f64 {
    assert_same_size(a, b);
    let (w, h) = (a.size().0 as usize, a.size().1 as usize);
    // Luma made a row at a time where a band reads it, not as whole planes.
    fn rows(img: &(impl Texels + ?Sized), r: usize, row: &mut [f64]) {
        let mut buf = Vec::new();
        for (v, p) in row.iter_mut().zip(img.row(r as u32, &mut buf)) {
            *v = luma_of(p);
        }
    }
    ssim_impl::ssim_rows(&|r, row| rows(a, r, row), &|r, row| rows(b, r, row), w, h)
}

/// Largest absolute RGB difference; `+inf` if any differing pair is non-finite.
///
/// # Panics
/// If the images differ in size.
pub fn max_abs(a: &Image, b: &Image) -> f64 {
    assert_same_size(a, b);
    channel_pairs(a, b).map(|(x, y)| abs_diff(x, y)).fold(0.0, f64::max)
}

/// Number of pixels where any RGB channel differs by more than 1/255
/// (non-finite differences count as bad).
///
/// # Panics
/// If the images differ in size.
pub fn bad_pixels(a: &Image, b: &Image) -> u64 {
    assert_same_size(a, b);
    a.data.iter().zip(&b.data).filter(|(p, q)| (0..3).any(|c| abs_diff(p[c], q[c]) > BAD_PIXEL_THRESHOLD)).count()
        as u64
}

/// `"identical"` for `+inf`, otherwise e.g. `"42.13 dB"`.
pub fn format_psnr(psnr: f64) -> String {
    if psnr == f64::INFINITY { "identical".to_string() } else { format!("{psnr:.2} dB") }
}

fn all_metrics(reference: &(impl Texels + ?Sized), actual: &Image, peak: f64) -> Metrics {
    // One pass for the squared error, the largest difference and the bad
    // pixels (the same values as mse, max_abs and bad_pixels, summed in the
    // same order).
    let (mut sum, mut max, mut bad) = (0.0, 0.0, 0u64);
    let (w, mut buf) = (actual.width as usize, Vec::new());
    for y in 0..actual.height {
        let theirs = reference.row(y, &mut buf);
        for (p, q) in theirs.iter().zip(&actual.data[y as usize * w..][..w]) {
            let mut is_bad = false;
            for c in 0..3 {
                let d = abs_diff(p[c], q[c]);
                sum += if d.is_finite() { d * d } else { 1.0 };
                max = f64::max(max, d);
                is_bad |= d > BAD_PIXEL_THRESHOLD;
            }
            bad += u64::from(is_bad);
        }
    }
    let n = actual.data.len() * 3;
    let mse = if n == 0 { 0.0 } else { sum / n as f64 };
    Metrics {
        psnr: psnr_from_mse(mse, peak),
        ssim: ssim(reference, actual),
        max_abs: max,
        bad_pixels: bad,
        nan: actual.nonfinite_count(),
        mse,
        flip_mean: None,
    }
}

/// `10 log10(peak² / mse)`; `+inf` when `mse` is 0.
pub fn psnr_from_mse(mse: f64, peak: f64) -> f64 {
    if mse == 0.0 { f64::INFINITY } else { 10.0 * (peak * peak / mse).log10() }
}

/// `|a - b|` in f64; 0 for identical bit patterns, `+inf` when non-finite.
fn abs_diff(a: f32, b: f32) -> f64 {
    if a.to_bits() == b.to_bits() {
        return 0.0;
    }
    let d = (f64::from(a) - f64::from(b)).abs();
    if d.is_finite() { d } else { f64::INFINITY }
}

/// Squared error with a non-finite difference counted as a full-scale error.
fn squared_error(a: f32, b: f32) -> f64 {
    let d = abs_diff(a, b);
    if d.is_finite() { d * d } else { 1.0 }
}

fn channel_pairs<'a>(a: &'a Image, b: &'a Image) -> impl Iterator<Item = (f32, f32)> + 'a {
    a.data.iter().zip(&b.data).flat_map(|(p, q)| (0..3).map(move |c| (p[c], q[c])))
}

fn rgb_values(img: &Image) -> impl Iterator<Item = f64> + '_ {
    img.data.iter().flat_map(|p| p[..3].iter().map(|&v| f64::from(v)))
}

/// Rec. 709 luma with non-finite channels replaced by 0 (see module docs).
/// Rec. 709 luma of a texel, non-finite channels as 0: what SSIM compares.
fn luma_of(p: &[f32; 4]) -> f64 {
    let finite = |v: f32| if v.is_finite() { f64::from(v) } else { 0.0 };
    0.2126 * finite(p[0]) + 0.7152 * finite(p[1]) + 0.0722 * finite(p[2])
}

fn check_same_size(reference: &(impl Texels + ?Sized), actual: &(impl Texels + ?Sized)) -> Result<(), ImageError> {
    if reference.size() == actual.size() {
        Ok(())
    } else {
        Err(ImageError::SizeMismatch { expected: reference.size(), actual: actual.size() })
    }
}

fn assert_same_size(a: &(impl Texels + ?Sized), b: &(impl Texels + ?Sized)) {
    if let Err(e) = check_same_size(a, b) {
        panic!("{e}");
    }
}

/// Serde adapter writing non-finite f64 as `"inf"` / `"-inf"` / `"nan"` and
/// reading numbers, those strings, or `null` (as NaN).
mod float_repr {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() {
            s.serialize_f64(*v)
        } else if v.is_nan() {
            s.serialize_str("nan")
        } else if *v > 0.0 {
            s.serialize_str("inf")
        } else {
            s.serialize_str("-inf")
        }
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Repr {
        Num(f64),
        Text(String),
        Null(()),
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match Repr::deserialize(d)? {
            Repr::Num(v) => Ok(v),
            Repr::Text(t) => t
                .parse::<f64>()
                .map_err(|_| D::Error::custom(format!("expected a number, \"inf\", \"-inf\" or \"nan\", got {t:?}"))),
            Repr::Null(()) => Ok(f64::NAN),
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn one_pass_metrics_are_the_separate_ones() {
        let (w, h) = (13u32, 7u32);
        let pixel = |i: u32, k: f32| {
            let v = ((i as f32 * k).sin() * 0.5 + 0.5).clamp(0.0, 1.0);
            [v, 1.0 - v, v * v, 1.0]
        };
        let a = Image { width: w, height: h, data: (0..w * h).map(|i| pixel(i, 0.7)).collect() };
        let mut b = Image { width: w, height: h, data: (0..w * h).map(|i| pixel(i, 0.71)).collect() };
        b.data[3][1] = f32::NAN;
        b.data[5][0] = f32::INFINITY;
        let m = all_metrics(&a, &b, 1.0);
        assert_eq!(m.mse.to_bits(), mse(&a, &b).to_bits());
        assert_eq!(m.max_abs.to_bits(), max_abs(&a, &b).to_bits());
        assert_eq!(m.bad_pixels, bad_pixels(&a, &b));
        assert!(m.bad_pixels > 2 && m.max_abs == f64::INFINITY);
    }

    #[test]
    fn flip_in_strips_is_the_whole_image_bit_for_bit() {
        // Noise with edges, so that the features and the colour filters both
        // see strip boundaries.
        let (w, h) = (97u32, 403u32);
        let mut state = 12345u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 24) as u8
        };
        let reference: Vec<u8> = (0..w * h * 3).map(|_| next()).collect();
        let actual: Vec<u8> = reference
            .iter()
            .enumerate()
            .map(|(i, &v)| if i % 7 == 0 { v.wrapping_add(next() % 40) } else { v })
            .collect();
        let row = (w * 3) as usize;
        let (reference, actual) = (
            move |y0: usize, y1: usize| reference[y0 * row..y1 * row].to_vec(),
            move |y0: usize, y1: usize| actual[y0 * row..y1 * row].to_vec(),
        );
        let errors = |rows, threads| flip_strips_of(w, h, &reference, &actual, rows, threads, <[f32]>::to_vec).concat();
        let whole = errors(h as usize, 1);
        assert_eq!(whole.len(), (w * h) as usize);
        assert!(whole.iter().any(|&e| e > 0.0));
        for (rows, threads) in [(202, 1), (202, 2), (134, 3), (40, 2)] {
            let parts = errors(rows, threads);
            let same = whole.iter().zip(&parts).all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same && parts.len() == whole.len(), "strips of {rows} rows, {threads} at once, differ");
        }
        let sums = |threads| flip_error_sums(w, h, &reference, &actual, threads).iter().sum::<f64>();
        assert_eq!(sums(1).to_bits(), sums(3).to_bits(), "the mean depends on the threads");
    }

    use super::*;

    /// The shortcut for identical images says what the full passes say
    /// (SSIM to rounding: the passes give 1 - 2e-16 where the formula is 1
    /// exactly), on a pattern, a constant image (SSIM's degenerate case), an
    /// image below SSIM's window and a wide one; and it is not taken for
    /// one changed bit or a NaN.
    #[test]
    fn identical_images_skip_the_passes_and_agree_with_them() {
        let pattern = |w: u32, h: u32| {
            Image::from_fn(w, h, |x, y| {
                let t = (x as f32 * 0.7).sin() * (y as f32 * 0.3).cos();
                [0.5 + 0.4 * t, x as f32 / w as f32, y as f32 / h as f32, 1.0]
            })
        };
        let constant = Image::from_fn(24, 24, |_, _| [0.25, 0.25, 0.25, 1.0]);
        for img in [pattern(32, 24), constant, pattern(5, 7), pattern(97, 13)] {
            let fast = identical(&img, &img, true).expect("identical");
            let full = Metrics { flip_mean: Some(flip_mean(&img, &img)), ..all_metrics(&img, &img, 1.0) };
            assert_eq!(
                (fast.psnr, fast.max_abs, fast.bad_pixels, fast.nan, fast.mse),
                (full.psnr, full.max_abs, full.bad_pixels, full.nan, full.mse)
            );
            assert_eq!(fast.flip_mean, full.flip_mean);
            assert!((fast.ssim - full.ssim).abs() < 1e-12, "{} vs {}", fast.ssim, full.ssim);
            let hdr = all_metrics(&img, &img, hdr_peak(&img));
            assert_eq!(identical(&img, &img, false).unwrap().flip_mean, hdr.flip_mean);
        }
        let a = pattern(8, 8);
        let mut b = a.clone();
        b.data[5][1] = f32::from_bits(b.data[5][1].to_bits() + 1);
        assert!(identical(&a, &b, true).is_none(), "one bit differs");
        assert!(compare(&a, &b).unwrap().psnr.is_finite());
        let mut n = a.clone();
        n.data[3][0] = f32::NAN;
        assert!(identical(&n, &n, true).is_none(), "NaN is never identical");
    }
}
