//! FLIP beside PSNR: NVIDIA's LDR-FLIP through the nv-flip crate.

use vista_image::Image;
use vista_image::metrics::{compare, compare_hdr, flip_mean};

fn grey(w: u32, h: u32, v: f32) -> Image {
    Image::from_fn(w, h, |_, _| [v, v, v, 1.0])
}

#[test]
fn identical_images_have_zero_flip() {
    let a = Image::from_fn(64, 48, |x, y| [x as f32 / 63.0, y as f32 / 47.0, 0.5, 1.0]);
    assert_eq!(flip_mean(&a, &a.clone()), 0.0);
    assert_eq!(compare(&a, &a).unwrap().flip_mean, Some(0.0));
}

#[test]
fn black_against_white_is_near_the_maximum_and_flip_grows_with_the_difference() {
    let black = grey(32, 32, 0.0);
    let white = grey(32, 32, 1.0);
    let full = flip_mean(&black, &white);
    assert!(full > 0.9 && full <= 1.0, "black vs white: {full}");
    let small = flip_mean(&grey(32, 32, 0.5), &grey(32, 32, 0.52));
    let larger = flip_mean(&grey(32, 32, 0.5), &grey(32, 32, 0.6));
    assert!(0.0 < small && small < larger && larger < full, "{small} {larger} {full}");
}

#[test]
fn one_changed_pixel_gives_a_small_local_error() {
    let a = grey(64, 64, 0.5);
    let mut b = a.clone();
    b.set(10, 10, [1.0, 1.0, 1.0, 1.0]);
    let f = flip_mean(&a, &b);
    // The error spreads over a few pixels around the change, never the image.
    assert!(f > 0.0 && f < 0.01, "{f}");
}

#[test]
fn hdr_comparisons_carry_no_flip_and_json_omits_it() {
    let a = grey(8, 8, 2.0);
    let m = compare_hdr(&a, &a).unwrap();
    assert_eq!(m.flip_mean, None);
    assert!(!serde_json::to_string(&m).unwrap().contains("flip_mean"));
    let j = serde_json::to_string(&compare(&grey(8, 8, 0.5), &grey(8, 8, 0.5)).unwrap()).unwrap();
    assert!(j.contains("\"flip_mean\":0.0"), "{j}");
}
