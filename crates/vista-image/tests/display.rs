//! Tone mapping, sRGB encoding and diff heat maps.

use approx::assert_abs_diff_eq;
use vista_image::{Image, diff_heatmap, srgb_encode, tonemap};

const GREEN: [f32; 4] = [0.0, 1.0, 0.0, 1.0];

#[test]
fn srgb_encode_endpoints_and_known_values() {
    assert_eq!(srgb_encode(0.0), 0.0);
    assert_eq!(srgb_encode(1.0), 1.0);
    assert_abs_diff_eq!(srgb_encode(0.001), 0.01292, epsilon = 1e-7); // linear toe
    assert_abs_diff_eq!(srgb_encode(0.5), 0.735_356_6, epsilon = 1e-6);
    assert_abs_diff_eq!(srgb_encode(0.18), 0.461_356_1, epsilon = 1e-6);
    // The two branches meet at the threshold.
    let t = 0.003_130_8f32;
    assert_abs_diff_eq!(srgb_encode(t), 12.92 * t, epsilon = 1e-6);
    // Out-of-range input is clamped.
    assert_eq!(srgb_encode(-1.0), 0.0);
    assert_eq!(srgb_encode(f32::NAN), 0.0);
    assert_eq!(srgb_encode(5.0), 1.0);
}

#[test]
fn tonemap_zero_is_black_and_alpha_is_copied() {
    let img = Image::from_fn(2, 1, |x, _| [0.0, 0.0, 0.0, x as f32 * 0.25]);
    let out = tonemap(&img, 1.0);
    assert_eq!(out.data, vec![[0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.25]]);
}

#[test]
fn tonemap_is_strictly_increasing_and_below_one() {
    let n = 161;
    let img = Image::from_fn(n, 1, |x, _| {
        let l = x as f32 * 0.05; // 0 ..= 8
        [l, l, l, 1.0]
    });
    let out = tonemap(&img, 1.0);
    for w in out.data.windows(2) {
        assert!(w[1][0] > w[0][0], "not increasing: {:?} -> {:?}", w[0], w[1]);
    }
    assert!(out.data.iter().all(|p| p[0] < 1.0 && p[0] >= 0.0));
    // Hand-computed: L = 1 -> 1 - e^-1 = 0.632121 -> 1.055 * 0.632121^(1/2.4) - 0.055.
    assert_abs_diff_eq!(out.get(20, 0)[0], 0.816_470, epsilon = 1e-6);
}

#[test]
fn tonemap_exposure_scales_luminance_and_clamps_bad_input() {
    let img = Image::from_fn(4, 1, |x, _| [x as f32 * 0.5, -2.0, f32::NAN, f32::NAN]);
    let a = tonemap(&img, 2.0);
    let b = tonemap(&Image::from_fn(4, 1, |x, _| [x as f32, 0.0, 0.0, 0.0]), 1.0);
    for x in 0..4 {
        assert_abs_diff_eq!(a.get(x, 0)[0], b.get(x, 0)[0], epsilon = 1e-6);
        assert_eq!(a.get(x, 0)[1], 0.0); // negative -> 0
        assert_eq!(a.get(x, 0)[2], 0.0); // NaN -> 0
        assert!(a.get(x, 0)[3].is_nan()); // alpha copied untouched
    }
    let inf = tonemap(&Image::from_fn(1, 1, |_, _| [f32::INFINITY, 0.0, 0.0, 1.0]), 1.0);
    assert_eq!(inf.get(0, 0)[0], 1.0);
    let dark = tonemap(&Image::from_fn(1, 1, |_, _| [3.0, 3.0, 3.0, 1.0]), -1.0);
    assert_eq!(dark.get(0, 0)[..3], [0.0, 0.0, 0.0]);
}

#[test]
fn heatmap_of_identical_images_is_black_and_opaque() {
    let a = Image::from_fn(5, 4, |x, y| [x as f32, y as f32, 0.5, 0.0]);
    let h = diff_heatmap(&a, &a, None);
    assert_eq!(h.dimensions(), (5, 4));
    assert!(h.data.iter().all(|p| *p == [0.0, 0.0, 0.0, 1.0]));
}

#[test]
fn heatmap_scales_to_max_diff_by_default() {
    let r = Image::new(4, 4);
    let mut a = r.clone();
    a.set(1, 1, [0.0, 0.5, 0.0, 0.0]); // the maximum -> white
    a.set(2, 2, [0.0, 0.0, 0.25, 0.0]); // half of it -> magenta
    a.set(3, 3, [0.0, 0.0, 0.0, 0.9]); // alpha only -> no difference
    let h = diff_heatmap(&r, &a, None);
    assert_eq!(h.get(1, 1), [1.0, 1.0, 1.0, 1.0]);
    assert_eq!(h.get(2, 2), [1.0, 0.0, 1.0, 1.0]);
    assert_eq!(h.get(3, 3), [0.0, 0.0, 0.0, 1.0]);
    assert_eq!(h.get(0, 0), [0.0, 0.0, 0.0, 1.0]);
}

#[test]
fn heatmap_explicit_and_minimum_scale() {
    let r = Image::new(2, 1);
    let mut a = r.clone();
    a.set(0, 0, [0.25, 0.0, 0.0, 1.0]);
    // With scale 1, a 0.25 diff is a quarter of the way: pure blue.
    assert_eq!(diff_heatmap(&r, &a, Some(1.0)).get(0, 0), [0.0, 0.0, 1.0, 1.0]);
    // Invalid scales fall back to the default (max diff -> white).
    assert_eq!(diff_heatmap(&r, &a, Some(0.0)).get(0, 0), [1.0; 4]);
    assert_eq!(diff_heatmap(&r, &a, Some(f32::NAN)).get(0, 0), [1.0; 4]);

    // A tiny diff is not stretched to white: the default scale is >= 1/255.
    let mut tiny = r.clone();
    tiny.set(1, 0, [1e-4, 0.0, 0.0, 0.0]);
    let p = diff_heatmap(&r, &tiny, None).get(1, 0);
    assert!(p[2] > 0.0 && p[2] < 0.2 && p[0] == 0.0, "{p:?}");
}

#[test]
fn heatmap_marks_non_finite_and_missing_pixels_green() {
    let r = Image::from_fn(3, 3, |_, _| [0.5; 4]);
    let mut a = r.clone();
    a.set(0, 0, [f32::NAN, 0.5, 0.5, 1.0]);
    a.set(1, 0, [0.5, f32::INFINITY, 0.5, 1.0]);
    let h = diff_heatmap(&r, &a, None);
    assert_eq!(h.get(0, 0), GREEN);
    assert_eq!(h.get(1, 0), GREEN);
    assert_eq!(h.get(2, 2), [0.0, 0.0, 0.0, 1.0]);

    let small = Image::from_fn(2, 3, |_, _| [0.5; 4]);
    let h = diff_heatmap(&r, &small, None);
    assert_eq!(h.dimensions(), (3, 3));
    assert_eq!(h.get(2, 1), GREEN);
    assert_eq!(h.get(1, 1), [0.0, 0.0, 0.0, 1.0]);
}
