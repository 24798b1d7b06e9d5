//! landscape (the seed's whole frame) on the GPU: the invariants that tie it to the
//! kernels it is composed of (its GPU-vs-CPU agreement is in agreement.rs).
//! Without air or clouds it is the heightfield kernel's shading under a
//! white sun; over flat ground it is the atmosphere kernel's sky; radiance is
//! finite and non-negative in every preset; clouds in front of the terrain
//! hide it.

mod common;

use vista_image::Image;
use vista_kernels::atmosphere::AtmosphereKernel;
use vista_kernels::heightfield::HeightfieldKernel;
use vista_kernels::landscape::LandscapeKernel;
use vista_kernels::{Kernel, ParamSet};
use vista_render::{Renderer, render};

fn params(preset: &str, set: &[(&str, &str)]) -> ParamSet {
    common::params(&LandscapeKernel, Some(preset), set)
}

fn gpu(ctx: &Renderer, k: &Kernel, p: &ParamSet, w: u32, h: u32) -> Image {
    render(ctx, k, p, w, h).unwrap_or_else(|e| panic!("{}: {e}", k.name())).into_raw()
}

/// The terrain settings both kernels share, as `--set` pairs.
const TERRAIN: [(&str, &str); 9] = [
    ("terrain", "ridged"),
    ("octaves", "8"),
    ("lacunarity", "2.07"),
    ("amplitude", "1.6"),
    ("scale", "0.3"),
    ("t_max", "25"),
    ("max_steps", "256"),
    ("snow_line", "1.2"),
    ("sun_azimuth_deg", "150"),
];

/// No air (both densities 0), no clouds (coverage 0), sun_intensity = pi
/// (the landscape's Lambert divides by pi) and the heightfield's ambient as
/// ground_ambient: every terrain pixel is the heightfield kernel's shading
/// with sun_color = white and no fog. The camera looks along +z (yaw 0,
/// pitch 0 = camera_target straight ahead), so both kernels trace the same
/// rays. The heightfield writes c^(1/2.2); the landscape writes c.
fn without_air_or_clouds_it_is_the_heightfield_shading_under_a_white_sun(ctx: &Renderer) {
    let (w, h) = (64, 40);
    let mut land: Vec<(&str, &str)> = TERRAIN.to_vec();
    land.extend([
        ("camera_pos", "7.3,2.4,4.1"),
        ("yaw_deg", "0"),
        ("pitch_deg", "0"),
        ("fov_deg", "55"),
        ("sun_elevation_deg", "30"),
        ("rayleigh_density", "0"),
        ("mie_density", "0"),
        ("coverage", "0"),
        ("sun_intensity", "3.141592653589793"),
        ("ground_ambient", "0.16,0.22,0.32"),
    ]);
    let mut hf: Vec<(&str, &str)> = TERRAIN.to_vec();
    hf.extend([
        ("camera_pos", "7.3,2.4,4.1"),
        ("camera_target", "7.3,2.4,14.1"),
        ("fov_deg", "55"),
        ("sun_elevation_deg", "30"),
        ("sun_color", "1,1,1"),
        ("visibility_km", "1000000000"),
    ]);
    let l = gpu(ctx, &LandscapeKernel, &params("seed", &land), w, h);
    let hp = common::params(&HeightfieldKernel, Some("default"), &hf);
    let hc = gpu(ctx, &HeightfieldKernel, &hp, w, h);
    let mut depth = hf.clone();
    depth.push(("view", "depth"));
    let hd = gpu(ctx, &HeightfieldKernel, &common::params(&HeightfieldKernel, Some("default"), &depth), w, h);
    let (mut terrain, mut worst) = (0, 0.0f32);
    for i in 0..l.data.len() {
        if hd.data[i][0] >= 1.0 {
            continue; // sky: the heightfield's is a fixed gradient
        }
        terrain += 1;
        for c in 0..3 {
            let a = l.data[i][c].max(0.0).powf(1.0 / 2.2);
            worst = worst.max((a - hc.data[i][c]).abs());
        }
    }
    eprintln!("landscape vs heightfield: {terrain} terrain pixels, max |difference| {worst:.2e}");
    assert!(terrain > (w * h / 4) as usize, "only {terrain} terrain pixels: the view misses the terrain");
    // Measured 3.3e-7 on lavapipe (the pow of the heightfield's encode);
    // 1e-5 leaves room for a driver contracting a multiply-add differently.
    assert!(worst <= 1e-5, "landscape without air or clouds differs from the heightfield shading by {worst:.2e}");
}

/// Flat ground (amplitude 0) under the camera, no clouds, latlong
/// projection: the upper hemisphere is the atmosphere kernel's sky seen from
/// 1000 camera_pos.y metres, for several sun elevations.
fn flat_ground_gives_the_atmosphere_kernels_sky_above_the_horizon(ctx: &Renderer) {
    let (w, h) = (64, 32);
    for (sun, preset) in [("30", "afternoon"), ("3", "sunset"), ("60", "noon")] {
        let land = params(
            "seed",
            &[
                ("projection", "latlong"),
                ("amplitude", "0"),
                ("coverage", "0"),
                ("camera_pos", "0,1,0"),
                ("sun_azimuth_deg", "0"),
                ("sun_elevation_deg", sun),
            ],
        );
        let atmo = common::params(
            &AtmosphereKernel,
            Some(preset),
            &[("sun_elevation_deg", sun), ("camera_altitude_m", "1000"), ("sun_intensity", "20"), ("mie_g", "0.8")],
        );
        let (l, a) = (gpu(ctx, &LandscapeKernel, &land, w, h), gpu(ctx, &AtmosphereKernel, &atmo, w, h));
        let mut worst = 0.0f32;
        for (pl, pa) in l.data.iter().zip(&a.data) {
            for c in 0..3 {
                worst = worst.max((pl[c] - pa[c]).abs() / pa[c].abs().max(1e-3));
            }
        }
        eprintln!("landscape vs atmosphere, sun {sun} deg: max relative difference {worst:.2e}");
        assert!(
            worst <= 1e-5,
            "sun {sun} deg: the landscape's flat-ground sky differs from the atmosphere kernel's by {worst:.2e}"
        );
    }
}

/// Every preset, and a sun low enough to be blocked by the ridges: every
/// raw value finite and >= 0.
fn radiance_is_finite_and_non_negative_in_every_preset(ctx: &Renderer) {
    let mut cases: Vec<(String, ParamSet)> =
        LandscapeKernel.presets().iter().map(|p| (p.name.to_string(), params(&p.name, &[]))).collect();
    cases.push(("seed, sun 1 deg".into(), params("seed", &[("sun_elevation_deg", "1")])));
    cases.push((
        "flythrough, analytic + ign".into(),
        params("flythrough", &[("cloud_integrator", "analytic"), ("cloud_jitter", "ign")]),
    ));
    for (name, p) in cases {
        let img = gpu(ctx, &LandscapeKernel, &p, 64, 36);
        let bad = img.data.iter().flat_map(|px| px.iter()).filter(|v| !v.is_finite() || **v < 0.0).count();
        assert_eq!(bad, 0, "landscape {name}: {bad} values are NaN, infinite or negative");
    }
}

/// A slab between the camera and the terrain, made ever denser, hides the
/// terrain: looking down from above the layer, the image loses the terrain's
/// detail (its variance across the frame falls) as the cloud optical depth
/// grows, and the flat-ground and ridged images converge.
fn clouds_in_front_hide_the_terrain(ctx: &Renderer) {
    let (w, h) = (48, 27);
    let view = [
        ("camera_pos", "0,5,0"),
        ("pitch_deg", "-50"),
        ("cloud_base_km", "2"),
        ("cloud_top_km", "4"),
        ("coverage", "1"),
        ("profile", "stratiform"),
    ];
    let mut spread = Vec::new();
    for density in ["0.01", "1", "50"] {
        let diff = |amplitude: &str| {
            let mut s = view.to_vec();
            s.extend([("density_scale", density), ("amplitude", amplitude)]);
            gpu(ctx, &LandscapeKernel, &params("seed", &s), w, h)
        };
        let (ridged, flat) = (diff("1.2"), diff("0"));
        let d =
            ridged.data.iter().zip(&flat.data).map(|(a, b)| (a[1] - b[1]).abs() as f64).sum::<f64>() / (w * h) as f64;
        eprintln!("density {density}/km: mean |ridged - flat| = {d:.3e}");
        spread.push(d);
    }
    assert!(
        spread[0] > 10.0 * spread[2] && spread[2] < 1e-3,
        "a dense slab in front does not hide the terrain: {spread:?}"
    );
}

fn main() {
    common::gpu_tests![
        without_air_or_clouds_it_is_the_heightfield_shading_under_a_white_sun,
        flat_ground_gives_the_atmosphere_kernels_sky_above_the_horizon,
        radiance_is_finite_and_non_negative_in_every_preset,
        clouds_in_front_hide_the_terrain,
    ];
}
