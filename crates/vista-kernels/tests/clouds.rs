//! clouds (SPEC 3.6): CPU-only invariants of the f64 reference march.

use vista_kernels::clouds::{
    Clouds, CloudsKernel, Profile, T_CUTOFF, analytic_weight, height_profile, ign, remap, white,
};
use vista_kernels::{ParamError, ParamSet};

fn params(preset: &str, set: &[(&str, &str)]) -> ParamSet {
    let set: Vec<(String, String)> = set.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    CloudsKernel.resolve(Some(preset), &set).expect("valid test params")
}

const GENERA: &[&str] = &[
    "cumulus",
    "cumulonimbus",
    "nimbostratus",
    "stratocumulus",
    "stratus",
    "altocumulus",
    "altostratus",
    "cirrus",
    "cirrocumulus",
    "cirrostratus",
];

/// Every n-th pixel ray of a 64 x 64 view.
fn rays(c: &Clouds, every: u32) -> impl Iterator<Item = (u32, u32, [f64; 3], [f64; 3])> + '_ {
    (0..64).step_by(every as usize).flat_map(move |y| {
        (0..64).step_by(every as usize).map(move |x| {
            let (o, d) = c.ray(x, y, 64, 64);
            (x, y, o, d)
        })
    })
}

#[test]
fn transmittance_is_in_unit_interval_and_never_increases_along_a_ray() {
    let mut rays_checked = 0;
    let mut cloudy = 0;
    for preset in GENERA {
        for (integrator, jitter) in [("riemann", "none"), ("analytic", "ign"), ("analytic", "white")] {
            let c = Clouds::from_params(&params(preset, &[("integrator", integrator), ("jitter", jitter)]));
            for (x, y, o, d) in rays(&c, 7) {
                let r = c.march(o, d, c.jitter_offset(x, y), true);
                let mut prev = 1.0;
                for (k, &t) in r.trace.iter().enumerate() {
                    assert!((0.0..=1.0).contains(&t), "{preset} ({x},{y}) step {k}: T = {t}");
                    assert!(t <= prev, "{preset} ({x},{y}) step {k}: T rose from {prev} to {t}");
                    prev = t;
                }
                assert_eq!(r.transmittance, prev);
                rays_checked += 1;
                cloudy += (prev < 0.9) as u32;
            }
        }
    }
    // The check must have seen real cloud, not only empty rays.
    assert!(cloudy * 4 > rays_checked, "only {cloudy} of {rays_checked} rays met cloud");
}

#[test]
fn doubling_density_never_raises_transmittance_cpu() {
    for preset in GENERA {
        let d = params(preset, &[]).f64("density_scale");
        let mut lower = 0;
        // The preset's density and an eighth of it (dense presets are opaque
        // on every ray at full density, where T = 0 both times).
        for d1 in [d, d / 8.0] {
            let c1 = Clouds::from_params(&params(preset, &[("density_scale", &d1.to_string())]));
            let c2 = Clouds::from_params(&params(preset, &[("density_scale", &(2.0 * d1).to_string())]));
            for (x, y, o, dir) in rays(&c1, 5) {
                let xi = c1.jitter_offset(x, y);
                let (t1, t2) = (c1.march(o, dir, xi, false).transmittance, c2.march(o, dir, xi, false).transmittance);
                assert!(t2 <= t1, "{preset} ({x},{y}): T {t1} at density {d1}, {t2} at {}", 2.0 * d1);
                lower += (t2 < t1) as u32;
            }
        }
        assert!(lower > 0, "{preset}: doubling the density changed no ray");
    }
}

#[test]
fn zero_coverage_gives_exactly_the_background() {
    for preset in GENERA {
        let c = Clouds::from_params(&params(preset, &[("coverage", "0")]));
        for (x, y, _, d) in rays(&c, 3) {
            let px = c.pixel(x, y, 64, 64);
            let bg = c.background(d);
            assert_eq!(px, [bg[0], bg[1], bg[2], 0.0], "{preset} ({x},{y})");
        }
    }
}

/// Analytic integration is energy-conserving: with a constant in-scattered
/// radiance (ambient only, no height falloff, no absorption) each step adds
/// Lin (T_k - T_k+1), so L = Lin (1 - T) exactly for any density field.
/// Riemann sums T_k x_k >= T_k (1 - exp(-x_k)) and overshoots.
#[test]
fn analytic_integrator_conserves_energy_and_riemann_overshoots() {
    let flat = [("sun_intensity", "0"), ("ambient", "1,1,1"), ("ambient_bottom", "1"), ("steps", "16")];
    let ca = Clouds::from_params(&params("cumulus", &[&flat[..], &[("integrator", "analytic")]].concat()));
    let cr = Clouds::from_params(&params("cumulus", &[&flat[..], &[("integrator", "riemann")]].concat()));
    let mut worst_riemann: f64 = 0.0;
    for (x, y, o, d) in rays(&ca, 3) {
        let a = ca.march(o, d, 0.5, false);
        // The T cutoff drops at most T_CUTOFF of the remaining light.
        let err = (a.radiance[0] - (1.0 - a.transmittance)).abs();
        assert!(err <= T_CUTOFF + 1e-12, "({x},{y}): L = {} but 1 - T = {}", a.radiance[0], 1.0 - a.transmittance);
        let r = cr.march(o, d, 0.5, false);
        assert!(r.radiance[0] >= a.radiance[0] - 1e-12, "({x},{y}): riemann below analytic");
        worst_riemann = worst_riemann.max(r.radiance[0] - (1.0 - r.transmittance));
    }
    assert!(worst_riemann > 0.01, "riemann at 16 steps should overshoot L = 1 - T, max excess {worst_riemann}");
}

#[test]
fn analytic_weight_has_the_right_limit() {
    assert_eq!(analytic_weight(0.0), 1.0);
    assert!((analytic_weight(1e-12) - 1.0).abs() < 1e-12);
    assert!((analytic_weight(1e-4) - (1.0 - 0.5e-4 + 1e-8 / 6.0)).abs() < 1e-13);
    assert!((analytic_weight(2.0) - (1.0 - (-2.0f64).exp()) / 2.0).abs() < 1e-15);
    assert!(analytic_weight(1e6).is_finite() && analytic_weight(1e6) > 0.0);
}

#[test]
fn remap_and_height_profile() {
    assert_eq!(remap(0.75, 0.5, 1.0, 0.0, 1.0), 0.5);
    assert_eq!(remap(0.2, 0.4, 0.4, 0.0, 1.0), 0.0, "empty interval: step, no division by zero");
    assert_eq!(remap(0.6, 0.4, 0.4, 0.0, 1.0), 1.0);
    for profile in [Profile::Stratiform, Profile::Cumuliform, Profile::Anvil] {
        assert_eq!(height_profile(profile, 0.1, 0.4, 0.0), 0.0);
        assert_eq!(height_profile(profile, 0.1, 0.4, 1.0), 0.0);
        for i in 0..=100 {
            let v = height_profile(profile, 0.1, 0.4, i as f64 / 100.0);
            assert!((0.0..=1.0).contains(&v), "{profile:?} at {i}%: {v}");
        }
    }
    // Anvil: denser near the top than in the middle of the tower.
    assert!(height_profile(Profile::Anvil, 0.03, 0.12, 0.8) > height_profile(Profile::Anvil, 0.03, 0.12, 0.4));
}

#[test]
fn jitter_hashes() {
    // IGN (Jimenez 2014) by its formula.
    assert_eq!(ign(0, 0, 0), 0.0);
    let want = (52.9829189 * (0.06711056f64 * 3.0 + 0.00583715 * 5.0).fract()).fract();
    assert_eq!(ign(3, 5, 0), want);
    assert_ne!(ign(3, 5, 1), ign(3, 5, 0));
    assert_eq!(ign(3, 5, 64), ign(3, 5, 0), "the seed shift has period 64");
    let mut sum = 0.0;
    for y in 0..64 {
        for x in 0..64 {
            for v in [ign(x, y, 7), white(x, y, 7)] {
                assert!((0.0..1.0).contains(&v));
            }
            sum += white(x, y, 7);
        }
    }
    let mean = sum / 4096.0;
    assert!((mean - 0.5).abs() < 0.02, "white jitter mean {mean}");
    assert_ne!(white(3, 5, 1), white(3, 5, 2));
}

#[test]
fn bad_parameters_are_rejected_with_the_value_and_range() {
    let err = CloudsKernel.resolve(Some("cumulus"), &[("cloud_top_km".into(), "0.5".into())]).unwrap_err();
    assert!(matches!(&err, ParamError::Invalid(m) if m.contains("cloud_top_km=0.5") && m.contains("cloud_base_km=1")));
    let err = CloudsKernel.resolve(None, &[("steps".into(), "0".into())]).unwrap_err();
    assert!(matches!(&err, ParamError::OutOfRange { param, .. } if param == "steps"), "{err}");
    let err = CloudsKernel.resolve(None, &[("jitter".into(), "blue".into())]).unwrap_err();
    assert!(err.to_string().contains("none|white|ign"), "{err}");
    let err = CloudsKernel.resolve(Some("cumulonimbus"), &[("sun_elevation_deg".into(), "-5".into())]).unwrap_err();
    assert!(err.to_string().contains("sun_elevation_deg"), "{err}");
}

#[test]
fn presets_are_valid_and_state_their_altitudes() {
    let names: Vec<&str> = CloudsKernel.presets().iter().map(|p| p.name.as_str()).collect();
    for g in GENERA.iter().chain(&["clear"]) {
        assert!(names.contains(g), "missing preset {g}");
    }
    for preset in CloudsKernel.presets() {
        let p = params(&preset.name, &[]);
        if preset.name != "clear" {
            let (base, top) = (p.f64("cloud_base_km"), p.f64("cloud_top_km"));
            assert!(
                preset.doc.contains(&format!("base {base:.1} km")) && preset.doc.contains(&format!("top {top:.1} km")),
                "{}: doc '{}' must state base {base:.1} km and top {top:.1} km",
                preset.name,
                preset.doc
            );
        }
        let (lo, hi) = CloudsKernel.output_bounds(&p);
        assert!(lo == 0.0 && hi.is_finite() && hi > 0.0);
    }
    // Temperate-latitude levels: high 5-13 km, middle 2-7 km, low below 2 km.
    let level = |name: &str| {
        let p = params(name, &[]);
        (p.f64("cloud_base_km"), p.f64("cloud_top_km"))
    };
    for high in ["cirrus", "cirrocumulus", "cirrostratus"] {
        let (b, t) = level(high);
        assert!(b >= 5.0 && t <= 13.0, "{high}: {b}-{t} km");
    }
    for middle in ["altocumulus", "altostratus"] {
        let (b, _) = level(middle);
        assert!((2.0..7.0).contains(&b), "{middle}: base {b} km");
    }
    for low in ["stratocumulus", "stratus", "cumulus", "nimbostratus", "cumulonimbus"] {
        let (b, _) = level(low);
        assert!(b < 2.0, "{low}: base {b} km");
    }
    let (_, cb_top) = level("cumulonimbus");
    assert!((9.0..=12.0).contains(&cb_top), "cumulonimbus top {cb_top} km");
}

#[test]
fn work_estimate_and_high_quality() {
    let p = params("cumulus", &[]);
    let wpp = CloudsKernel.work_per_pixel(&p);
    assert_eq!(wpp, 64.0 * 13.0 * p.f64("octaves"));
    let hq: Vec<(&str, &str)> = CloudsKernel.high_quality();
    assert!(hq.contains(&("steps", "512")) && hq.contains(&("light_steps", "32")), "{hq:?}");
}

#[test]
fn output_stays_within_the_declared_bounds() {
    // Dense, thick, few steps: the case where riemann overshoots most.
    for integrator in ["riemann", "analytic"] {
        let p = params("cumulonimbus", &[("density_scale", "200"), ("steps", "4"), ("integrator", integrator)]);
        let (lo, hi) = CloudsKernel.output_bounds(&p);
        let img = CloudsKernel.reference(&p, 24, 24);
        for px in &img.data {
            for &v in &px[..3] {
                assert!(v.is_finite() && v >= lo && v <= hi, "{integrator}: {v} outside [{lo}, {hi}]");
            }
        }
    }
}

fn hq(preset: &str, set: &[(&str, &str)]) -> ParamSet {
    let mut all: Vec<(&str, &str)> = CloudsKernel.high_quality();
    all.extend_from_slice(set);
    params(preset, &all)
}

/// SPEC 7/8 seed experiment on `cumulus`: against the 512 x 32 reference,
/// analytic integration + IGN jitter at 32 x 6 steps must be at least as
/// close (PSNR, peak = reference max) as riemann without jitter at 64 x 12.
#[test]
fn seed_experiment_analytic_ign_at_half_the_steps_beats_riemann_64x12() {
    let (w, h) = (96, 96);
    let reference = CloudsKernel.reference(&hq("cumulus", &[]), w, h);
    let peak = vista_image::metrics::hdr_peak(&reference);
    let psnr = |set: &[(&str, &str)]| {
        let img = CloudsKernel.reference(&params("cumulus", set), w, h);
        vista_image::metrics::psnr_with_peak(&reference, &img, peak)
    };
    let base = psnr(&[("integrator", "riemann"), ("jitter", "none"), ("steps", "64"), ("light_steps", "12")]);
    let fast = psnr(&[("integrator", "analytic"), ("jitter", "ign"), ("steps", "32"), ("light_steps", "6")]);
    // The same two with uniform light steps (light_spread = 1).
    let base_u = psnr(&[("steps", "64"), ("light_steps", "12"), ("light_spread", "1")]);
    let fast_u = psnr(&[
        ("integrator", "analytic"),
        ("jitter", "ign"),
        ("steps", "32"),
        ("light_steps", "6"),
        ("light_spread", "1"),
    ]);
    eprintln!(
        "clouds seed experiment (cumulus {w}x{h}, reference 512x32 analytic): riemann/none 64x12 {base:.2} dB, \
         analytic/ign 32x6 {fast:.2} dB; with uniform light steps: {base_u:.2} dB vs {fast_u:.2} dB"
    );
    assert!(fast >= base, "analytic/ign 32x6 ({fast:.2} dB) is less close than riemann/none 64x12 ({base:.2} dB)");
    // Why light_spread defaults to 8: six uniform light steps cost ~5 dB.
    assert!(fast > fast_u + 2.0, "geometric light steps: {fast:.2} dB vs uniform {fast_u:.2} dB");
}

/// Geometric and uniform light steps converge to the same radiance.
#[test]
fn light_step_spacings_converge_to_the_same_image() {
    let a = CloudsKernel.reference(&hq("cumulus", &[("light_steps", "128"), ("light_spread", "1")]), 24, 24);
    let b = CloudsKernel.reference(&hq("cumulus", &[("light_steps", "128"), ("light_spread", "8")]), 24, 24);
    let p = vista_image::metrics::psnr_with_peak(&a, &b, vista_image::metrics::hdr_peak(&a));
    assert!(p > 55.0, "uniform vs geometric light steps at 128 steps: {p:.1} dB");
    for (n, spread) in [(1, 8.0), (6, 8.0), (12, 1.0), (32, 8.0), (256, 1.0001)] {
        let (first, growth) = vista_kernels::clouds::light_step_layout(n, spread);
        let total: f64 = (0..n).map(|i| first * growth.powi(i as i32)).sum();
        let last = first * growth.powi(n as i32 - 1);
        assert!((total - 1.0).abs() < 1e-12, "n {n} spread {spread}: steps sum to {total}");
        if n > 1 {
            assert!((last / first - spread).abs() < 1e-9 * spread, "n {n}: last/first = {}", last / first);
        }
    }
}

/// The primary-step options change where the samples sit, not what
/// they integrate: geometric steps (step_spread) and golden-ratio offsets
/// per step (jitter_steps) converge to the uniform march's image.
#[test]
fn primary_step_layouts_converge_to_the_same_image() {
    let uniform = CloudsKernel.reference(&hq("cumulus", &[]), 16, 16);
    let peak = vista_image::metrics::hdr_peak(&uniform);
    for set in [&[("step_spread", "4")][..], &[("jitter", "ign"), ("jitter_steps", "golden")][..]] {
        let other = CloudsKernel.reference(&hq("cumulus", set), 16, 16);
        let p = vista_image::metrics::psnr_with_peak(&uniform, &other, peak);
        eprintln!("{set:?} vs uniform steps at 512 steps: {p:.1} dB");
        assert!(p > 50.0, "{set:?} vs uniform steps at 512 steps: {p:.1} dB");
    }
    // At 32 steps each layout differs from the uniform march: the options do something.
    let coarse = CloudsKernel.reference(&hq("cumulus", &[("steps", "32")]), 16, 16);
    let spread = CloudsKernel.reference(&hq("cumulus", &[("steps", "32"), ("step_spread", "4")]), 16, 16);
    assert!(vista_image::metrics::max_abs(&coarse, &spread) > 1e-3, "step_spread 4 left the image unchanged");
}

/// SPEC 9: cost grows about as steps * (1 + light_steps). Every ray spends
/// at most that many density evaluations (work_per_pixel / octaves), and a
/// thin overcast layer, where no cutoff fires, spends exactly that.
#[test]
fn density_evaluations_follow_steps_times_one_plus_light_steps() {
    for (steps, light) in [(16u32, 4u32), (32, 8), (64, 12)] {
        let (s, l) = (steps.to_string(), light.to_string());
        let p = params(
            "altostratus",
            &[
                ("steps", &s),
                ("light_steps", &l),
                ("coverage", "1"),
                ("density_scale", "0.5"),
                ("profile_bottom", "0.01"),
                ("profile_top", "0.01"),
            ],
        );
        let c = Clouds::from_params(&p);
        let bound = steps * (1 + light);
        assert_eq!(CloudsKernel.work_per_pixel(&p), bound as f64 * p.f64("octaves"));
        let mut full = 0;
        let mut n = 0;
        for (x, y, o, d) in rays(&c, 8) {
            let r = c.march(o, d, 0.5, false);
            assert!(r.density_evals <= bound, "{steps}x{light} ({x},{y}): {} evaluations > {bound}", r.density_evals);
            full += (r.density_evals == bound) as u32;
            n += 1;
        }
        assert!(full * 10 >= n * 9, "{steps}x{light}: only {full} of {n} rays spent steps * (1 + light_steps)");
    }
}

/// Camera inside the layer (the flythrough preset): every ray's march starts
/// at the camera, not at the slab's boundary behind it, and its
/// transmittance is exp(-integral of sigma_t from the camera), which a fine
/// independent quadrature over [0, t1] confirms; the same integral taken
/// from the slab boundary behind the camera does not match.
#[test]
fn with_the_camera_inside_the_layer_the_march_starts_at_the_camera() {
    for layer in ["slab", "shell"] {
        march_starts_at_the_camera(layer);
    }
}

fn march_starts_at_the_camera(layer: &str) {
    let c =
        Clouds::from_params(&params("flythrough", &[("steps", "1024"), ("max_distance_km", "6"), ("layer", layer)]));
    let o = c.view.pos;
    assert!(o[1] > c.base && o[1] < c.top, "the flythrough camera must be inside the layer");
    let (mut checked, mut distinct) = (0, 0);
    for (x, y, o, d) in rays(&c, 8) {
        let (t0, t1) = c.layer_segment(o, d).expect("inside the layer every ray has a segment");
        assert_eq!(t0, 0.0, "{layer} pixel ({x}, {y}): the segment starts at {t0}, not at the camera");
        let r = c.march(o, d, 0.5, false);
        if r.transmittance <= T_CUTOFF {
            continue;
        }
        // Midpoint rule at 16x the march's resolution, from the camera.
        let tau = |from: f64, to: f64| {
            let n = 16 * 1024;
            let dt = (to - from) / n as f64;
            (0..n).map(|i| c.density([0, 1, 2].map(|k| o[k] + d[k] * (from + (i as f64 + 0.5) * dt)))).sum::<f64>() * dt
        };
        let from_camera = tau(0.0, t1);
        let t = r.transmittance;
        assert!(
            (t - (-from_camera).exp()).abs() <= 2e-3,
            "{layer} pixel ({x}, {y}): T = {t}, exp(-tau from the camera) = {}",
            (-from_camera).exp()
        );
        // The part of the line behind the camera, inside the layer.
        let back = c.layer_segment(o, d.map(|v| -v)).map_or(0.0, |(_, t)| t);
        let behind = tau(-back, 0.0);
        if behind > 0.05 {
            distinct += 1;
            assert!(
                (t - (-(from_camera + behind)).exp()).abs() > 1e-3,
                "{layer} pixel ({x}, {y}): the part behind the camera counted"
            );
        }
        checked += 1;
    }
    assert!(
        checked >= 20 && distinct >= 5,
        "{layer}: only {checked} rays checked, {distinct} with cloud behind the camera"
    );
}

/// The shell's planet: the atmosphere's ground radius (km).
const R: f64 = 6360.0;

/// A horizontal ray from a camera under the shell is tangent to the sphere
/// through the camera (the centre lies straight below it), so it enters the
/// layer and leaves it where the closed-form chords sqrt((R + h)^2 - (R +
/// a)^2) of the base and top spheres end.
#[test]
fn a_tangent_ray_crosses_the_shell_along_the_closed_form_chord() {
    for (a, base, top) in [(0.0, 1.0, 3.0), (1.5, 2.5, 4.5), (0.3, 8.0, 12.0)] {
        let (pos, base_s, top_s) = (format!("0.4,{a},-0.7"), base.to_string(), top.to_string());
        let at = |layer| {
            let set = [
                ("layer", layer),
                ("camera_pos", pos.as_str()),
                ("cloud_base_km", base_s.as_str()),
                ("cloud_top_km", top_s.as_str()),
                ("max_distance_km", "1000"),
            ];
            Clouds::from_params(&params("cumulus", &set))
        };
        let (c, slab) = (at("shell"), at("slab"));
        for az in [0.0f64, 1.0, 2.5] {
            let d = [az.sin(), 0.0, az.cos()];
            let (t0, t1) = c.layer_segment(c.view.pos, d).expect("a tangent ray reaches the shell");
            let chord = |h: f64| ((R + h) * (R + h) - (R + a) * (R + a)).sqrt();
            for (t, want, what) in [(t0, chord(base), "enters"), (t1, chord(top), "leaves")] {
                assert!(
                    (t - want).abs() <= 1e-9 * want,
                    "camera at {a} km, layer {base}-{top} km, azimuth {az}: the ray {what} at {t} km, chord {want} km"
                );
            }
            // The flat slab is never reached by a horizontal ray from under it.
            assert!(slab.layer_segment(slab.view.pos, d).is_none());
        }
    }
}

/// Near the zenith a shell whose base and top lie far below R is the slab.
/// From a camera at radius rho = R + a, a ray at zenith angle theta reaches
/// the height h' = h - a above the camera at s = h' / cos(theta) in the slab
/// and at t = sqrt((rho cos(theta) + s)^2 - s^2 sin^2(theta)) - rho
/// cos(theta) in the shell; since sqrt(X^2 - Y) >= X - Y / X,
/// 0 <= s - t <= s^2 sin^2(theta) / (rho cos(theta) + s), which is where the
/// two segments' ends must lie. The bound is about twice the true gap
/// (sqrt(X^2 - Y) ~ X - Y / 2X), so the test also sees it is no looser.
/// The altitude of a point at horizontal distance r from the axis likewise
/// exceeds its y by between 0 and r^2 / (2 (R + y)).
#[test]
fn near_the_zenith_a_thin_shell_agrees_with_the_slab_within_the_derived_bound() {
    for a in [0.0, 1.0] {
        let set = |layer: &str| {
            Clouds::from_params(&params(
                "cumulus",
                &[("layer", layer), ("camera_pos", &format!("2.0,{a},3.0")), ("max_distance_km", "1000")],
            ))
        };
        let (shell, slab) = (set("shell"), set("slab"));
        let o = shell.view.pos;
        for theta_deg in [0.0f64, 2.0, 5.0, 10.0, 20.0] {
            let th = theta_deg.to_radians();
            let d = [th.sin() * 0.6, th.cos(), th.sin() * 0.8];
            let (s0, s1) = slab.layer_segment(o, d).unwrap();
            let (t0, t1) = shell.layer_segment(o, d).unwrap();
            for (s, t) in [(s0, t0), (s1, t1)] {
                let bound = s * s * th.sin().powi(2) / ((R + a) * th.cos() + s);
                let gap = s - t;
                assert!(
                    gap >= -1e-9 && gap <= bound + 1e-9,
                    "a = {a} km, theta = {theta_deg} deg: slab {s} km, shell {t} km, gap {gap} outside [0, {bound}]"
                );
                if theta_deg >= 5.0 {
                    assert!(gap >= 0.4 * bound, "theta = {theta_deg}: gap {gap} far under the bound {bound}");
                }
            }
        }
        for r in [0.0f64, 1.0, 10.0, 50.0] {
            let y = 2.0;
            let p = [o[0] + 0.6 * r, y, o[2] + 0.8 * r];
            let rise = shell.altitude(p) - y;
            let bound = r * r / (2.0 * (R + y));
            assert!(rise >= -1e-12 && rise <= bound + 1e-12, "r = {r} km: altitude - y = {rise}, bound {bound}");
            assert_eq!(slab.altitude(p), y);
        }
    }
}

/// Seeds the okta calibration averages over, and the others the test below
/// checks: 16 and 12, doubled for altostratus, whose 7 x 13 km cells make a
/// single sky one of only a few draws (single seeds scatter from 0.30 to 0.62
/// at 4 oktas), so its means need twice the seeds to settle within 1/16.
fn okta_seeds(preset: &str, held_out: bool) -> std::ops::Range<u32> {
    let k = if preset == "altostratus" { 2 } else { 1 };
    if held_out { 16 * k..16 * k + 12 * k } else { 0..16 * k }
}
/// Sky directions per side of the okta grid (32 x 32 = 1024 rays).
const SKY_GRID: u32 = 32;

fn sky_cover_at(preset: &str, set: &[(&str, &str)], seed: u32) -> f64 {
    let mut s = set.to_vec();
    let seed = seed.to_string();
    s.push(("seed", &seed));
    Clouds::from_params(&params(preset, &s)).sky_cover(SKY_GRID)
}

/// Regenerates each preset's okta table (paste into kernels/clouds.toml):
/// for n = 1..8 the coverage at which the sky cover, averaged over the
/// calibration seeds (okta_seeds), is n / 8 (8: 31/32, inside the 1/16
/// band), by bisection. `cargo test -p vista-kernels --test clouds
/// calibrate_oktas --release -- --ignored --nocapture` (VISTA_CALIBRATE=genus
/// for one).
#[test]
#[ignore]
fn calibrate_oktas() {
    let only = std::env::var("VISTA_CALIBRATE").ok();
    for preset in GENERA.iter().filter(|g| only.as_deref().is_none_or(|o| o == **g)) {
        let seeds = okta_seeds(preset, false);
        let mean = |c: f64| {
            let c = format!("{c:.5}");
            seeds.clone().map(|s| sky_cover_at(preset, &[("coverage", &c)], s)).sum::<f64>() / seeds.len() as f64
        };
        let mut table = Vec::new();
        for n in 1..=8 {
            let target = if n == 8 { 31.0 / 32.0 } else { n as f64 / 8.0 };
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..18 {
                let mid = 0.5 * (lo + hi);
                if mean(mid) < target { lo = mid } else { hi = mid }
            }
            table.push(hi);
        }
        let f = |v: &[f64]| v.iter().map(|c| format!("{c:.4}")).collect::<Vec<_>>().join(", ");
        println!(
            "[preset.{preset}]\nokta_coverage_low = [{}]\nokta_coverage_high = [{}]",
            f(&table[..4]),
            f(&table[4..])
        );
    }
}

/// Where the 1/16 cannot hold, and why (measured; docs/guide.md "Cloud amount in
/// oktas"): (genus, oktas, allowed distance of the held-out mean from n / 8).
/// Cirrostratus is a veil of 0.25/km whose vertical optical depth is about
/// 0.09: even at full coverage its thinnest directions stay under tau = 0.1,
/// so it tops out at 0.86 of the sky (7 oktas), which 8 then gives.
const OKTA_LIMITS: [(&str, i32, f64); 1] = [("cirrostratus", 8, 0.15)];

/// coverage_oktas = n gives n / 8 of the sky directions (those that reach
/// the layer) an optical depth above 0.1, within 1/16, for every genus and
/// every n (but OKTA_LIMITS), averaged over seeds the calibration never
/// saw (okta_seeds). One seed's sky is one draw of the noise field, and a layer
/// with large cells shows only a few of them, so single seeds scatter more;
/// the worst single seed is printed.
#[test]
fn coverage_oktas_gives_that_fraction_of_the_sky_within_a_sixteenth() {
    let mut failures = Vec::new();
    for preset in GENERA {
        let (mut row, mut worst_seed) = (format!("{preset:14}"), 0.0f64);
        for n in 0..=8 {
            let n_text = n.to_string();
            let fr: Vec<f64> =
                okta_seeds(preset, true).map(|s| sky_cover_at(preset, &[("coverage_oktas", &n_text)], s)).collect();
            let mean = fr.iter().sum::<f64>() / fr.len() as f64;
            let target = n as f64 / 8.0;
            worst_seed = fr.iter().map(|f| (f - target).abs()).fold(worst_seed, f64::max);
            row += &format!(" {n}:{mean:.3}");
            let limit = OKTA_LIMITS.iter().find(|l| l.0 == *preset && l.1 == n).map_or(1.0 / 16.0, |l| l.2);
            if (mean - target).abs() > limit {
                failures.push(format!("{preset} {n} oktas: mean sky cover {mean:.3} over seeds {fr:.3?}"));
            }
        }
        eprintln!("{row} | worst single seed off by {worst_seed:.3}");
    }
    assert!(failures.is_empty(), "okta calibration misses its bound:\n{}", failures.join("\n"));
}

/// sky_cover stops each optical-depth sum once it passes the threshold; the
/// early answer must be the full sum's for every direction, cloudy or clear.
#[test]
fn the_early_optical_depth_test_agrees_with_the_full_sum() {
    let mut compared = [0usize; 2];
    for preset in ["cumulus", "stratus", "altostratus", "cirrostratus"] {
        let c = Clouds::from_params(&params(preset, &[]));
        for i in 0..12 {
            let sin_e = (i as f64 + 0.5) / 12.0;
            let cos_e = (1.0 - sin_e * sin_e).sqrt();
            for j in 0..24 {
                let az = std::f64::consts::TAU * (j as f64 + 0.5) / 24.0;
                let d = [cos_e * az.sin(), sin_e, cos_e * az.cos()];
                let full = c.optical_depth(c.view.pos, d, 96);
                for tau in [0.0, 0.1, 1.0, 5.0] {
                    let early = c.optical_depth_exceeds(c.view.pos, d, 96, tau);
                    assert_eq!(early, full > tau, "{preset} dir {d:?}: optical depth {full} against {tau}");
                    compared[early as usize] += 1;
                }
            }
        }
    }
    assert!(compared[0] > 100 && compared[1] > 100, "both answers must occur: {compared:?}");
}

/// step_km: a ray takes ceil(segment / step_km) steps, at most `steps`, and
/// spends at most that many times (1 + light_steps) density evaluations;
/// mean_work (what sweeps report as work) is that count averaged over the
/// image, and for cumulus at 0.14 km it is well under the fixed count.
#[test]
fn step_km_gives_each_ray_the_steps_its_segment_needs() {
    let c = Clouds::from_params(&params("cumulus", &[("steps", "128"), ("light_steps", "4"), ("step_km", "0.14")]));
    let (mut sum, mut n, mut capped, mut short) = (0.0, 0, 0, 0);
    for (x, y, o, d) in rays(&c, 4) {
        let (t0, t1) = c.layer_segment(o, d).expect("cumulus: every ray meets the slab");
        let steps = c.primary_steps(t0, t1);
        let expected = ((t1 - t0) / 0.14).ceil().min(128.0) as u32;
        assert_eq!(steps, expected, "({x},{y}): {steps} steps over {:.3} km", t1 - t0);
        let r = c.march(o, d, 0.5, false);
        assert!(r.density_evals <= steps * 5, "({x},{y}): {} evaluations > {steps} x 5", r.density_evals);
        capped += (steps == 128) as u32;
        short += (steps < 32) as u32;
        sum += steps as f64;
        n += 1;
    }
    assert!(short > 0 && capped == 0, "{short} rays under 32 steps, {capped} at the cap of 128");
    // Over every pixel of the 64 x 64 image, not the sampled rays above.
    let mean = c.mean_work(64, 64) / (5.0 * c.fbm.octaves as f64);
    assert!((mean - sum / n as f64).abs() < 2.0, "mean steps {mean:.2} vs {:.2} on the sampled rays", sum / n as f64);
    assert!(mean < 40.0, "cumulus at 0.14 km: {mean:.1} steps per ray on average");
    // Off (the default): every ray takes `steps`.
    let fixed = Clouds::from_params(&params("cumulus", &[("steps", "48"), ("light_steps", "4")]));
    assert_eq!(fixed.mean_work(64, 64), 48.0 * 5.0 * fixed.fbm.octaves as f64);
}
