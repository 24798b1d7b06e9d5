//! GPU against the f64 CPU reference, every kernel, with bounds set from the
//! measured agreement (README "GPU vs CPU bounds"), all four channels
//! compared. Then the proof that those bounds can fail: a 5% change of a
//! physical or shading constant in a temporary copy of the shaders, three
//! per kernel, must break at least one setting's bound; and dropping the
//! heightfield hit refinement must break its depth agreement.

mod common;

use vista_golden::{Agreement, agreement};
use vista_image::Image;
use vista_kernels::Kernel;
use vista_render::Renderer;

/// One compared setting: kernel, preset, overrides, size.
type Setting = (&'static str, &'static str, &'static [(&'static str, &'static str)], (u32, u32));

const SETTINGS: &[Setting] = &[
    ("fbm", "default", &[], (96, 64)),
    ("fbm", "rotated", &[("seed", "7")], (96, 64)),
    ("fbm", "value", &[("offset", "-12.5,7.25"), ("z_slice", "3.3")], (96, 64)),
    ("ridged", "default", &[], (96, 64)),
    ("ridged", "soft", &[("basis", "value"), ("seed", "11")], (96, 64)),
    ("cloudmap", "default", &[], (96, 64)),
    ("cloudmap", "perlin", &[("seed", "3")], (96, 64)),
    ("atmosphere", "afternoon", &[], (48, 24)),
    ("atmosphere", "sunset", &[], (48, 24)),
    ("atmosphere", "noon", &[("projection", "fisheye")], (32, 32)),
    ("clouds", "cumulus", &[], (48, 48)),
    ("clouds", "cumulus", &[("integrator", "analytic"), ("jitter", "ign")], (48, 48)),
    ("clouds", "cumulonimbus", &[("jitter", "white"), ("jitter_seed", "5")], (48, 48)),
    (
        "clouds",
        "cumulus",
        &[
            ("integrator", "analytic"),
            ("jitter", "ign"),
            ("step_spread", "2"),
            ("jitter_steps", "golden"),
            ("step_km", "0.1"),
        ],
        (48, 48),
    ),
    ("clouds", "cirrus", &[], (48, 48)),
    ("clouds", "flythrough", &[], (48, 48)),
    ("heightfield", "valley", &[], (48, 30)),
    ("heightfield", "ridges", &[], (48, 30)),
    ("heightfield", "fog", &[], (48, 30)),
    ("heightfield", "mist", &[], (48, 30)),
    ("landscape", "seed", &[], (48, 27)),
    ("landscape", "dawn", &[], (48, 27)),
    ("landscape", "flythrough", &[], (48, 27)),
    ("landscape", "overcast", &[], (48, 27)),
];

/// Bound of a kernel's GPU-vs-CPU agreement on a backend: (min PSNR dB,
/// max abs), a few dB under the worst measured there (README "GPU vs CPU
/// bounds"). lavapipe is the bless-time driver; SwiftShader's transcendental
/// functions are less precise (WGSL allows sin/cos 2^-11 absolute error),
/// which is the whole spread: fbm's rotated case, the sky and the clouds.
fn bound(kernel: &str, preset: &str, backend: &str) -> (f64, f64) {
    let lavapipe = backend == "lavapipe";
    match kernel {
        // Measured 67.8 dB, 5.1e-2 on SwiftShader: from inside the layer the
        // rays march up to 20 km through cloud, so its less precise exp
        // errors accumulate over more in-cloud samples than from below.
        "clouds" if preset == "flythrough" && !lavapipe => (65.0, 6e-2),
        "fbm" if lavapipe => (120.0, 1e-5),
        "fbm" => (65.0, 3e-3),
        "ridged" | "cloudmap" => (120.0, 1e-5),
        "atmosphere" if lavapipe => (120.0, 1e-4),
        "atmosphere" => (65.0, 5e-2),
        "clouds" if lavapipe => (110.0, 5e-4),
        "clouds" => (75.0, 1e-2),
        // Over the pixels whose hit agrees with the oracle's (see masked_by_hits).
        "heightfield" if lavapipe => (HEIGHTFIELD_PSNR, 2e-2),
        "heightfield" => (HEIGHTFIELD_PSNR, 2e-2),
        // The radiance given the GPU's own terrain hits (see with_gpu_hits).
        "landscape" if lavapipe => (90.0, 2e-2),
        // Measured 55.4 dB (seed, flythrough), 0.90 max abs (dawn, near the
        // sun's disc of Mie forward scattering) on SwiftShader: the sky's
        // and the clouds' exp differences above, carried onto the terrain.
        "landscape" => (52.0, 1.0),
        other => panic!("no bound for {other}"),
    }
}

const HEIGHTFIELD_PSNR: f64 = 65.0;

/// CPU images by what determines them (kernel, canonical params, size and,
/// for the landscape, the GPU hits it shades): a shader fault changes only
/// the GPU side, so the fault loop reuses the f64 references instead of
/// recomputing them per fault (the heightfield's brute-force march and the
/// landscape's are most of this suite's time).
fn cpu_cached(key: String, make: impl FnOnce() -> Image) -> Image {
    static CACHE: std::sync::OnceLock<std::sync::Mutex<std::collections::HashMap<String, Image>>> =
        std::sync::OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(img) = cache.lock().unwrap().get(&key) {
        return img.clone();
    }
    let img = make();
    cache.lock().unwrap().insert(key, img.clone());
    img
}

/// The f64 reference of `p`, computed once per process.
fn reference(k: &Kernel, p: &vista_kernels::ParamSet, w: u32, h: u32) -> Image {
    cpu_cached(format!("{} {} {w}x{h}", k.name(), p.canonical()), || k.reference(p, w, h))
}

fn render_pair(gpu: &Renderer, s: &Setting) -> (&'static Kernel, Image, Image) {
    let (name, preset, set, (w, h)) = *s;
    let k = vista_kernels::find(name).unwrap();
    let p = common::params(k, Some(preset), set);
    let mut g = vista_render::render(gpu, k, &p, w, h).unwrap_or_else(|e| panic!("{name} {preset}: {e}")).raw;
    if name == "landscape" {
        let c = with_gpu_hits(gpu, k, s, &p);
        return (k, g, c);
    }
    let mut c = reference(k, &p, w, h);
    if name == "heightfield" {
        masked_by_hits(gpu, k, s, &mut g, &mut c);
    }
    (k, g, c)
}

/// Share of pixels whose landscape terrain hit must agree with the oracle's
/// (within LANDSCAPE_DEPTH_TOL t); measured at 48 x 27 on lavapipe: seed,
/// dawn and overcast 96.5%, flythrough 93.7%.
const LANDSCAPE_HIT_PCT: f64 = 90.0;
const LANDSCAPE_DEPTH_TOL: f32 = 1e-3;

/// The landscape's f64 reference shading the GPU's own terrain hits
/// (decoded from its depth view), after checking that those hits agree with
/// the brute-force oracle's at LANDSCAPE_HIT_PCT of the pixels. So the
/// radiance bound judges shading and composition apart from the hit
/// search: 20 m ridges seen from 20 km alias, and a hit a few metres along
/// the ray can flip a soft shadow.
fn with_gpu_hits(gpu: &Renderer, k: &Kernel, s: &Setting, p: &vista_kernels::ParamSet) -> Image {
    let (_, preset, set, (w, h)) = *s;
    let mut depth_set: Vec<(&str, &str)> = set.iter().copied().filter(|(n, _)| *n != "view").collect();
    depth_set.push(("view", "depth"));
    let dp = common::params(k, Some(preset), &depth_set);
    let gd = vista_render::render(gpu, k, &dp, w, h).unwrap().raw;
    let cd = reference(k, &dp, w, h);
    let same = gd
        .data
        .iter()
        .zip(&cd.data)
        .filter(|(a, b)| (a[0] < 1.0) == (b[0] < 1.0) && (a[0] - b[0]).abs() <= LANDSCAPE_DEPTH_TOL * b[0])
        .count();
    let pct = 100.0 * same as f64 / gd.data.len() as f64;
    assert!(pct >= LANDSCAPE_HIT_PCT, "landscape {preset}: terrain hits agree at {pct:.1}% < {LANDSCAPE_HIT_PCT}%");
    let hits: Vec<u32> = gd.data.iter().map(|px| px[0].to_bits()).collect();
    let key = format!("landscape at GPU hits {} {w}x{h} {:x}", p.canonical(), {
        use std::hash::{Hash, Hasher};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        hits.hash(&mut hasher);
        hasher.finish()
    });
    cpu_cached(key, || {
        let scene = vista_kernels::landscape::Landscape::from_params(p);
        let t_max = p.f64("t_max");
        vista_kernels::render_cpu(w, h, |_, _, x, y| {
            let z = gd.get(x, y)[0] as f64;
            scene.pixel_with_hit(x, y, w, h, (z < 1.0).then_some(z * t_max))
        })
    })
}

/// Heightfield shading is compared where both sides found the same surface:
/// pixels whose hit differs from the brute-force oracle's (a crest taken on
/// its near or far side; the depth tests bound how many) are set equal.
fn masked_by_hits(gpu: &Renderer, k: &Kernel, s: &Setting, g: &mut Image, c: &mut Image) {
    let (_, preset, set, (w, h)) = *s;
    let mut depth_set: Vec<(&str, &str)> = set.iter().copied().filter(|(n, _)| *n != "view").collect();
    depth_set.push(("view", "depth"));
    let p = common::params(k, Some(preset), &depth_set);
    let gd = vista_render::render(gpu, k, &p, w, h).unwrap().raw;
    let cd = reference(k, &p, w, h);
    let mut differ = 0;
    for i in 0..g.data.len() {
        let (a, b) = (gd.data[i][0], cd.data[i][0]);
        if (a < 1.0) != (b < 1.0) || (a - b).abs() > DEPTH_TOL {
            g.data[i] = c.data[i];
            differ += 1;
        }
    }
    assert!(differ * 100 <= g.data.len() * 10, "heightfield {preset}: {differ} pixels hit elsewhere than the oracle");
}

/// One setting's agreement, and the figures when it breaks its bound.
fn judge(gpu: &Renderer, s: &Setting) -> (Agreement, Option<String>) {
    let (k, g, c) = render_pair(gpu, s);
    let a = agreement(k, &g, &c);
    let (min_psnr, max_abs) = bound(s.0, s.1, gpu.backend());
    let broken = (a.psnr < min_psnr || a.max_abs > max_abs)
        .then(|| format!("{} {} {:?}: {:.1} dB, max abs {:.2e}", s.0, s.1, s.2, a.psnr, a.max_abs));
    (a, broken)
}

/// The settings of `kernel` whose agreement breaks its bound, with figures.
fn violations(gpu: &Renderer, kernel: &str) -> Vec<String> {
    SETTINGS.iter().filter(|s| s.0 == kernel).filter_map(|s| judge(gpu, s).1).collect()
}

fn gpu_agrees_with_the_f64_reference_within_measured_bounds(gpu: &Renderer) {
    let mut failures = Vec::new();
    for s in SETTINGS {
        let (a, broken) = judge(gpu, s);
        let (min_psnr, max_abs) = bound(s.0, s.1, gpu.backend());
        // A README table row (`-- --nocapture`).
        eprintln!(
            "| {} | {} {:?} | {:.1} dB | {:.2e} | {min_psnr} dB / {max_abs:.0e} | {} |",
            s.0,
            s.1,
            s.2,
            a.psnr,
            a.max_abs,
            gpu.backend()
        );
        failures.extend(broken);
    }
    assert!(failures.is_empty(), "GPU vs CPU outside the bounds:\n{}", failures.join("\n"));
}

/// (kernel, shader file, exact text, the text with the constant x 1.05).
type Fault = (&'static str, &'static str, &'static str, &'static str);

const FAULTS: &[Fault] = &[
    ("fbm", "lib/noise.wgsl", "t * 6.0 - 15.0", "t * 6.3 - 15.0"),
    ("fbm", "lib/noise.wgsl", "t * 6.0 - 15.0) + 10.0", "t * 6.0 - 15.0) + 10.5"),
    ("fbm", "fbm.wgsl", "let value = 0.5 + 0.5 * f", "let value = 0.5 + 0.525 * f"),
    ("ridged", "lib/noise.wgsl", "- 15.0) + 10.0", "- 15.75) + 10.0"),
    (
        "ridged",
        "lib/fractal.wgsl",
        "let peak = max(s.offset, PERLIN_MAX_ABS - s.offset);",
        "let peak = 1.05 * max(s.offset, PERLIN_MAX_ABS - s.offset);",
    ),
    ("ridged", "lib/noise.wgsl", "return unit_from_hash(h.x) * 2.0 - 1.0;", "return unit_from_hash(h.x) * 2.1 - 1.0;"),
    ("cloudmap", "cloudmap.wgsl", "255.0 * max(", "267.75 * max("),
    ("cloudmap", "cloudmap.wgsl", "clamp(0.5 + 0.5 * f", "clamp(0.5 + 0.525 * f"),
    ("cloudmap", "lib/noise.wgsl", "t * 6.0 - 15.0", "t * 6.3 - 15.0"),
    ("atmosphere", "lib/sky.wgsl", "const H_R: f32 = 8000.0;", "const H_R: f32 = 8400.0;"),
    ("atmosphere", "lib/sky.wgsl", "const H_M: f32 = 1200.0;", "const H_M: f32 = 1260.0;"),
    ("atmosphere", "lib/sky.wgsl", "const BETA_M: f32 = 3.996e-6;", "const BETA_M: f32 = 4.1958e-6;"),
    ("clouds", "lib/cloud_slab.wgsl", "return plateau * (1.0 - 0.5 * h);", "return plateau * (1.0 - 0.525 * h);"),
    ("clouds", "lib/phase.wgsl", "(4.0 * PI * denom * sqrt(denom))", "(4.2 * PI * denom * sqrt(denom))"),
    // Issue 19's sampling options: geometric primary steps, golden-ratio
    // offsets, steps per ray from step_km.
    (
        "clouds",
        "lib/cloud_slab.wgsl",
        "end_frac = expm1(f32(k + 1u) * log_r)",
        "end_frac = expm1(f32(k + 1u) * 1.05 * log_r)",
    ),
    ("clouds", "lib/cloud_slab.wgsl", "xk = fract(xi + f32(k) * INV_PHI);", "xk = fract(xi + f32(k) * 0.6);"),
    ("clouds", "lib/cloud_slab.wgsl", "clamp(ceil((t1 - t0) / s.c.step_km)", "clamp(floor((t1 - t0) / s.c.step_km)"),
    (
        "clouds",
        "lib/cloud_slab.wgsl",
        "let g = 0.5 + 0.5 * sum * s.inv_amplitude;",
        "let g = 0.5 + 0.525 * sum * s.inv_amplitude;",
    ),
    ("landscape", "landscape.wgsl", "params.sun_intensity / PI", "params.sun_intensity / (1.05 * PI)"),
    ("landscape", "landscape.wgsl", "KM * 0.5 * (c0 + c1)", "KM * 0.525 * (c0 + c1)"),
    (
        "landscape",
        "landscape.wgsl",
        "let all = sky_segment(air, d, start, end);",
        "let all = sky_segment(air, d, start, 0.95 * end);",
    ),
    // Composition faults: fog in front of the clouds dropped; the terrain
    // behind them seen without its aerial perspective.
    ("landscape", "landscape.wgsl", "front.inscatter + front.transmittance * (", "front.inscatter + ("),
    ("landscape", "landscape.wgsl", "back.inscatter + back.transmittance * surface", "back.inscatter + surface"),
    (
        "heightfield",
        "lib/terrain.wgsl",
        "const GRASS = vec3(0.16, 0.26, 0.08);",
        "const GRASS = vec3(0.16, 0.273, 0.08);",
    ),
    ("heightfield", "heightfield.wgsl", "const KOSCHMIEDER: f32 = 3.912;", "const KOSCHMIEDER: f32 = 4.1076;"),
    (
        "heightfield",
        "heightfield.wgsl",
        "const AMBIENT = vec3(0.16, 0.22, 0.32);",
        "const AMBIENT = vec3(0.16, 0.231, 0.32);",
    ),
];

fn a_five_percent_constant_change_fails_an_agreement_bound(gpu: &Renderer<'static>) {
    let mut survived = Vec::new();
    for (kernel, file, from, to) in FAULTS {
        let (_dir, edited) = common::with_edit(gpu, file, from, to);
        let v = violations(&edited, kernel);
        eprintln!("fault {kernel} {file}: '{from}' -> '{to}': {} settings out of bounds {v:?}", v.len());
        if v.is_empty() {
            survived.push(format!("{kernel} {file}: '{from}' -> '{to}'"));
        }
    }
    assert!(survived.is_empty(), "5% constant changes the agreement bounds let through:\n{}", survived.join("\n"));
    for kernel in ["fbm", "ridged", "cloudmap", "atmosphere", "clouds", "heightfield", "landscape"] {
        assert!(FAULTS.iter().filter(|f| f.0 == kernel).count() >= 3, "{kernel}: fewer than 3 constants tried");
    }
}

/// A hit agrees with the oracle's when the depths (t / t_max) are within
/// 2e-5: 0.4 m at t_max = 20 km. The refinement brings most hits there; the
/// unrefined march stops up to eps t short (measured below).
const DEPTH_TOL: f32 = 2e-5;

/// Depth agreement with the brute-force oracle over the pixels where either
/// side hits (both-sky pixels, about half the frame, say nothing). Returns
/// (agreeing, total).
fn depth_agreement(gpu: &Renderer, preset: &str) -> (usize, usize) {
    let k = vista_kernels::find("heightfield").unwrap();
    let p = common::params(k, Some(preset), &[("view", "depth")]);
    let (w, h) = (64, 40);
    let g = vista_render::render(gpu, k, &p, w, h).unwrap().raw;
    let r = reference(k, &p, w, h);
    let either: Vec<(f32, f32)> =
        g.data.iter().zip(&r.data).map(|(a, b)| (a[0], b[0])).filter(|(a, b)| *a < 1.0 || *b < 1.0).collect();
    let ok = either.iter().filter(|(a, b)| *a < 1.0 && *b < 1.0 && (a - b).abs() <= DEPTH_TOL).count();
    (ok, either.len())
}

/// Share of either-hit pixels whose depth must agree, per preset. Measured
/// at 64 x 40 with refinement on lavapipe / SwiftShader: valley 95.9 /
/// 95.8%, ridges 92.5 / 92.3%, grazing 83.9 / 83.8%; without it 3.1%,
/// 10.8%, 48.2% (lavapipe).
const DEPTH_AGREEMENT_PCT: [(&str, f64); 3] = [("valley", 92.0), ("ridges", 89.0), ("grazing", 80.0)];

fn heightfield_depth_agrees_over_pixels_where_either_side_hits(gpu: &Renderer) {
    for (preset, min_pct) in DEPTH_AGREEMENT_PCT {
        let (ok, n) = depth_agreement(gpu, preset);
        let pct = 100.0 * ok as f64 / n as f64;
        eprintln!("heightfield {preset}: depth agrees at {ok}/{n} either-hit pixels ({pct:.2}%)");
        assert!(pct >= min_pct, "{preset}: {pct:.2}% < {min_pct}%");
    }
}

fn dropping_the_hit_refinement_fails_the_depth_agreement(gpu: &Renderer<'static>) {
    let refined = "return Hit(true, refine(s, m.eps, o, d, prev, vec2(t, dh)), k);";
    let (_dir, edited) = common::with_edit(gpu, "lib/terrain.wgsl", refined, "return Hit(true, t, k);");
    for (preset, min_pct) in DEPTH_AGREEMENT_PCT {
        let (ok, n) = depth_agreement(&edited, preset);
        let pct = 100.0 * ok as f64 / n as f64;
        eprintln!("heightfield {preset} without refinement: {pct:.2}% of either-hit pixels agree");
        assert!(pct < min_pct, "{preset}: without refinement the agreement still reaches {pct:.2}% >= {min_pct}%");
    }
}

fn main() {
    common::run_gpu_tests(&[
        (
            "gpu_agrees_with_the_f64_reference_within_measured_bounds",
            gpu_agrees_with_the_f64_reference_within_measured_bounds,
        ),
        (
            "a_five_percent_constant_change_fails_an_agreement_bound",
            a_five_percent_constant_change_fails_an_agreement_bound,
        ),
        (
            "heightfield_depth_agrees_over_pixels_where_either_side_hits",
            heightfield_depth_agrees_over_pixels_where_either_side_hits,
        ),
        (
            "dropping_the_hit_refinement_fails_the_depth_agreement",
            dropping_the_hit_refinement_fails_the_depth_agreement,
        ),
    ]);
}
