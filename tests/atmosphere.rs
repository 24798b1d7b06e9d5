//! GPU checks of the atmosphere kernel (SPEC 3.5, SPEC 9): WGSL against the
//! f64 CPU reference (same settings and converged), sky invariants on the
//! rendered images, finiteness over the whole sun/altitude range, EXR round
//! trip (the uniform layout is checked for every kernel in tests/shaders.rs).

mod common;

use vista_image::Image;
use vista_image::metrics::{hdr_peak, psnr_with_peak};
use vista_kernels::ParamSet;
use vista_kernels::atmosphere::AtmosphereKernel;

const K: AtmosphereKernel = AtmosphereKernel;

fn params(preset: Option<&str>, set: &[(&str, String)]) -> ParamSet {
    let o: Vec<(String, String)> = set.iter().map(|(k, v)| (k.to_string(), v.clone())).collect();
    K.resolve(preset, &o).unwrap_or_else(|e| panic!("{e}"))
}

fn gpu(ctx: &vista_render::Renderer, p: &ParamSet, w: u32, h: u32) -> Image {
    vista_render::render(ctx, &K, p, w, h).unwrap_or_else(|e| panic!("render failed: {e}")).into_raw()
}

fn samples(view: u32, light: u32) -> [(&'static str, String); 2] {
    [("view_samples", view.to_string()), ("light_samples", light.to_string())]
}

/// GPU at 256 x 64 steps against the converged CPU reference. The reference
/// runs at 512 x 128: on 64 x 32 images it is within 96-138 dB (peak = max)
/// of the CPU at 1024 x 256 for every preset, far beyond the 45 dB asked
/// here, at a quarter of the cost (1024 x 256 takes ~1.5 s per preset).
fn gpu_high_quality_matches_converged_cpu(ctx: &vista_render::Renderer) {
    let (w, h) = (32, 16);
    // afternoon is noon's geometry at another sun angle; left out for time.
    for preset in ["noon", "sunset", "twilight", "high_altitude"] {
        let reference = K.reference(&params(Some(preset), &samples(512, 128)), w, h);
        let actual = gpu(ctx, &params(Some(preset), &samples(256, 64)), w, h);
        let psnr = psnr_with_peak(&reference, &actual, hdr_peak(&reference));
        eprintln!("{preset}: GPU 256x64 vs CPU 512x128 {psnr:.2} dB (peak {:.3})", hdr_peak(&reference));
        assert!(psnr >= 45.0, "{preset}: GPU 256x64 vs converged CPU {psnr:.2} dB < 45");
    }
}

fn mean_rgb(img: &Image, rows: std::ops::Range<u32>) -> [f64; 3] {
    let mut s = [0.0; 3];
    for y in rows.clone() {
        for x in 0..img.width {
            let p = img.get(x, y);
            (0..3).for_each(|k| s[k] += p[k] as f64);
        }
    }
    s.map(|v| v / (img.width * rows.len() as u32) as f64)
}

fn gpu_sky_invariants(ctx: &vista_render::Renderer) {
    let (w, h) = (64, 32);
    let render = |preset: &str| gpu(ctx, &params(Some(preset), &[]), w, h);
    let (noon, afternoon, sunset, twilight) =
        (render("noon"), render("afternoon"), render("sunset"), render("twilight"));

    for (name, img) in [("noon", &noon), ("afternoon", &afternoon), ("sunset", &sunset), ("twilight", &twilight)] {
        // L >= 0 and finite.
        assert!(
            img.data.iter().all(|p| p[..3].iter().all(|c| c.is_finite() && *c >= 0.0)),
            "{name}: negative or non-finite L"
        );
        // Mirror symmetry about the sun's azimuth: u -> 1 - u maps pixel x to
        // W - 1 - x exactly; f32 sin(2 pi u) vs sin(2 pi (1 - u)) differ slightly.
        let peak = hdr_peak(img) as f32;
        for y in 0..h {
            for x in 0..w / 2 {
                let (a, b) = (img.get(x, y), img.get(w - 1 - x, y));
                for k in 0..3 {
                    let tol = 1e-4 * a[k].abs() + 1e-6 * peak;
                    assert!((a[k] - b[k]).abs() <= tol, "{name}: ({x},{y}) {a:?} vs mirror {b:?}");
                }
            }
        }
    }

    // Zenith (top row) bluer than the horizon (bottom row) at noon.
    let (top, bottom) = (mean_rgb(&noon, 0..1), mean_rgb(&noon, h - 1..h));
    let (bz, bh) = (top[2] / top[0], bottom[2] / bottom[0]);
    eprintln!("noon B/R: zenith {bz:.3}, horizon {bh:.3}");
    assert!(bz > 1.5 * bh, "noon zenith B/R {bz} vs horizon {bh}");

    // Horizon toward the sun (columns 0 and W-1, bottom row): redder at sunset.
    let toward_sun = |img: &Image| {
        let (a, b) = (img.get(0, h - 1), img.get(w - 1, h - 1));
        [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]) as f64)
    };
    let (s, n) = (toward_sun(&sunset), toward_sun(&noon));
    eprintln!("horizon toward the sun: sunset {s:.4?} (R/B {:.2}), noon {n:.4?} (R/B {:.2})", s[0] / s[2], n[0] / n[2]);
    assert!(s[0] > s[1] && s[1] > s[2], "sunset horizon toward the sun must be R > G > B: {s:?}");
    assert!(s[0] / s[2] > 5.0 * (n[0] / n[2]), "sunset R/B {} vs noon {}", s[0] / s[2], n[0] / n[2]);

    // Zenith at sun 45 deg: B > G > R.
    let z = mean_rgb(&gpu(ctx, &params(None, &[("sun_elevation_deg", "45".into())]), w, h), 0..1);
    assert!(z[2] > z[1] && z[1] > z[0], "zenith at sun 45 deg: {z:?}");

    // Radiance peaks toward the sun: in every row (elevation) the brightest
    // column is one of the two next to azimuth 0. (The image maximum itself
    // is on the horizon below the sun, where the path is longest.)
    for (name, img) in [("noon", &noon), ("afternoon", &afternoon), ("sunset", &sunset)] {
        for y in 0..h {
            let sum = |x: u32| img.get(x, y)[..3].iter().sum::<f32>();
            let brightest = (0..w).max_by(|&a, &b| sum(a).total_cmp(&sum(b))).unwrap();
            assert!(brightest == 0 || brightest == w - 1, "{name}: row {y} peaks at column {brightest}");
        }
    }

    // Earth shadow: the sun 4 deg below the horizon dims the sky > 10x
    // against the sun on the horizon.
    let mean = |img: &Image| mean_rgb(img, 0..h).iter().sum::<f64>();
    let horizon_sun = gpu(ctx, &params(None, &[("sun_elevation_deg", "0".into())]), w, h);
    let ratio = mean(&horizon_sun) / mean(&twilight);
    eprintln!("Earth shadow: mean L at sun 0 deg / sun -4 deg = {ratio:.1}");
    assert!(ratio >= 10.0, "sun -4 deg only {ratio:.2}x darker than sun 0 deg");
}

/// Finite, non-negative and within `output_bounds` over the whole range of
/// sun elevations and camera altitudes (and the extreme mie_g), tiny images.
fn gpu_finite_over_the_parameter_grid(ctx: &vista_render::Renderer) {
    let suns = [-10.0, -6.0, -2.0, -0.01, 0.0, 0.01, 1.0, 5.0, 20.0, 45.0, 75.0, 89.99, 90.0];
    let alts = [0.0, 0.5, 10.0, 1000.0, 8000.0, 30_000.0, 59_990.0, 60_000.0, 60_010.0, 100_000.0];
    for sun in suns {
        for alt in alts {
            for (g, proj) in [(0.8, "latlong"), (0.99, "fisheye"), (-0.99, "latlong")] {
                let p = params(
                    None,
                    &[
                        ("sun_elevation_deg", sun.to_string()),
                        ("camera_altitude_m", alt.to_string()),
                        ("mie_g", g.to_string()),
                        ("projection", proj.into()),
                        ("view_samples", "12".into()),
                        ("light_samples", "3".into()),
                    ],
                );
                let (lo, hi) = K.output_bounds(&p);
                let img = gpu(ctx, &p, 8, 8);
                for px in &img.data {
                    for &c in &px[..3] {
                        assert!(
                            c.is_finite() && c >= lo && c <= hi,
                            "sun {sun} alt {alt} g {g} {proj}: L = {c} not in [{lo}, {hi}]"
                        );
                    }
                    assert_eq!(px[3], 1.0);
                }
                if alt >= 60_000.0 {
                    // At or above the top, upward rays meet no air.
                    assert!(img.data.iter().all(|p| p[..3] == [0.0; 3]), "alt {alt}: upward rays miss the atmosphere");
                } else if sun >= 0.0 && alt < 60_000.0 {
                    assert!(img.data.iter().any(|p| p[2] > 0.0), "sun {sun} alt {alt}: sky is black");
                }
            }
        }
    }
    // Fewest steps possible.
    let p = params(Some("sunset"), &samples(1, 1));
    assert!(gpu(ctx, &p, 8, 4).data.iter().all(|px| px.iter().all(|c| c.is_finite())));
}

fn exr_round_trip_is_bit_identical(ctx: &vista_render::Renderer) {
    let raw = gpu(ctx, &params(Some("sunset"), &[]), 32, 16);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sunset.exr");
    vista_image::save(&path, &raw).unwrap();
    let back = vista_image::load(&path).unwrap();
    assert!(back.bit_identical(&raw), "EXR round trip changed the radiance");
    assert!(raw.data.iter().any(|p| p[0] > 1.0), "the sunset render should hold HDR values above 1");
}

fn main() {
    common::gpu_tests![
        gpu_high_quality_matches_converged_cpu,
        gpu_sky_invariants,
        gpu_finite_over_the_parameter_grid,
        exr_round_trip_is_bit_identical,
    ];
}
