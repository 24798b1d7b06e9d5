//! Hand-computed metric cases.

use vista_image::metrics::{self, Metrics, compare, compare_hdr, format_psnr};
use vista_image::{Image, ImageError};

fn constant(w: u32, h: u32, v: f32, alpha: f32) -> Image {
    Image::from_fn(w, h, |_, _| [v, v, v, alpha])
}

fn pattern(w: u32, h: u32) -> Image {
    Image::from_fn(w, h, |x, y| {
        let t = (x as f32 * 0.7).sin() * (y as f32 * 0.3).cos();
        [0.5 + 0.4 * t, x as f32 / w as f32, y as f32 / h as f32, 1.0]
    })
}

#[test]
fn identical_images() {
    let a = pattern(16, 16);
    let m = compare(&a, &a.clone()).unwrap();
    assert_eq!(m.psnr, f64::INFINITY);
    assert!((m.ssim - 1.0).abs() < 1e-12, "{}", m.ssim);
    assert_eq!(m.max_abs, 0.0);
    assert_eq!(m.mse, 0.0);
    assert_eq!(m.bad_pixels, 0);
    assert_eq!(m.nan, 0);
    assert_eq!(format_psnr(m.psnr), "identical");
}

#[test]
fn constant_offset_gives_20_db() {
    // Alpha differs too and must be ignored.
    let r = constant(16, 16, 0.25, 1.0);
    let a = constant(16, 16, 0.35, 0.0);
    let m = compare(&r, &a).unwrap();
    assert!((m.mse - 0.01).abs() < 1e-8, "mse {}", m.mse);
    assert!((m.psnr - 20.0).abs() < 1e-5, "psnr {}", m.psnr);
    assert!((m.max_abs - 0.1).abs() < 1e-7, "max_abs {}", m.max_abs);
    assert_eq!(m.bad_pixels, 256);
    assert_eq!(format_psnr(m.psnr), "20.00 dB");

    // Flat images: variances vanish, SSIM = (2 mx my + C1) / (mx² + my² + C1).
    let (mx, my) = (0.25f64, f64::from(0.35f32));
    let c1 = 1e-4;
    let expected = (2.0 * mx * my + c1) / (mx * mx + my * my + c1);
    assert!((m.ssim - expected).abs() < 1e-9, "ssim {} vs {expected}", m.ssim);
}

#[test]
fn known_mse_with_sparse_errors() {
    // 4x2 grey image; pixel (1,0) R off by 0.5, pixel (3,1) G and B off by 0.25.
    // Sum of squares = 0.25 + 2 * 0.0625 = 0.375 over 8 * 3 = 24 samples.
    let r = constant(4, 2, 0.25, 1.0);
    let mut a = r.clone();
    a.set(1, 0, [0.75, 0.25, 0.25, 1.0]);
    a.set(3, 1, [0.25, 0.0, 0.5, 1.0]);
    assert_eq!(metrics::mse(&r, &a), 0.375 / 24.0);
    assert!((metrics::psnr(&r, &a) - 10.0 * 64f64.log10()).abs() < 1e-12);
    assert!((metrics::psnr_with_peak(&r, &a, 2.0) - 10.0 * 256f64.log10()).abs() < 1e-12);
    assert_eq!(metrics::max_abs(&r, &a), 0.5);
    assert_eq!(metrics::bad_pixels(&r, &a), 2);
    // Symmetric.
    assert_eq!(metrics::mse(&a, &r), metrics::mse(&r, &a));
}

#[test]
fn bad_pixel_threshold_and_nan_count() {
    let r = constant(8, 8, 0.5, 1.0);
    let mut a = r.clone();
    let step = 1.0 / 255.0;
    a.set(0, 0, [0.5 + 0.5 * step, 0.5, 0.5, 1.0]); // below threshold: fine
    a.set(1, 0, [0.5 + 2.0 * step, 0.5, 0.5, 1.0]); // bad (R)
    a.set(2, 0, [0.5, 0.5, 0.5, 1.0 - 2.0 * step]); // alpha only: fine
    a.set(3, 0, [0.5, 0.5, 0.5 - 1.5 * step, 1.0]); // bad (B)
    a.set(4, 5, [0.5, f32::NAN, 0.5, 1.0]); // bad, non-finite
    a.set(6, 7, [0.5, 0.5, 0.5, f32::INFINITY]); // non-finite alpha: not bad
    let m = compare(&r, &a).unwrap();
    assert_eq!(m.bad_pixels, 3);
    assert_eq!(m.nan, 2);
    assert_eq!(m.max_abs, f64::INFINITY);
    assert_eq!(a.first_nonfinite(), Some((4, 5)));
}

#[test]
fn non_finite_values_do_not_poison_metrics() {
    let r = constant(16, 16, 0.5, 1.0);
    let mut a = r.clone();
    a.set(8, 8, [0.5, f32::NAN, 0.5, 1.0]);
    let m = compare(&r, &a).unwrap();
    // One sample counts as a full-scale error: MSE = 1 / (256 * 3).
    assert_eq!(m.mse, 1.0 / 768.0);
    assert!((m.psnr - 10.0 * 768f64.log10()).abs() < 1e-9);
    assert!(m.ssim.is_finite() && m.ssim < 1.0, "ssim {}", m.ssim);
    assert_eq!(m.nan, 1);

    // The same NaN in both images is not a difference (bitwise comparison).
    let m = compare(&a, &a.clone()).unwrap();
    assert_eq!(m.psnr, f64::INFINITY);
    assert_eq!(m.bad_pixels, 0);
    assert_eq!(m.nan, 1);
}

#[test]
fn hdr_psnr_uses_reference_peak() {
    let mut r = constant(16, 16, 1.0, 1.0);
    r.set(3, 3, [4.0, 2.0, 1.0, 1.0]);
    r.set(4, 4, [f32::INFINITY, 1.0, 1.0, 1.0]); // non-finite values are not a peak
    let mut a = r.clone();
    for p in &mut a.data {
        for c in &mut p[..3] {
            *c += 0.125;
        }
    }
    assert_eq!(metrics::hdr_peak(&r), 4.0);
    let hdr = compare_hdr(&r, &a).unwrap();
    let ldr = compare(&r, &a).unwrap();
    // inf + 0.125 == inf bitwise, so 767 of the 768 samples are off by 0.125.
    let mse = 767.0 * 0.015625 / 768.0;
    assert!((hdr.mse - mse).abs() < 1e-15, "{}", hdr.mse);
    assert!((hdr.psnr - 10.0 * (16.0 / mse).log10()).abs() < 1e-9);
    assert!((hdr.psnr - ldr.psnr - 10.0 * 16f64.log10()).abs() < 1e-9);
    assert_eq!(hdr.ssim, ldr.ssim);

    let black = Image::new(4, 4);
    assert_eq!(metrics::hdr_peak(&black), 1.0);
}

#[test]
fn size_mismatch_is_an_error() {
    let err = compare(&Image::new(16, 16), &Image::new(16, 8)).unwrap_err();
    assert!(matches!(err, ImageError::SizeMismatch { expected: (16, 16), actual: (16, 8) }));
    assert!(err.to_string().contains("expected 16x16, got 16x8"), "{err}");
    assert!(compare_hdr(&Image::new(2, 2), &Image::new(3, 2)).is_err());
}

#[test]
#[should_panic(expected = "size mismatch")]
fn bare_metric_functions_panic_on_size_mismatch() {
    metrics::mse(&Image::new(2, 2), &Image::new(2, 3));
}

#[test]
fn ssim_small_images_use_global_window() {
    let a = pattern(8, 6);
    assert!((metrics::ssim(&a, &a) - 1.0).abs() < 1e-12);
    let b = constant(8, 6, 0.5, 1.0);
    let s = metrics::ssim(&a, &b);
    assert!(s.is_finite() && s < 0.9, "{s}");
    // Wide but short (no valid 11x11 window) also falls back.
    let wide = pattern(40, 5);
    assert!(metrics::ssim(&wide, &constant(40, 5, 0.5, 1.0)).is_finite());
    // Empty images compare as identical.
    let m = compare(&Image::new(0, 0), &Image::new(0, 0)).unwrap();
    assert_eq!((m.mse, m.psnr, m.ssim), (0.0, f64::INFINITY, 1.0));
}

#[test]
fn ssim_drops_with_noise_and_is_symmetric() {
    let a = pattern(32, 24);
    let mut state = 12345u32;
    let b = Image::from_fn(32, 24, |x, y| {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let n = (state >> 8) as f32 / (1u32 << 24) as f32 - 0.5;
        let p = a.get(x, y);
        [p[0] + 0.1 * n, p[1], p[2], 1.0]
    });
    let s = metrics::ssim(&a, &b);
    assert!(s > 0.3 && s < 0.999, "{s}");
    assert!((s - metrics::ssim(&b, &a)).abs() < 1e-12);
}

#[test]
fn format_psnr_rounds_to_two_decimals() {
    assert_eq!(format_psnr(f64::INFINITY), "identical");
    assert_eq!(format_psnr(42.1349), "42.13 dB");
    assert_eq!(format_psnr(7.0), "7.00 dB");
}

#[test]
fn metrics_json_round_trip_keeps_infinity() {
    let m = Metrics { psnr: f64::INFINITY, ssim: 1.0, max_abs: 0.0, bad_pixels: 0, nan: 0, mse: 0.0, flip_mean: None };
    let json = serde_json::to_string(&m).unwrap();
    assert!(json.contains(r#""psnr":"inf""#), "{json}");
    let back: Metrics = serde_json::from_str(&json).unwrap();
    assert_eq!(back, m);

    let finite = Metrics { psnr: 31.5, ..m };
    let back: Metrics = serde_json::from_str(&serde_json::to_string(&finite).unwrap()).unwrap();
    assert_eq!(back, finite);

    // serde_json's own encoding of non-finite floats (null) is accepted as NaN.
    let from_null: Metrics =
        serde_json::from_str(r#"{"psnr":null,"ssim":1,"max_abs":"-inf","bad_pixels":0,"nan":0,"mse":0.0}"#).unwrap();
    assert!(from_null.psnr.is_nan());
    assert_eq!(from_null.max_abs, f64::NEG_INFINITY);
    assert!(
        serde_json::from_str::<Metrics>(r#"{"psnr":"lots","ssim":1,"max_abs":0,"bad_pixels":0,"nan":0,"mse":0}"#)
            .is_err()
    );
}

/// Not a correctness test: `cargo test -p vista-image -- --ignored --nocapture`.
#[test]
#[ignore]
fn ssim_1024_timing() {
    let a = pattern(1024, 1024);
    let b = Image::from_fn(1024, 1024, |x, y| {
        let p = a.get(x, y);
        [p[0] * 0.9, p[1], p[2] + 0.01, 1.0]
    });
    let t = std::time::Instant::now();
    let s = metrics::ssim(&a, &b);
    println!("ssim 1024x1024 = {s:.6} in {:?}", t.elapsed());
}

/// A golden held in 16 bits (`Image16`, read a row at a time) gives the
/// very metrics its `Image` does, every one bit for bit: where the render
/// differs (a NaN among the differences), where it has the same values,
/// and where the sizes differ.
#[test]
fn a_16_bit_golden_is_judged_as_its_image_is() {
    use vista_image::Image16;
    let (w, h) = (300u32, 70u32);
    let data: Vec<u16> = (0..w * h * 4).map(|i| ((i as u64 * 2654435761) % 65536) as u16).collect();
    let golden = Image16 { width: w, height: h, data };
    let as_image = golden.to_image();
    let mut actual = Image::from_fn(w, h, |x, y| {
        let g = as_image.get(x, y);
        [g[0] * 0.9 + 0.05, g[1], (g[2] + (x % 7) as f32 / 100.0).min(1.0), g[3]]
    });
    actual.set(3, 4, [f32::NAN, 0.5, 0.5, 1.0]);
    let bits = |m: metrics::Metrics| {
        [m.psnr, m.ssim, m.max_abs, m.mse, m.flip_mean.unwrap()]
            .map(f64::to_bits)
            .to_vec()
            .into_iter()
            .chain([m.bad_pixels, m.nan])
            .collect::<Vec<u64>>()
    };
    let m16 = metrics::compare(&golden, &actual).unwrap();
    let m32 = metrics::compare(&as_image, &actual).unwrap();
    assert!(m16.psnr.is_finite() && m16.psnr < 40.0 && m16.bad_pixels > 0 && m16.nan == 1, "{m16:?}");
    assert_eq!(bits(m16), bits(m32));
    let same = metrics::compare(&golden, &as_image).unwrap();
    assert_eq!((same.psnr, same.ssim, same.flip_mean), (f64::INFINITY, 1.0, Some(0.0)));
    assert!(metrics::compare(&golden, &constant(w, h + 1, 0.5, 1.0)).is_err());
}
