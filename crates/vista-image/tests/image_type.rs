//! The `Image` type: construction, access, non-finite detection, hashing.

use vista_image::{Image, ImageError};

#[test]
fn new_is_all_zero_and_sized() {
    let img = Image::new(3, 2);
    assert_eq!((img.width, img.height), (3, 2));
    assert_eq!(img.data, vec![[0.0; 4]; 6]);
}

#[test]
fn from_fn_is_row_major_with_y0_on_top() {
    let img = Image::from_fn(3, 2, |x, y| [x as f32, y as f32, 0.0, 1.0]);
    assert_eq!(img.data[0], [0.0, 0.0, 0.0, 1.0]);
    assert_eq!(img.data[2], [2.0, 0.0, 0.0, 1.0]);
    assert_eq!(img.data[3], [0.0, 1.0, 0.0, 1.0]);
    assert_eq!(img.get(2, 1), [2.0, 1.0, 0.0, 1.0]);
}

#[test]
fn set_then_get() {
    let mut img = Image::new(4, 4);
    img.set(3, 1, [0.1, 0.2, 0.3, 0.4]);
    assert_eq!(img.get(3, 1), [0.1, 0.2, 0.3, 0.4]);
    assert_eq!(img.data[4 + 3], [0.1, 0.2, 0.3, 0.4]);
    assert_eq!(img.data.iter().filter(|p| **p != [0.0; 4]).count(), 1);
}

#[test]
#[should_panic(expected = "outside the 4x4 image")]
fn get_out_of_bounds_panics_with_message() {
    Image::new(4, 4).get(4, 0);
}

#[test]
fn from_raw_checks_length() {
    assert!(Image::from_raw(2, 2, vec![[0.0; 4]; 4]).is_ok());
    let err = Image::from_raw(2, 3, vec![[0.0; 4]; 5]).unwrap_err();
    assert!(matches!(err, ImageError::BadDimensions { width: 2, height: 3, expected: 6, len: 5 }));
    let msg = err.to_string();
    assert!(msg.contains("2x3") && msg.contains('6') && msg.contains('5'), "{msg}");
}

#[test]
fn nonfinite_detection_counts_any_channel() {
    let mut img = Image::from_fn(5, 4, |_, _| [0.5; 4]);
    assert_eq!(img.first_nonfinite(), None);
    assert_eq!(img.nonfinite_count(), 0);

    img.set(3, 2, [0.0, f32::INFINITY, 0.0, 1.0]);
    img.set(1, 3, [f32::NAN, f32::NAN, 0.0, 1.0]); // two bad channels, one pixel
    img.set(4, 3, [0.0, 0.0, 0.0, f32::NEG_INFINITY]); // alpha counts too
    assert_eq!(img.first_nonfinite(), Some((3, 2)));
    assert_eq!(img.nonfinite_count(), 3);

    img.set(0, 1, [0.0, 0.0, f32::NAN, 0.0]);
    assert_eq!(img.first_nonfinite(), Some((0, 1)));
    assert_eq!(img.nonfinite_count(), 4);
}

#[test]
fn content_hash_is_stable_fnv1a() {
    // Reference values from an independent Python FNV-1a 64 over
    // width, height and f32 bits, all little-endian.
    let data = vec![[0.0, 0.5, 1.0, -0.0], [1.5, -2.0, 0.25, 1.0]];
    let a = Image::from_raw(2, 1, data.clone()).unwrap();
    let b = Image::from_raw(1, 2, data).unwrap();
    assert_eq!(a.content_hash(), "e8a3efd471f046a4");
    assert_eq!(b.content_hash(), "f121cb0443269d54");
    assert_eq!(Image::new(0, 0).content_hash(), "a8c7f832281a39c5");
}

/// The bytes the worker sends over its pipe: each f32's little-endian
/// bits, RGBA, row after row; back into the same bits (NaN payloads and
/// -0.0 included), and refused at any other length.
#[test]
fn le_bytes_round_trip_bit_for_bit() {
    let nan = f32::from_bits(0x7fc0_1234);
    let a = Image::from_raw(2, 1, vec![[0.0, 0.5, 1.0, -0.0], [nan, -2.0, f32::INFINITY, 1.0]]).unwrap();
    let bytes = a.le_bytes().into_owned();
    assert_eq!(&bytes[4..8], &0.5f32.to_le_bytes());
    assert_eq!(&bytes[16..20], &0x7fc0_1234u32.to_le_bytes());
    let b = Image::from_le_bytes(2, 1, &bytes).unwrap();
    assert!(a.bit_identical(&b));
    assert!(Image::from_le_bytes(2, 2, &bytes).is_none());
    assert!(Image::from_le_bytes(1, 1, &bytes[..15]).is_none());
}

#[test]
fn content_hash_sees_bit_level_changes() {
    let a = Image::from_fn(8, 8, |x, y| [x as f32 / 8.0, y as f32 / 8.0, 0.0, 1.0]);
    let mut b = a.clone();
    assert_eq!(a.content_hash(), b.content_hash());
    b.set(7, 7, [0.875, f32::from_bits(0.875f32.to_bits() + 1), 0.0, 1.0]);
    assert_ne!(a.content_hash(), b.content_hash());
    let mut c = a.clone();
    c.set(0, 0, [-0.0, 0.0, 0.0, 1.0]);
    assert_ne!(a.content_hash(), c.content_hash());
}

#[test]
fn bit_identical_is_nan_safe_and_bitwise() {
    let a = Image::from_fn(3, 3, |x, _| [f32::NAN, x as f32, 0.0, 1.0]);
    let b = a.clone();
    assert!(a.bit_identical(&b));
    assert_ne!(a, b); // PartialEq follows IEEE, NaN != NaN

    let mut c = a.clone();
    c.set(1, 1, [f32::NAN, 1.0, 0.0, 0.5]);
    assert!(!a.bit_identical(&c));

    let zero = Image::new(1, 1);
    let mut neg_zero = Image::new(1, 1);
    neg_zero.set(0, 0, [-0.0, 0.0, 0.0, 0.0]);
    assert!(!zero.bit_identical(&neg_zero));
    assert!(!Image::new(2, 3).bit_identical(&Image::new(3, 2)));
}

#[test]
fn crop_takes_the_rectangle_and_refuses_what_does_not_fit() {
    let img = Image::from_fn(8, 4, |x, y| [x as f32, y as f32, 0.0, 1.0]);
    let c = img.crop(2, 1, 3, 2).unwrap();
    assert_eq!(c.dimensions(), (3, 2));
    assert_eq!(c.get(0, 0), img.get(2, 1));
    assert_eq!(c.get(2, 1), img.get(4, 2));
    assert!(img.crop(6, 0, 3, 1).is_none() && img.crop(0, 0, 0, 1).is_none() && img.crop(u32::MAX, 0, 2, 1).is_none());
    let z = c.zoom(2);
    assert_eq!(z.dimensions(), (6, 4));
    assert_eq!(z.get(5, 3), c.get(2, 1));
}

/// Pixel noise (a checkerboard) blurs away; a step (a band edge) stays.
#[test]
fn box_blur_removes_pixel_noise_and_keeps_steps() {
    let noise = Image::from_fn(16, 16, |x, y| [((x + y) % 2) as f32; 4]);
    let b = noise.box_blur(1);
    let inner = b.get(8, 8)[0];
    assert!((inner - 4.0 / 9.0).abs() < 1e-6 || (inner - 5.0 / 9.0).abs() < 1e-6, "{inner}");
    let step = Image::from_fn(16, 16, |x, _| [if x < 8 { 0.0 } else { 1.0 }; 4]);
    let s = step.box_blur(1);
    assert_eq!((s.get(2, 5)[0], s.get(13, 5)[0]), (0.0, 1.0));
    assert!((s.get(7, 5)[0] - 1.0 / 3.0).abs() < 1e-6);
    // Edge windows are clipped, not zero-padded.
    assert_eq!(s.get(15, 0)[0], 1.0);
}

/// A thumbnail fits the edge on its longer side, keeps the aspect (sides
/// rounded up), and each texel is the mean of its block (a partial block
/// at the edge included); an image that fits is returned whole.
#[test]
fn thumbnails_average_blocks_and_fit_the_edge() {
    let img = Image::from_fn(10, 4, |x, y| [x as f32, y as f32, 1.0, 1.0]);
    let t = img.thumbnail(4);
    assert_eq!((t.width, t.height), (4, 2), "factor 3: 10 -> 4, 4 -> 2");
    assert_eq!(t.get(0, 0), [1.0, 1.0, 1.0, 1.0], "x 0..3, y 0..3");
    assert_eq!(t.get(3, 1), [9.0, 3.0, 1.0, 1.0], "the last column alone, the last row alone");
    assert!(img.thumbnail(10).bit_identical(&img));
    let wide = Image::new(1920, 1080).thumbnail(128);
    assert_eq!((wide.width, wide.height), (128, 72));
}
