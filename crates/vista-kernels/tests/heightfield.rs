//! CPU-only checks of the heightfield kernel's f64 march, camera, shading
//! and fog (SPEC 3.4 and the heightfield line of SPEC 9). World unit: 1 km.

use vista_kernels::heightfield::*;
use vista_kernels::{ParamError, ParamSet, pixel_uv};

fn params(preset: &str, sets: &[(&str, &str)]) -> Result<ParamSet, ParamError> {
    let o: Vec<(String, String)> = sets.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    HeightfieldKernel.resolve(Some(preset), &o)
}

fn settings(relax: f64, eps: f64, t_max: f64, max_steps: u32) -> MarchSettings {
    MarchSettings { t_max, relax, eps, max_steps }
}

fn norm(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / l)
}

/// Unit direction with elevation `down_deg` below the horizon and azimuth `az_deg`.
fn dir(down_deg: f64, az_deg: f64) -> [f64; 3] {
    let (e, a) = (-down_deg.to_radians(), az_deg.to_radians());
    [e.cos() * a.sin(), e.sin(), e.cos() * a.cos()]
}

#[test]
fn flat_plane_hit_is_analytic() {
    let h0 = 0.3;
    let plane = Terrain::plane(h0, 0.0, 0.0);
    let o = [0.4, 1.5, -2.0];
    let s = settings(0.5, 1e-3, 200.0, 8192);
    let mut worst: f64 = 0.0;
    for down in [0.5, 1.0, 3.0, 10.0, 30.0, 60.0, 89.0] {
        for az in [0.0, 37.0, 145.0, 260.0] {
            let d = dir(down, az);
            let t_star = (o[1] - h0) / -d[1];
            let m = relax_march(&plane, o, d, &s);
            assert!(m.hit, "ray {down} deg down missed the plane (t* = {t_star})");
            let err = (m.t - t_star).abs();
            // SPEC 9: marched t within eps * t of t* = (o.y - h0) / (-d.y).
            assert!(err <= s.eps * t_star, "down {down} az {az}: t {} vs t* {t_star}", m.t);
            worst = worst.max(err / t_star);
            // The brute-force reference bisects to the same point.
            let b = brute_force_hit(&plane, o, d, s.t_max, 0.0, BRUTE_STEPS).expect("brute force hits");
            assert!((b - t_star).abs() <= 1e-9 * t_star, "brute {b} vs {t_star}");
        }
    }
    // D is linear along the ray, so interpolating the last two samples lands
    // on t* to rounding, far inside eps * t.
    assert!(worst < 1e-9, "worst relative error {worst:e}");
}

#[test]
fn inclined_plane_and_sine_match_bisection() {
    let ramp = Terrain::plane(0.1, 0.3, -0.2);
    let sine = Terrain::sine(0.4, 1.3); // L = 0.52, 1/sqrt(1 + L^2) = 0.887
    let o = [0.2, 1.6, 0.1];
    let s = settings(0.5, 1e-3, 60.0, 20000);
    for (name, terrain) in [("ramp", &ramp), ("sine", &sine)] {
        let (mut n, mut grazed) = (0, 0);
        for down in [2.0, 5.0, 12.0, 25.0, 45.0, 70.0] {
            for az in (0..12).map(|i| i as f64 * 30.0 + 7.0) {
                let d = dir(down, az);
                let m = relax_march(terrain, o, d, &s);
                // Plain f64 bisection of the first crossing (40000 samples),
                // and the same under the march's footprint rule D < eps t.
                let plain = brute_force_hit(terrain, o, d, s.t_max, 0.0, 40000);
                let footprint = brute_force_hit(terrain, o, d, s.t_max, s.eps, 40000);
                assert_eq!(m.hit, footprint.is_some(), "{name}: down {down} az {az}: {m:?} vs {footprint:?}");
                let Some(tf) = footprint else { continue };
                let above = terrain.above(o, d, m.t);
                assert!(above.abs() <= s.eps * m.t, "{name}: |D| = {above} at t = {}", m.t);
                match plain {
                    Some(tb) if (tb - tf).abs() <= s.eps * tb => {
                        assert!((m.t - tb).abs() <= s.eps * tb, "{name}: march {} vs bisection {tb}", m.t);
                        n += 1;
                    }
                    // The ray passed a crest within eps t: the hit lies in
                    // that band, before any true crossing.
                    _ => {
                        assert!(m.t >= tf * (1.0 - 1e-9) && plain.is_none_or(|tb| m.t < tb), "{name}: {m:?}");
                        grazed += 1;
                    }
                }
            }
        }
        assert!(n >= 40, "{name}: only {n} rays hit");
        assert!(grazed <= 3, "{name}: {grazed} grazing footprint hits");
        if name == "ramp" {
            assert_eq!(grazed, 0, "a plane has no crests");
        }
    }
}

#[test]
fn relax_below_slope_bound_never_tunnels() {
    // Steep sine hills: L = amplitude * scale = 3, safe relax = 1/sqrt(10).
    let sine = Terrain::sine(0.5, 6.0);
    let l = 3.0_f64;
    let safe = 1.0 / (1.0 + l * l).sqrt();
    let o = [0.05, 0.56, 0.0];
    let (mut rays, mut tunnels_safe, mut tunnels_one) = (0, 0, 0);
    for down in [0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 12.0] {
        for az in (0..24).map(|i| i as f64 * 15.0 + 3.0) {
            let d = dir(down, az);
            let Some(first) = brute_force_hit(&sine, o, d, 8.0, 0.0, 200_000) else {
                continue;
            };
            rays += 1;
            let late = |m: March| !m.hit || m.t > first * (1.0 + 1e-6) + 1e-9;
            let m = relax_march(&sine, o, d, &settings(safe, 1e-4, 8.0, 200_000));
            // Stopping early (eps band) is allowed; passing the first crossing is not.
            if late(m) {
                tunnels_safe += 1;
            }
            if late(relax_march(&sine, o, d, &settings(1.0, 1e-4, 8.0, 200_000))) {
                tunnels_one += 1;
            }
        }
    }
    assert!(rays > 100, "only {rays} rays hit");
    assert_eq!(
        tunnels_safe, 0,
        "relax {safe:.3} <= 1/sqrt(1+L^2) passed the first crossing on {tunnels_safe}/{rays} rays"
    );
    // The bound is not idle: relax 1 on this terrain does pass ridges.
    assert!(tunnels_one > 0, "relax 1 never tunnelled on L = 3 hills ({rays} rays)");
    eprintln!("sine L=3: relax {safe:.3}: 0 tunnels; relax 1.0: {tunnels_one}/{rays} rays past the first crossing");
}

#[test]
fn ramp_normals_are_exact_and_normals_point_up() {
    for (s, r) in [(0.3, -0.2), (-1.5, 0.7), (0.0, 0.0), (4.0, 2.5)] {
        let ramp = Terrain::plane(0.2, s, r);
        let want = norm([-s, 1.0, -r]);
        for (x, z) in [(0.0, 0.0), (3.7, -12.1), (-250.0, 90.5)] {
            for delta in [1e-4, 1e-3, 0.05] {
                let n = ramp.normal(x, z, delta);
                let err = (0..3).map(|i| (n[i] - want[i]).abs()).fold(0.0, f64::max);
                assert!(err < 1e-9, "ramp ({s}, {r}) at ({x}, {z}) delta {delta}: {n:?} vs {want:?}");
            }
        }
    }
    // Normals of the noise terrains (and their shading path) always face up.
    for preset in ["valley", "ridges", "grazing"] {
        let scene = Scene::from_params(&params(preset, &[]).unwrap(), 64, 40).unwrap();
        for i in 0..400 {
            let (x, z) = (i as f64 * 0.137 - 20.0, (i * 7 % 400) as f64 * 0.091 - 15.0);
            let n = scene.terrain.normal(x, z, Terrain::normal_step(x, z, 1e-3, 1.0));
            assert!(n[1] > 0.0 && n.iter().all(|c| c.is_finite()), "{preset}: normal {n:?} at ({x}, {z})");
        }
    }
}

#[test]
fn fog_contrast_is_two_percent_at_visibility() {
    let c = [0.05, 0.3, 0.1];
    for v in [0.3, 0.6, 1.0, 3.0, 40.0] {
        let sigma = fog_extinction(v);
        let contrast = |t: f64| {
            let f = apply_fog(c, t, sigma);
            (0..3).map(|i| (f[i] - SKY_HORIZON[i]) / (c[i] - SKY_HORIZON[i])).collect::<Vec<_>>()
        };
        for k in contrast(0.0) {
            assert!((k - 1.0).abs() < 1e-12);
        }
        // Koschmieder: contrast 2% at the meteorological visibility.
        for k in contrast(v) {
            assert!((k - 0.02).abs() < 1e-5, "V = {v}: contrast at V is {k}");
        }
        assert!(contrast(0.5 * v)[0] > contrast(v)[0] && contrast(v)[0] > contrast(2.0 * v)[0]);
    }
    // Presets: fog below 1 km, mist in 1-5 km.
    let v = |p: &str| params(p, &[]).unwrap().f64("visibility_km");
    assert!(v("fog") < 1.0);
    assert!((1.0..=5.0).contains(&v("mist")));
}

#[test]
fn camera_follows_the_spec() {
    let cam = Camera::new([1.0, 2.0, 3.0], [4.0, 1.0, 7.0], 50.0, 1.6).unwrap();
    let f = norm([3.0, -1.0, 4.0]);
    let dotp = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-15);
    assert!(close(cam.forward, f), "{:?} vs {f:?}", cam.forward);
    // r = normalize(cross(f, (0,1,0))) = normalize(-f.z, 0, f.x); up = cross(r, f).
    let r = norm([-f[2], 0.0, f[0]]);
    assert!(close(cam.right, r), "{:?} vs {r:?}", cam.right);
    assert!(dotp(cam.up, cam.forward).abs() < 1e-15 && dotp(cam.up, cam.right).abs() < 1e-15);
    assert!((dotp(cam.up, cam.up) - 1.0).abs() < 1e-15 && cam.up[1] > 0.0);
    // The image centre looks along f; the top edge is fov/2 above it; the
    // right edge is atan(tan(fov/2) W/H) to the right (along +r).
    let centre = cam.ray(0.5, 0.5);
    assert!(dotp(centre, f) > 1.0 - 1e-15);
    let top = cam.ray(0.5, 0.0);
    assert!((dotp(top, f).acos() - 25f64.to_radians()).abs() < 1e-12 && dotp(top, cam.up) > 0.0);
    let right = cam.ray(1.0, 0.5);
    let want = (25f64.to_radians().tan() * 1.6).atan();
    assert!((dotp(right, f).acos() - want).abs() < 1e-12 && dotp(right, cam.right) > 0.0);
    // Pixel centres: pixel (0, 0) of a 4 x 2 image is at u = 1/8, v = 1/4.
    assert_eq!(pixel_uv(0, 0, 4, 2), (0.125, 0.25));
}

#[test]
fn check_rejects_bad_cameras_and_ranges() {
    let e = params("valley", &[("camera_target", "9,0.5,3")]).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("camera_target") && msg.contains("camera_pos"), "{msg}");
    let e = params("valley", &[("camera_target", "9,-4,3")]).unwrap_err();
    assert!(e.to_string().contains("vertical"), "{e}");
    for (k, v) in [
        ("relax", "0"),
        ("relax", "1.5"),
        ("eps", "0"),
        ("max_steps", "0"),
        ("fov_deg", "179"),
        ("visibility_km", "0.0005"),
    ] {
        match params("valley", &[(k, v)]) {
            Err(ParamError::OutOfRange { param, .. }) => assert_eq!(param, k),
            other => panic!("{k}={v}: expected OutOfRange, got {other:?}"),
        }
    }
    assert!(params("valley", &[("relax", "1")]).is_ok());
    assert!(params("valley", &[("view", "bogus")]).is_err());
}

/// Every ray of a preset at a small size through the f64 relax march.
fn march_preset(preset: &str, sets: &[(&str, &str)], w: u32, h: u32) -> (Scene, Vec<([f64; 3], March)>) {
    let scene = Scene::from_params(&params(preset, sets).unwrap(), w, h).unwrap();
    let rays = (0..w * h)
        .map(|i| {
            let (u, v) = pixel_uv(i % w, i / w, w, h);
            let d = scene.camera.ray(u, v);
            (d, relax_march(&scene.terrain, scene.camera.pos, d, &scene.march))
        })
        .collect();
    (scene, rays)
}

#[test]
fn f64_march_hits_satisfy_eps_and_survive_more_steps() {
    for preset in ["valley", "ridges", "grazing"] {
        let (scene, rays) = march_preset(preset, &[("max_steps", "64")], 40, 24);
        let mut more = scene.march;
        more.max_steps = 256;
        let o = scene.camera.pos;
        let (mut hits, mut hits_more) = (0, 0);
        for (d, m) in &rays {
            let m2 = relax_march(&scene.terrain, o, *d, &more);
            hits_more += m2.hit as u32;
            if m.hit {
                hits += 1;
                let above = scene.terrain.above(o, *d, m.t);
                assert!(above.abs() <= scene.march.eps * m.t, "{preset}: |D| = {above} > eps t at t = {}", m.t);
                assert!(m2.hit && m2.t == m.t, "{preset}: hit at {} lost with more steps ({m2:?})", m.t);
            }
        }
        assert!(hits > 100 && hits_more >= hits, "{preset}: {hits} hits at 64 steps, {hits_more} at 256");
    }
}

#[test]
fn reference_views_are_finite_and_consistent() {
    let (w, h) = (24, 16);
    for preset in ["valley", "grazing", "fog"] {
        let depth = HeightfieldKernel.reference(&params(preset, &[("view", "depth")]).unwrap(), w, h);
        let normal = HeightfieldKernel.reference(&params(preset, &[("view", "normal")]).unwrap(), w, h);
        let color = HeightfieldKernel.reference(&params(preset, &[]).unwrap(), w, h);
        let steps = HeightfieldKernel.reference(&params(preset, &[("view", "steps")]).unwrap(), w, h);
        let (mut sky, mut ground) = (0, 0);
        for i in 0..(w * h) as usize {
            for img in [&depth, &normal, &color, &steps] {
                let p = img.data[i];
                assert!(p.iter().all(|c| c.is_finite() && (0.0..=1.0).contains(c)), "{preset}: {p:?}");
                assert_eq!(p[3], 1.0);
            }
            for img in [&depth, &steps] {
                let p = img.data[i];
                assert!(p[0] == p[1] && p[1] == p[2], "{preset}: grey views need R = G = B: {p:?}");
            }
            if depth.data[i][0] == 1.0 {
                sky += 1;
                assert_eq!(normal.data[i], [0.0, 0.0, 0.0, 1.0]);
            } else {
                ground += 1;
                assert!(normal.data[i][1] > 0.5, "{preset}: hit normal faces down");
            }
        }
        assert!(sky > 0 && ground > 0, "{preset}: sky {sky}, ground {ground}");
    }
}

#[test]
fn work_estimate_counts_heights_times_octaves() {
    let p = params("valley", &[]).unwrap();
    let w = HeightfieldKernel.work_per_pixel(&p);
    assert_eq!(w, (256.0 + 32.0 + REFINE_ITERS as f64 + 5.0) * 8.0);
}
