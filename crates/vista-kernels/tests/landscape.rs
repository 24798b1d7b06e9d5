//! landscape (the seed's whole frame): CPU-only checks of the composed f64 reference.

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

/// The clouds kernel's params that show the landscape's clouds as the
/// landscape sees them with its air off: every param of the clouds' `cloud`
/// group takes the landscape's value of the same leaf (each kernel's group
/// rule names it), the camera and jitter come along, the sun is white at
/// the landscape's intensity and the clouds kernel's background sky black.
fn clouds_seen_by(landscape: &ParamSet) -> ParamSet {
    let (clouds, land) = (vista_kernels::find("clouds").unwrap(), vista_kernels::find("landscape").unwrap());
    let (cg, lg) = (clouds.group("cloud").unwrap(), land.group("cloud").unwrap());
    let has = |n: &str| landscape.value(n).is_some();
    let mut set: Vec<(String, String)> = Vec::new();
    for spec in clouds.params() {
        // The leaf this clouds param feeds, if it feeds one of the group's.
        let leaf = spec.name.strip_prefix(cg.prefix.as_str()).unwrap_or(&spec.name);
        let leaf = cg.rename.iter().find(|(_, n)| n == leaf).map_or(leaf, |(l, _)| l.as_str());
        let fed_by = |n: &str| clouds.params().iter().any(|s| s.name == n);
        if cg.param(leaf, fed_by) != spec.name {
            continue;
        }
        let from = lg.param(leaf, has);
        if let Some(v) = landscape.value(&from) {
            set.push((spec.name.to_string(), v.to_string()));
        }
    }
    for (to, from) in [
        ("camera_pos", "camera_pos"),
        ("yaw_deg", "yaw_deg"),
        ("pitch_deg", "pitch_deg"),
        ("fov_deg", "fov_deg"),
        ("sun_azimuth_deg", "sun_azimuth_deg"),
        ("sun_elevation_deg", "sun_elevation_deg"),
        ("sun_intensity", "sun_intensity"),
        ("jitter", "cloud_jitter"),
        ("jitter_seed", "cloud_jitter_seed"),
    ] {
        set.push((to.to_string(), landscape.value(from).unwrap().to_string()));
    }
    for (k, v) in [("sun_color", "1,1,1"), ("sky_zenith", "0,0,0"), ("sky_horizon", "0,0,0"), ("coverage_oktas", "-1")]
    {
        set.push((k.to_string(), v.to_string()));
    }
    clouds.resolve(None, &set).expect("the landscape's clouds are valid clouds params")
}

/// The flythrough's camera is inside the slab, so every cloud segment starts
/// at the camera; and with the air off, every ray that leaves into the sky
/// shows exactly what the clouds kernel's own reference renders for the
/// landscape's clouds (params mapped leaf by leaf through the two kernels'
/// `cloud` groups): the landscape's composition adds nothing to an upward
/// ray but the unattenuated sun. (It replaced a test that compared
/// `pixel` with `march_segment`, which `pixel` calls.) Fails on a landscape
/// reference that dims the sun it gives its clouds by 3% or swaps the
/// jitter's pixel coordinates (both tried).
#[test]
fn with_the_air_off_upward_rays_show_the_clouds_kernels_clouds() {
    let set = [("rayleigh_density", "0"), ("mie_density", "0"), ("cloud_octaves", "3"), ("octaves", "7")];
    let set: Vec<(&str, &str)> =
        set.into_iter().chain([("cloud_jitter", "white"), ("cloud_step_spread", "3"), ("cloud_gain", "0.6")]).collect();
    let p = params("flythrough", &set);
    let l = Landscape::from_params(&p);
    let (w, h) = (32, 18);
    let landscape = LandscapeKernel.reference(&p, w, h);
    let clouds = vista_kernels::find("clouds").unwrap().reference(&clouds_seen_by(&p), w, h);
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
            let (a, b) = (landscape.get(x, y), clouds.get(x, y));
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= 1e-6 * b[c].max(1.0), "pixel ({x}, {y}) ch {c}: {} vs {}", a[c], b[c]);
            }
            sky += 1;
            lit += (b[1] > 0.0) as u32;
        }
    }
    assert!(sky >= 100 && lit * 2 >= sky, "{sky} upward rays, {lit} with cloud light");
}
