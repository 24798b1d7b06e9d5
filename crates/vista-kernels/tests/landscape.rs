//! landscape (issue 16): CPU-only checks of the composed f64 reference.

use vista_kernels::heightfield::HitSearch;
use vista_kernels::landscape::{Landscape, LandscapeKernel};
use vista_kernels::{ParamError, ParamSet};

fn params(preset: &str, set: &[(&str, &str)]) -> ParamSet {
    let set: Vec<(String, String)> = set.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    LandscapeKernel.resolve(Some(preset), &set).expect("valid test params")
}

fn rejected(set: &[(&str, &str)]) -> String {
    let set: Vec<(String, String)> = set.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    match LandscapeKernel.resolve(Some("seed"), &set) {
        Err(e @ (ParamError::Invalid(_) | ParamError::OutOfRange { .. })) => e.to_string(),
        other => panic!("{set:?} must be refused, got {other:?}"),
    }
}

#[test]
fn bad_parameters_are_rejected_naming_the_value_and_what_is_allowed() {
    let e = rejected(&[("camera_pos", "0,-0.5,0")]);
    assert!(e.contains("camera_pos y = -0.5") && e.contains("[0, 100]"), "{e}");
    let e = rejected(&[("cloud_base_km", "3"), ("cloud_top_km", "2")]);
    assert!(e.contains("cloud_top_km=2") && e.contains("cloud_base_km=3"), "{e}");
    let e = rejected(&[("cloud_steps", "0")]);
    assert!(e.contains("cloud_steps=0") && e.contains("[1, 4096]"), "{e}");
    let e = rejected(&[("pitch_deg", "90")]);
    assert!(e.contains("pitch_deg=90"), "{e}");
}

/// The flythrough's camera is inside the slab, so every cloud segment starts
/// at the camera, and a ray that leaves into the sky (with the air off, so
/// only the clouds and the surface remain) carries exactly the clouds
/// reference's march from the camera, lit by the unattenuated sun.
#[test]
fn with_the_camera_inside_the_layer_the_clouds_start_at_the_camera() {
    let p = params("flythrough", &[("rayleigh_density", "0"), ("mie_density", "0")]);
    let l = Landscape::from_params(&p);
    let (w, h) = (32, 18);
    let (mut sky, mut lit) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let (o, d) = l.ray(x, y, w, h);
            assert!(o[1] > l.clouds.base && o[1] < l.clouds.top, "the flythrough camera must be inside the slab");
            let (t0, _) = l.clouds.layer_segment(o, d).expect("inside the slab every ray has a segment");
            assert_eq!(t0, 0.0, "pixel ({x}, {y}): the cloud segment starts at {t0}, not at the camera");
            if d[1] <= 0.0 {
                continue; // toward the terrain
            }
            let px = l.pixel(x, y, w, h, HitSearch::BruteForce);
            let (t0, t1) = l.clouds.layer_segment(o, d).unwrap();
            let sun = [l.sun_intensity; 3];
            let m = l.clouds.march_segment(o, d, t0, t1, l.clouds.jitter_offset(x, y), sun, false);
            for (c, (a, b)) in px.iter().zip(&m.radiance).enumerate() {
                assert!((a - b).abs() <= 1e-12 * b.max(1.0), "pixel ({x}, {y}) ch {c}: {a} vs {b}");
            }
            sky += 1;
            lit += (m.radiance[1] > 0.0) as u32;
        }
    }
    assert!(sky >= 100 && lit * 2 >= sky, "{sky} upward rays, {lit} with cloud light");
}
