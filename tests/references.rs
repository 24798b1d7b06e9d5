//! Every example project checked against a reference written from the
//! math, not from its golden (SPEC 18): a change to vista's host layer
//! that moves a result is caught here even where `bless` and `check` agree
//! with each other. Each reference is computed in f64 (or exactly, for
//! integers) from the formula the example's shader documents; the WGSL is
//! not transliterated. Each allowance is an error bound from the formats
//! and f32 (an 8-bit or f16 store's rounding, carried through a chain of
//! passes where there is one), stated beside the check.

use std::path::{Path, PathBuf};

use common::allow_no_gpu;
use libtest_mimic::{Arguments, Trial};
use vista_render::OutputValue;

mod common;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples").join(name)
}

/// Renders `kernel` of example project `name` with its defaults at
/// `width` x `height` on this process's device.
fn render_example(name: &str, kernel: &str, width: u32, height: u32) -> Result<vista_render::Rendered, String> {
    render_example_with(name, kernel, &[], width, height)
}

fn npy_u32(path: &Path) -> Vec<u32> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let npy = vista_image::npy::decode_npy(path, &bytes).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(npy.descr, "<u4", "{}", path.display());
    npy.data.chunks_exact(4).map(|w| u32::from_le_bytes(w.try_into().expect("4 bytes"))).collect()
}

/// examples/graphs, row_offsets: compressed-row offsets of the counts in
/// inputs/values.npy, every length from arrayLength. The reference: the
/// exclusive prefix sum (mod 2^32), then the total.
fn graphs_row_offsets() -> Result<(), String> {
    let counts = npy_u32(&example("graphs/inputs/values.npy"));
    let mut want = Vec::with_capacity(counts.len() + 1);
    let mut total = 0u32;
    for c in &counts {
        want.push(total);
        total = total.wrapping_add(*c);
    }
    want.push(total);
    let out = render_example("graphs", "row_offsets", 64, 64)?;
    let Some(OutputValue::Buffer { bytes, .. }) = out.outputs.first().map(|o| &o.value) else {
        return Err("row_offsets: no buffer output".into());
    };
    let got: Vec<u32> = bytes.chunks_exact(4).map(|w| u32::from_le_bytes(w.try_into().expect("4 bytes"))).collect();
    if got.len() != want.len() {
        return Err(format!("row_offsets: {} offsets, want {}", got.len(), want.len()));
    }
    match got.iter().zip(&want).position(|(a, b)| a != b) {
        None => Ok(()),
        Some(i) => Err(format!("row_offsets: offset {i} is {}, the exclusive scan says {}", got[i], want[i])),
    }
}

/// A texture output's texels (raw f32 RGBA, rows top to bottom).
fn texels(out: &vista_render::Rendered) -> Result<(u32, u32, Vec<[f32; 4]>), String> {
    match out.outputs.first().map(|o| &o.value) {
        Some(OutputValue::Texture { raw, .. }) => Ok((raw.width, raw.height, raw.data.clone())),
        _ => Err("no texture output".into()),
    }
}

/// examples/harness-crate, glow: I = exp(-(r / radius)^2) + ring exp(-((r - ring_at) / ring_width)^2)
/// at p = 2 uv - 1, tinted, clamped, stored in rgba8unorm: within one 8-bit step.
fn harness_crate_glow() -> Result<(), String> {
    let (tint, radius, ring, ring_at, ring_width) = ([1.0, 0.7, 0.3], 0.35, 0.5, 0.7, 0.08);
    let (w, h, got) = texels(&render_example("harness-crate", "glow", 64, 64)?)?;
    let mut worst = (0.0f64, 0usize);
    for (i, texel) in got.iter().enumerate() {
        let (x, y) = ((i as u32 % w) as f64, (i as u32 / w) as f64);
        let p = [(x + 0.5) / w as f64 * 2.0 - 1.0, (y + 0.5) / h as f64 * 2.0 - 1.0];
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let intensity = (-(r / radius).powi(2)).exp() + ring * (-((r - ring_at) / ring_width).powi(2)).exp();
        for c in 0..3 {
            let want = (tint[c] * intensity).clamp(0.0, 1.0);
            let err = (texel[c] as f64 - want).abs();
            if err > worst.0 {
                worst = (err, i);
            }
        }
    }
    match worst.0 <= 1.0 / 255.0 {
        true => Ok(()),
        false => Err(format!("glow: texel {} is {:.5} from the formula (allowed: one 8-bit step)", worst.1, worst.0)),
    }
}

/// examples/real-kernels, mandelbrot: escape time of z <- z^2 + c from 0
/// over [-2.2, 0.8] x [-1.2, 1.2], at most 96 steps, red = steps / 96.
/// f32 and f64 orbits part near the set's boundary, so at most 1% of the
/// pixels may differ, where the orbit is
/// chaotic (measured on lavapipe: 4 of 6144, 0.07%).
fn real_kernels_mandelbrot() -> Result<(), String> {
    let (w, h, got) = texels(&render_example("real-kernels", "mandelbrot", 96, 64)?)?;
    let mut differ = 0;
    for (i, texel) in got.iter().enumerate() {
        let (x, y) = ((i as u32 % w) as f64, (i as u32 / w) as f64);
        let c = [-2.2 + 3.0 * (x + 0.5) / w as f64, -1.2 + 2.4 * (y + 0.5) / h as f64];
        let (mut z, mut n) = ([0.0f64, 0.0], 0u32);
        while n < 96 && z[0] * z[0] + z[1] * z[1] <= 4.0 {
            z = [z[0] * z[0] - z[1] * z[1] + c[0], 2.0 * z[0] * z[1] + c[1]];
            n += 1;
        }
        let want = n as f64 / 96.0;
        if (texel[0] as f64 - want).abs() > 0.5 / 255.0 + 1e-6 {
            differ += 1;
        }
    }
    let share = differ as f64 / got.len() as f64;
    println!("mandelbrot: {differ} of {} pixels differ from the f64 escape time", got.len());
    match share <= 0.01 {
        true => Ok(()),
        false => Err(format!(
            "mandelbrot: {differ} of {} pixels differ from the escape time ({:.2}%)",
            got.len(),
            100.0 * share
        )),
    }
}

/// Renders `kernel` of example project `name` with `set` over its defaults.
fn render_example_with(
    name: &str,
    kernel: &str,
    set: &[(&str, &str)],
    width: u32,
    height: u32,
) -> Result<vista_render::Rendered, String> {
    let ctx = vista_gpu::Context::shared(&common::config().gpu).map_err(|e| e.to_string())?;
    let set: Vec<(String, String)> = set.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    common::render_in_project(ctx, &example(name), kernel, &set, (width, height))
}

/// Golden case `case` of example `name` rendered as `vista check` renders
/// it: its params, defs, inputs (leaf values inline too) and size.
fn render_case(name: &str, case: &str) -> Result<vista_render::Rendered, String> {
    let ctx = vista_gpu::Context::shared(&common::config().gpu).map_err(|e| e.to_string())?;
    let project = vista_project::Project::at(&example(name)).map_err(|e| e.to_string())?;
    let store = vista_golden::Store::of_project(&project, "references").map_err(|e| e.to_string())?;
    let cases = store.load_cases().map_err(|e| e.to_string())?;
    let c = cases.iter().find(|c| c.id == case).ok_or_else(|| format!("no case {case}"))?;
    let gpu = vista_render::Renderer::new(ctx, &project, common::config().limits).map_err(|e| e.to_string())?;
    vista_render::render_with(&gpu, &c.kernel, &c.params, &c.inputs, c.width, c.height)
        .map_err(|e| format!("{case}: {e}"))
}

/// The texture output named `name` (raw f32 RGBA, rows top to bottom).
fn texels_named(out: &vista_render::Rendered, name: &str) -> Result<(u32, u32, Vec<[f32; 4]>), String> {
    match out.outputs.iter().find(|o| o.name == name).map(|o| &o.value) {
        Some(OutputValue::Texture { raw, .. }) => Ok((raw.width, raw.height, raw.data.clone())),
        _ => Err(format!("no texture output '{name}'")),
    }
}

/// What texel (x, y) should hold: per channel (RGBA) the reference value
/// and how far a correct render may be from it; `None` leaves it unchecked.
type Want = Option<([f64; 4], [f64; 4])>;

/// Every texel of a `w`-wide image against `want`. Ok with how many were
/// checked; else how many are off and the worst, by texel and channel.
fn compare(label: &str, w: u32, got: &[[f32; 4]], want: impl Fn(u32, u32) -> Want) -> Result<usize, String> {
    let (mut checked, mut off, mut ratio) = (0usize, 0usize, 0.0f64);
    let mut worst: Option<(f64, u32, u32, usize, f32, f64, f64)> = None;
    for (i, texel) in got.iter().enumerate() {
        let (x, y) = (i as u32 % w, i as u32 / w);
        let Some((value, allowed)) = want(x, y) else { continue };
        checked += 1;
        let mut bad = false;
        for c in 0..4 {
            let err = (f64::from(texel[c]) - value[c]).abs();
            // An error NaN is off, and the worst.
            let excess = if err.is_nan() { f64::INFINITY } else { err - allowed[c] };
            if allowed[c] > 0.0 {
                ratio = ratio.max(err / allowed[c]);
            }
            if excess > 0.0 {
                bad = true;
                if worst.is_none_or(|w| excess > w.0) {
                    worst = Some((excess, x, y, c, texel[c], value[c], allowed[c]));
                }
            }
        }
        off += usize::from(bad);
    }
    println!("{label}: {checked} texels checked, worst error {ratio:.3} of its allowance");
    match worst {
        None => Ok(checked),
        Some((_, x, y, c, g, r, a)) => Err(format!(
            "{label}: {off} of {checked} texels off the reference; worst ({x}, {y}) channel {c}: \
             got {g}, reference {r:.6}, allowed +-{a:.3e}"
        )),
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    a.map(|c| c / n)
}

/// p + t d.
fn along(p: [f64; 3], d: [f64; 3], t: f64) -> [f64; 3] {
    [p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]]
}

fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// One 8-bit level: a float to unorm8 conversion may give either of the
/// two levels nearest the value (Vulkan's "one of the two closest"), so an
/// rgba8unorm texel is within one step of the exact value.
const UNORM8_STEP: f64 = 1.0 / 255.0;

/// A float to f16 conversion may give either of the two nearest f16
/// values: within 2^-10 of the value, relatively, for normal numbers, and
/// within 2^-24 (the subnormal spacing) absolutely below them.
fn f16_rounding(v: f64) -> f64 {
    v.abs() * 2f64.powi(-10) + 2f64.powi(-24)
}

// ---------------------------------------------------------------- project

/// Ken Perlin's Improved Noise (2002): the reference permutation of 0..255.
#[rustfmt::skip]
const PERLIN_PERMUTATION: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99, 37, 240,
    21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88,
    237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83,
    111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80,
    73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173, 186, 3, 64,
    52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17, 182,
    189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22,
    39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210,
    144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84,
    204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78,
    66, 215, 61, 156, 180,
];

/// Improved Noise in f64 as Perlin's reference implementation defines it:
/// the permutation doubled to 512 entries, fade 6t^5 - 15t^4 + 10t^3, the
/// gradient of a corner picked by its hash's low 4 bits among the 12 cube
/// edges (4 repeated).
fn perlin(x: f64, y: f64, z: f64) -> f64 {
    let p = |i: usize| usize::from(PERLIN_PERMUTATION[i & 255]);
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
    let grad = |hash: usize, x: f64, y: f64, z: f64| {
        let h = hash & 15;
        let u = if h < 8 { x } else { y };
        let v = if h < 4 {
            y
        } else if h == 12 || h == 14 {
            x
        } else {
            z
        };
        (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
    };
    let cell = [x.floor(), y.floor(), z.floor()];
    let [xi, yi, zi] = cell.map(|c| (c as i64 & 255) as usize);
    let (x, y, z) = (x - cell[0], y - cell[1], z - cell[2]);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let (a, b) = (p(xi) + yi, p(xi + 1) + yi);
    let (aa, ab, ba, bb) = (p(a) + zi, p(a + 1) + zi, p(b) + zi, p(b + 1) + zi);
    let face = |dz: usize, z: f64| {
        let x0 = lerp(u, grad(p(aa + dz), x, y, z), grad(p(ba + dz), x - 1.0, y, z));
        let x1 = lerp(u, grad(p(ab + dz), x, y - 1.0, z), grad(p(bb + dz), x - 1.0, y - 1.0, z));
        lerp(v, x0, x1)
    };
    lerp(w, face(0, z), face(1, z - 1.0))
}

/// examples/project, marble: v = 0.5 + 0.5 sin(2 pi (stripes u + turbulence
/// perlin(scale u, scale v, z))), colour = mix(vein, base, v), with Perlin's
/// Improved Noise over his permutation (vista's seed 0, which the host
/// uploads as a buffer: a wrong table, a uniform field read from the wrong
/// offset or a texel off by one all move the veins).
fn project_marble() -> Result<(), String> {
    // The reference's own reference value (SPEC 3.1): a mistyped table fails here.
    #[allow(clippy::approx_constant)] // SPEC 3.1's point, not pi
    let at = perlin(3.14, 42.0, 7.0);
    if (at - 0.13691995878400012).abs() > 1e-15 {
        return Err(format!(
            "marble: the f64 Perlin noise gives {at} at (3.14, 42, 7), SPEC 3.1 says 0.13691995878400012"
        ));
    }
    let (stripes, turbulence, scale, z) = (6.0, 1.0, 4.0, 0.5);
    let (base, vein) = ([0.92, 0.9, 0.85], [0.25, 0.22, 0.2]);
    // Allowance: the GPU's f32 forms the sine's argument 2 pi (6 u + bend),
    // |arg| <= 2 pi (6 + 1.04) < 45, to a few ulp(45) = 4e-6 (Perlin in f32:
    // ~1e-6, times 2 pi); its sin is within 2^-11 (WGSL's bound) of the true
    // one. v moves by half of that, the colour by |base - vein| <= 0.67
    // times v: 0.67 * 0.5 * (2^-11 + 2e-5) = 1.7e-4, so 2e-4 (an f32
    // rgba32float texel stores it unrounded). One texel of u moves the
    // argument by 2 pi 6 / 96 = 0.39: colour changes up to 0.13.
    let allowed = 2e-4;
    let (w, h, got) = texels(&render_example("project", "marble", 96, 64)?)?;
    compare("marble", w, &got, |x, y| {
        let (u, v) = ((f64::from(x) + 0.5) / f64::from(w), (f64::from(y) + 0.5) / f64::from(h));
        let bend = turbulence * perlin(scale * u, scale * v, z);
        let t = 0.5 + 0.5 * (std::f64::consts::TAU * (stripes * u + bend)).sin();
        let c = |k: usize| vein[k] + (base[k] - vein[k]) * t;
        Some(([c(0), c(1), c(2), 1.0], [allowed, allowed, allowed, 0.0]))
    })
    .map(|_| ())
}

// ----------------------------------------------------------------- render

// SPEC 3.5's atmosphere: lengths in m, the planet centred at the origin.
const R_GROUND: f64 = 6_360_000.0;
const R_TOP: f64 = 6_420_000.0;
const BETA_RAYLEIGH: [f64; 3] = [5.802e-6, 13.558e-6, 33.1e-6];
const H_RAYLEIGH: f64 = 8000.0;
const BETA_MIE: f64 = 3.996e-6;
const H_MIE: f64 = 1200.0;

/// One sky of SPEC 3.5: sun direction, camera altitude, E_sun, the HG g and
/// the midpoint steps.
struct Sky {
    sun: [f64; 3],
    altitude: f64,
    e_sun: f64,
    g: f64,
    view_samples: u32,
    light_samples: u32,
}

/// (rho_R, rho_M) at p: exp(-h / H) at the altitude h = |p| - R_ground.
fn air_density(p: [f64; 3]) -> [f64; 2] {
    let h = dot(p, p).sqrt() - R_GROUND;
    [(-h / H_RAYLEIGH).exp(), (-h / H_MIE).exp()]
}

/// exp(-optical depth) of density columns (Rayleigh, Mie); Mie extinction
/// is 1.11 beta_M.
fn air_transmittance(column: [f64; 2]) -> [f64; 3] {
    BETA_RAYLEIGH.map(|b| (-(b * column[0] + 1.11 * BETA_MIE * column[1])).exp())
}

/// Distance along the unit d from p, inside the sphere of radius r about
/// the origin, to where the ray leaves it.
fn sphere_exit(p: [f64; 3], d: [f64; 3], r: f64) -> f64 {
    let b = dot(p, d);
    -b + (b * b - (dot(p, p) - r * r)).sqrt()
}

/// Distance along the unit d from p, above the ground, to the ground, if
/// the ray meets it.
fn ground_ahead(p: [f64; 3], d: [f64; 3]) -> Option<f64> {
    let b = dot(p, d);
    let disc = b * b - (dot(p, p) - R_GROUND * R_GROUND);
    let t = -b - disc.max(0.0).sqrt();
    (disc >= 0.0 && t > 0.0).then_some(t)
}

/// T_sun at p: the midpoint rule with light_samples steps to the top of the
/// atmosphere toward the sun; 0 where the planet is in the way.
fn sun_transmittance(sky: &Sky, p: [f64; 3]) -> [f64; 3] {
    if ground_ahead(p, sky.sun).is_some() {
        return [0.0; 3];
    }
    let du = sphere_exit(p, sky.sun, R_TOP) / f64::from(sky.light_samples);
    let mut column = [0.0; 2];
    for j in 0..sky.light_samples {
        let rho = air_density(along(p, sky.sun, (f64::from(j) + 0.5) * du));
        column = [column[0] + rho[0] * du, column[1] + rho[1] * du];
    }
    air_transmittance(column)
}

/// SPEC 3.5's L along the unit v: E_sun times the integral over the view
/// ray (camera to the top of the atmosphere or the ground) of T(camera, p)
/// (beta_R rho_R P_R + beta_M rho_M P_HG) T_sun(p), by the midpoint rule
/// with view_samples steps; T(camera, p) at a step's midpoint is the
/// midpoint sum of the steps before it and half of its own.
fn sky_radiance(sky: &Sky, v: [f64; 3]) -> [f64; 3] {
    let camera = [0.0, R_GROUND + sky.altitude, 0.0];
    let end = ground_ahead(camera, v).unwrap_or_else(|| sphere_exit(camera, v, R_TOP));
    let dt = end / f64::from(sky.view_samples);
    let mu = dot(v, sky.sun);
    let pi = std::f64::consts::PI;
    let rayleigh = 3.0 / (16.0 * pi) * (1.0 + mu * mu);
    let g = sky.g;
    let mie = (1.0 - g * g) / (4.0 * pi * (1.0 + g * g - 2.0 * g * mu).powf(1.5));
    let (mut before, mut sum) = ([0.0; 2], [0.0; 3]);
    for i in 0..sky.view_samples {
        let p = along(camera, v, (f64::from(i) + 0.5) * dt);
        let rho = air_density(p);
        let to_p = air_transmittance([before[0] + 0.5 * dt * rho[0], before[1] + 0.5 * dt * rho[1]]);
        let sun = sun_transmittance(sky, p);
        for c in 0..3 {
            sum[c] += to_p[c] * (BETA_RAYLEIGH[c] * rho[0] * rayleigh + BETA_MIE * rho[1] * mie) * sun[c];
        }
        before = [before[0] + dt * rho[0], before[1] + dt * rho[1]];
    }
    sum.map(|s| sky.e_sun * dt * s)
}

/// Unit vector at azimuth phi (from +z toward +x) and elevation e.
fn sky_direction(phi: f64, e: f64) -> [f64; 3] {
    [e.cos() * phi.sin(), e.sin(), e.cos() * phi.cos()]
}

/// How far the full-screen sky may be from the f64 integral: per channel
/// 2e-4 of L, plus 1e-7 absolute for black texels. The GPU's f32 sums of
/// 32 view and 8 light midpoint terms are good to ~40 ulp (5e-6 relative),
/// the optical depths too, so exp(-tau), tau <= ~10 (blue at the horizon),
/// is within 10 * 5e-6 = 5e-5 relative; a term is the product of two such
/// transmittances and the phases: 1e-4. Doubled for the direction's f32
/// sin/cos, good to ulps, where d ln L / d elevation reaches ~20 per radian
/// near the horizon. Half a pixel of uv moves the elevation by 0.016 rad
/// and L by percents. The bound takes sin, cos and exp to be good to a few
/// ulp, as lavapipe's are (the suite's device; measured: 0.02-0.03 of the
/// allowance). WGSL asks only 2^-11 absolute of sin and cos, which near the
/// sun, where d ln P_HG / d mu = 3g / (1 + g^2 - 2 g mu) reaches 60, can
/// move L by percents: SwiftShader's approximations land 1% off there and
/// fail this check, a difference that is the driver's.
fn sky_allowance(l: [f64; 3]) -> [f64; 4] {
    [l[0], l[1], l[2], 0.0].map(|v| 2e-4 * v + 1e-7)
}

/// examples/render, sky_fullscreen, latlong at the defaults (sun at 30
/// degrees, 1 km, E_sun 20, g 0.8, 32 x 8 steps): the full-screen
/// triangle's uv at every pixel centre, (0, 0) top left, fed to SPEC 3.5's
/// latlong direction; every texel the f64 integral's value there.
fn render_sky_latlong() -> Result<(), String> {
    let e = 30f64.to_radians();
    let sky =
        Sky { sun: [0.0, e.sin(), e.cos()], altitude: 1000.0, e_sun: 20.0, g: 0.8, view_samples: 32, light_samples: 8 };
    let (w, h, got) = texels(&render_example("render", "sky_fullscreen", 96, 48)?)?;
    compare("sky_fullscreen latlong", w, &got, |x, y| {
        let (u, v) = ((f64::from(x) + 0.5) / f64::from(w), (f64::from(y) + 0.5) / f64::from(h));
        let l = sky_radiance(&sky, sky_direction(std::f64::consts::TAU * u, std::f64::consts::FRAC_PI_2 * (1.0 - v)));
        Some(([l[0], l[1], l[2], 1.0], sky_allowance(l)))
    })
    .map(|_| ())
}

/// examples/render, sky_fullscreen, equidistant fisheye on a wide image,
/// sun at 2 degrees: xy = (2u - 1, 1 - 2v) size / min(size), zenith at the
/// centre, the sun's azimuth up, elevation (pi / 2)(1 - r); black (0)
/// outside r = 1. The aspect comes from the width and height uniforms.
fn render_sky_fisheye() -> Result<(), String> {
    let e = 2f64.to_radians();
    let sky =
        Sky { sun: [0.0, e.sin(), e.cos()], altitude: 1000.0, e_sun: 20.0, g: 0.8, view_samples: 32, light_samples: 8 };
    let set = [("projection", "fisheye"), ("sun_elevation_deg", "2")];
    let (w, h, got) = texels(&render_example_with("render", "sky_fullscreen", &set, 64, 48)?)?;
    let short = f64::from(w.min(h));
    compare("sky_fullscreen fisheye", w, &got, |x, y| {
        let xy = [(2.0 * f64::from(x) + 1.0 - f64::from(w)) / short, (f64::from(h) - 2.0 * f64::from(y) - 1.0) / short];
        let r = xy[0].hypot(xy[1]);
        // On the rim f32 may decide r <= 1 otherwise; no pixel centre is that
        // close at 64 x 48 (two odd squares never sum to 48^2).
        if (r - 1.0).abs() < 1e-5 {
            return None;
        }
        let l = match r <= 1.0 {
            true => sky_radiance(&sky, sky_direction(xy[0].atan2(xy[1]), std::f64::consts::FRAC_PI_2 * (1.0 - r))),
            false => [0.0; 3],
        };
        Some(([l[0], l[1], l[2], 1.0], sky_allowance(l)))
    })
    .map(|_| ())
}

/// RGB values on a grid with, per texel and channel, how far a correct
/// render may be from them (its error bound, carried along the chain).
#[derive(Clone)]
struct Bounded {
    w: usize,
    h: usize,
    value: Vec<[f64; 3]>,
    bound: Vec<[f64; 3]>,
}

impl Bounded {
    /// Every texel from its centre's uv (as a compute pass over pixel
    /// centres or a full-screen triangle gives it): value and bound.
    fn from_uv(w: usize, h: usize, f: impl Fn(f64, f64) -> ([f64; 3], [f64; 3])) -> Bounded {
        let (mut value, mut bound) = (Vec::with_capacity(w * h), Vec::with_capacity(w * h));
        for y in 0..h {
            for x in 0..w {
                let (v, b) = f((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                value.push(v);
                bound.push(b);
            }
        }
        Bounded { w, h, value, bound }
    }

    /// WebGPU's bilinear filter at uv, clamp-to-edge: the four texels
    /// around uv * size - 0.5, weighted by the fractions. The bound is the
    /// same weighted sum of the texels' bounds.
    fn sample(&self, uv: [f64; 2]) -> ([f64; 3], [f64; 3]) {
        let (x, y) = (uv[0] * self.w as f64 - 0.5, uv[1] * self.h as f64 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: f64, j: f64| {
            let i = (i as i64).clamp(0, self.w as i64 - 1) as usize;
            let j = (j as i64).clamp(0, self.h as i64 - 1) as usize;
            j * self.w + i
        };
        let taps = [
            (at(x0, y0), (1.0 - fx) * (1.0 - fy)),
            (at(x0 + 1.0, y0), fx * (1.0 - fy)),
            (at(x0, y0 + 1.0), (1.0 - fx) * fy),
            (at(x0 + 1.0, y0 + 1.0), fx * fy),
        ];
        let (mut v, mut b) = ([0.0; 3], [0.0; 3]);
        for (i, weight) in taps {
            for c in 0..3 {
                v[c] += weight * self.value[i][c];
                b[c] += weight * self.bound[i][c];
            }
        }
        (v, b)
    }

    /// The mean of four bilinear samples at uv +- d texels along both axes.
    fn four_taps(&self, uv: [f64; 2], d: f64) -> ([f64; 3], [f64; 3]) {
        let (dx, dy) = (d / self.w as f64, d / self.h as f64);
        let (mut v, mut b) = ([0.0; 3], [0.0; 3]);
        for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            let (tv, tb) = self.sample([uv[0] + sx * dx, uv[1] + sy * dy]);
            for c in 0..3 {
                v[c] += 0.25 * tv[c];
                b[c] += 0.25 * tb[c];
            }
        }
        (v, b)
    }

    /// Stored in an f16 texture: each value may round to either
    /// neighbouring f16.
    fn stored_f16(mut self) -> Bounded {
        for (v, b) in self.value.iter().zip(&mut self.bound) {
            for c in 0..3 {
                b[c] += f16_rounding(v[c]);
            }
        }
        self
    }

    /// An additive blend of `add` onto this target (same size): dst + src,
    /// src converted to the target's f16 first (a blend unit may work at
    /// the target's precision), the sum stored in f16.
    fn plus_f16(mut self, add: &Bounded) -> Bounded {
        for i in 0..self.value.len() {
            for c in 0..3 {
                self.value[i][c] += add.value[i][c];
                self.bound[i][c] += add.bound[i][c] + f16_rounding(add.value[i][c]);
            }
        }
        self.stored_f16()
    }
}

/// examples/render, bloom at 96 x 48: the compute source (a sky gradient
/// and three Gaussian suns, at p = pixel centre / height), a bright pass
/// (box of 4 x 4 texels as four bilinear taps one texel off the centre,
/// minus the threshold, at least 0) into half size, two more box
/// down-samples, three tent up-samples (four bilinear taps half a texel
/// off) added onto the next larger level, the last onto the cleared glow,
/// and the tonemap 1 - exp(-exposure (scene + intensity glow)) into
/// rgba8unorm. The reference runs the same chain in f64 from those
/// formulas and WebGPU's bilinear filter, and carries an error bound
/// through it: every f16 store (and the blend's f16 source) may round to
/// either neighbouring f16 (2^-10 relative), the filter's weights are
/// exact (the taps fall on quarter texels), and an average or a max(. - c,
/// 0) passes its inputs' bound on. Both outputs, glow (rgba16float) and
/// ldr, are checked at every texel.
fn render_bloom() -> Result<(), String> {
    let (w, h) = (96usize, 48usize);
    let (threshold, intensity, exposure) = (1.0, 0.6, 1.0);
    let suns = [
        ([0.3, 0.3], 0.04, [40.0, 30.0, 18.0]),
        ([1.1, 0.55], 0.025, [10.0, 25.0, 40.0]),
        ([1.6, 0.2], 0.06, [30.0, 12.0, 6.0]),
    ];
    let hdr = Bounded::from_uv(w, h, |u, v| {
        let p = [u * w as f64 / h as f64, v];
        let mut c = [0.05, 0.07, 0.12].map(|k| k * (1.2 - p[1]));
        for (centre, radius, colour) in suns {
            let d = (p[0] - centre[0]).hypot(p[1] - centre[1]) / radius;
            (0..3).for_each(|k| c[k] += colour[k] * (-d * d).exp());
        }
        // f32: exp(-x) within WGSL's 3 + 2x ulp, e^-x (3 + 2x) <= 3, so a
        // sun term within 3 * 2^-23 * 40 = 1.4e-5; three suns, with margin: 1e-4.
        (c, [1e-4; 3])
    })
    .stored_f16();
    let half = |b: &Bounded| (b.w / 2, b.h / 2);
    let (w1, h1) = half(&hdr);
    let down1 = Bounded::from_uv(w1, h1, |u, v| {
        let (c, b) = hdr.four_taps([u, v], 1.0);
        (c.map(|c| (c - threshold).max(0.0)), b)
    })
    .stored_f16();
    let (w2, h2) = half(&down1);
    let down2 = Bounded::from_uv(w2, h2, |u, v| down1.four_taps([u, v], 1.0)).stored_f16();
    let (w3, h3) = half(&down2);
    let down3 = Bounded::from_uv(w3, h3, |u, v| down2.four_taps([u, v], 1.0)).stored_f16();
    let down2 = down2.clone().plus_f16(&Bounded::from_uv(w2, h2, |u, v| down3.four_taps([u, v], 0.5)));
    let down1 = down1.clone().plus_f16(&Bounded::from_uv(w1, h1, |u, v| down2.four_taps([u, v], 0.5)));
    let glow = Bounded::from_uv(w, h, |_, _| ([0.0; 3], [0.0; 3]))
        .plus_f16(&Bounded::from_uv(w, h, |u, v| down1.four_taps([u, v], 0.5)));

    let out = render_example("render", "bloom", w as u32, h as u32)?;
    let (gw, gh, got) = texels_named(&out, "glow")?;
    if (gw as usize, gh as usize) != (w, h) {
        return Err(format!("bloom: glow is {gw}x{gh}, want {w}x{h}"));
    }
    compare("bloom glow", gw, &got, |x, y| {
        let i = y as usize * w + x as usize;
        let (v, b) = (glow.value[i], glow.bound[i]);
        Some(([v[0], v[1], v[2], 1.0], [b[0], b[1], b[2], 0.0]))
    })?;
    let (_, _, got) = texels_named(&out, "ldr")?;
    compare("bloom ldr", gw, &got, |x, y| {
        let i = y as usize * w + x as usize;
        let (mut v, mut b) = ([0.0, 0.0, 0.0, 1.0], [0.0; 4]);
        for c in 0..3 {
            // At the texel centres the tonemap reads one texel of each.
            let radiance = hdr.value[i][c] + intensity * glow.value[i][c];
            let bound = hdr.bound[i][c] + intensity * glow.bound[i][c];
            v[c] = 1.0 - (-exposure * radiance).exp();
            // The curve's slope within the bound: at most exposure exp(-exposure
            // (radiance - bound)); then the 8-bit conversion, and 1e-6 for f32.
            b[c] = exposure * (-exposure * (radiance - bound).max(0.0)).exp() * bound + UNORM8_STEP + 1e-6;
        }
        Some((v, b))
    })
    .map(|_| ())
}

fn npy_bytes(path: &Path, descr: &str) -> Vec<u8> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let npy = vista_image::npy::decode_npy(path, &bytes).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(npy.descr, descr, "{}", path.display());
    npy.data
}

/// examples/render, grass at 160 x 96 and time 0.8, where nothing but the
/// ground or nothing at all is drawn. The camera of the README: eye (0,
/// 0.55, -2.2) looking at (0, 0.25, 1), fov 40 degrees, pixel (0, 0) top
/// left. A pixel whose centre and the points one pixel away around it all
/// see the ground quad (y = 0, x in [-4, 4], z in [-1.5, 4]), and that is
/// no nearer than a pixel to any card's projected triangles (their upper
/// vertices swayed by wind (cos a, 0, sin a), a = |p| sin(time) 20), is the
/// soil texel (92, 70, 44) / 255 faded to the sky colour by exp(-0.12 c.z),
/// c.z the depth of the ground point its centre sees (what perspective-
/// correct interpolation of the depth gives); one whose rays all miss the
/// ground is the clear colour (0.55, 0.70, 0.90). Both within one 8-bit
/// step (the conversion's two nearest levels) plus 1e-5 for f32 (the
/// interpolated depth is good to ~1e-6 relative, the fog's exp to ulps).
fn render_grass() -> Result<(), String> {
    let (w, h) = (160u32, 96u32);
    let (time, wind, fov) = (0.8f64, 0.06, 40f64.to_radians());
    let (eye, look) = ([0.0, 0.55, -2.2], [0.0, 0.25, 1.0]);
    let sky_colour = [0.55, 0.70, 0.90];
    let soil = [92.0 / 255.0, 70.0 / 255.0, 44.0 / 255.0];
    let forward = normalize([look[0] - eye[0], look[1] - eye[1], look[2] - eye[2]]);
    let right = normalize(cross([0.0, 1.0, 0.0], forward));
    let up = cross(forward, right);
    let (t, aspect) = ((fov / 2.0).tan(), f64::from(w) / f64::from(h));
    // Camera coordinates of p, then its pixel position (x right, y down).
    let camera = |p: [f64; 3]| {
        let d = [p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]];
        [dot(d, right), dot(d, up), dot(d, forward)]
    };
    let to_pixel = |c: [f64; 3]| {
        let ndc = [c[0] / (c[2] * t * aspect), c[1] / (c[2] * t)];
        [(ndc[0] + 1.0) / 2.0 * f64::from(w), (1.0 - ndc[1]) / 2.0 * f64::from(h)]
    };
    // The world point on y = 0 the ray through pixel position (sx, sy)
    // meets, with its camera depth; None if it points at or above the horizon.
    let ground_hit = |sx: f64, sy: f64| {
        let ndc = [2.0 * sx / f64::from(w) - 1.0, 1.0 - 2.0 * sy / f64::from(h)];
        let d: [f64; 3] = std::array::from_fn(|k| forward[k] + ndc[0] * t * aspect * right[k] + ndc[1] * t * up[k]);
        (d[1] < 0.0).then(|| {
            let s = -eye[1] / d[1];
            (along(eye, d, s), s)
        })
    };
    let on_ground = |p: [f64; 3]| (-4.0..=4.0).contains(&p[0]) && (-1.5..=4.0).contains(&p[2]);

    let vertices: Vec<f32> = npy_bytes(&example("render/inputs/grass_blades.npy"), "<f4")
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
        .collect();
    let indices: Vec<usize> = npy_bytes(&example("render/inputs/grass_indices.npy"), "<u2")
        .chunks_exact(2)
        .map(|b| usize::from(u16::from_le_bytes(b.try_into().expect("2 bytes"))))
        .collect();
    // Each card triangle's pixel-space bounding box, a pixel wider each way.
    let mut near_card = vec![false; (w * h) as usize];
    for tri in indices.chunks_exact(3) {
        let corners = [tri[0], tri[1], tri[2]].map(|i| {
            let v = &vertices[5 * i..5 * i + 5];
            let p = [v[0], v[1], v[2]].map(f64::from);
            let upper = v[4] < 0.5;
            let p = match upper {
                true => {
                    let a = dot(p, p).sqrt() * time.sin() * 20.0;
                    [p[0] + wind * a.cos(), p[1], p[2] + wind * a.sin()]
                }
                false => p,
            };
            ((v[3], v[4]) == (0.97, 0.97), camera(p))
        });
        if corners.iter().all(|c| c.0) {
            continue; // the ground
        }
        if corners.iter().any(|c| c.1[2] <= 0.05) {
            return Err("grass: a card reaches the near plane, which this check does not clip".into());
        }
        let px = corners.map(|c| to_pixel(c.1));
        let lo = [0, 1].map(|k| px.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min) - 1.0);
        let hi = [0, 1].map(|k| px.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max) + 1.0);
        for y in (lo[1].floor().max(0.0) as u32)..(hi[1].ceil().min(f64::from(h)) as u32) {
            for x in (lo[0].floor().max(0.0) as u32)..(hi[0].ceil().min(f64::from(w)) as u32) {
                let (cx, cy) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                if cx >= lo[0] && cx <= hi[0] && cy >= lo[1] && cy <= hi[1] {
                    near_card[(y * w + x) as usize] = true;
                }
            }
        }
    }

    let (_, _, got) = texels(&render_example("render", "grass", w, h)?)?;
    let (ground, clear) = (std::cell::Cell::new(0), std::cell::Cell::new(0));
    let allowed = [UNORM8_STEP + 1e-5, UNORM8_STEP + 1e-5, UNORM8_STEP + 1e-5, 0.0];
    compare("grass ground and sky", w, &got, |x, y| {
        if near_card[(y * w + x) as usize] {
            return None;
        }
        let (cx, cy) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
        let around = [(0.0, 0.0), (-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)];
        let sees: Vec<bool> =
            around.iter().map(|(dx, dy)| ground_hit(cx + dx, cy + dy).is_some_and(|(p, _)| on_ground(p))).collect();
        if sees.iter().all(|s| *s) {
            ground.set(ground.get() + 1);
            let (_, depth) = ground_hit(cx, cy).expect("seen above");
            let fog = (-0.12 * depth).exp();
            let c: [f64; 3] = std::array::from_fn(|k| sky_colour[k] + (soil[k] - sky_colour[k]) * fog);
            Some(([c[0], c[1], c[2], 1.0], allowed))
        } else if sees.iter().all(|s| !s) {
            clear.set(clear.get() + 1);
            Some(([sky_colour[0], sky_colour[1], sky_colour[2], 1.0], allowed))
        } else {
            None
        }
    })?;
    // Not vacuous: at this view the ground below the first layer and the
    // sky above the cards are each a large share of the image.
    let floor = (w * h / 10) as usize;
    match ground.get() >= floor && clear.get() >= floor {
        true => Ok(()),
        false => Err(format!(
            "grass: only {} ground and {} sky texels checked (want {floor} each)",
            ground.get(),
            clear.get()
        )),
    }
}

// ---------------------------------------------------------------- sources

/// examples/sources, transmittance (naga_oil modules, SAMPLE_COUNT = 40 as
/// a valued def) at 72 x 40: mu = 2u - 1, r from the top (6460 km) at v =
/// 0 to the ground (6360 km) at v = 1; T = exp(-beta_R integral of
/// exp(-(radius - R_ground) / H) along the ray to the top sphere), the
/// integral by the midpoint rule with 40 steps, radius by the law of
/// cosines; alpha = that path's length over the ground's horizontal one.
/// Allowance: T is stored in rgba16float, 2^-10 relative; the f32 forms
/// r^2 + t^2 + 2 r mu t at ~4e7 km^2 to a few ulp (4 km^2 each), the
/// radius to 1e-3 km, the density to 1e-3 / 8 = 1.3e-4 relative and so the
/// depth; |dT| = T tau d(tau)/tau <= (1 / e) 1.3e-4 = 5e-5; 1e-4 absolute.
fn sources_transmittance() -> Result<(), String> {
    let (bottom, top, scale_height) = (6360.0f64, 6460.0f64, 8.0f64);
    let beta = [0.005802, 0.013558, 0.0331];
    let to_top = |r: f64, mu: f64| (-r * mu + (r * r * (mu * mu - 1.0) + top * top).max(0.0).sqrt()).max(0.0);
    let longest = to_top(bottom, 0.0);
    let (w, h, got) = texels(&render_example("sources", "transmittance", 72, 40)?)?;
    compare("transmittance", w, &got, |x, y| {
        let (u, v) = ((f64::from(x) + 0.5) / f64::from(w), (f64::from(y) + 0.5) / f64::from(h));
        let (mu, r) = (2.0 * u - 1.0, top + (bottom - top) * v);
        let d = to_top(r, mu);
        let dt = d / 40.0;
        let depth: f64 = (0..40)
            .map(|i| {
                let t = (f64::from(i) + 0.5) * dt;
                let radius = (r * r + t * t + 2.0 * r * mu * t).sqrt();
                (-(radius - bottom) / scale_height).exp() * dt
            })
            .sum();
        let t = beta.map(|b| (-b * depth).exp());
        let reach = (d / longest).clamp(0.0, 1.0);
        let want = [t[0], t[1], t[2], reach];
        Some((want, want.map(|v| f16_rounding(v) + 1e-4)))
    })
    .map(|_| ())
}

/// examples/sources, mips (one file composed twice: FIRST_PASS on the
/// first pass, the format written in for ##TEXTURE_FORMAT##) at 64 x 48:
/// mip1 (32 x 24) is each 2 x 2 block of the source PNG (16-bit: v /
/// 65535, as rgba32float) averaged with Karis weights 1 / (1 + luma),
/// luma = (0.2126, 0.7152, 0.0722) . rgb; mip2 (16 x 12) each 2 x 2 block of
/// mip1 plainly averaged, against both the f64 chain and the GPU's own
/// mip1. Allowance: each level is stored in rgba16float (2^-10 relative,
/// per store; lavapipe's f16 stores truncate: measured up to 0.97 of
/// this), plus 1e-6 for f32 (weights and sums of four terms).
/// The PNG's samples are read with vista_image's decoder: the input's
/// decoding is not what this checks, what the host does with it is.
fn sources_mips() -> Result<(), String> {
    let source = vista_image::read_png16(&example("sources/inputs/ridges.png")).map_err(|e| e.to_string())?;
    let sw = source.width as usize;
    let texel = |x: usize, y: usize| source.data[y * sw + x].map(f64::from);
    let out = render_example("sources", "mips", 64, 48)?;
    let (w1, h1, got1) = texels_named(&out, "mip1")?;
    let (w2, h2, got2) = texels_named(&out, "mip2")?;
    if (w1, h1, w2, h2) != (32, 24, 16, 12) {
        return Err(format!("mips: levels {w1}x{h1} and {w2}x{h2}, want 32x24 and 16x12 (width / 2, width / 4)"));
    }
    let block = |x: u32, y: u32| [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| (2 * x + dx, 2 * y + dy));
    let karis = |x: u32, y: u32| {
        let (mut sum, mut weight) = ([0.0; 3], 0.0);
        for (sx, sy) in block(x, y) {
            let c = texel(sx as usize, sy as usize);
            let wk = 1.0 / (1.0 + 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]);
            (0..3).for_each(|k| sum[k] += wk * c[k]);
            weight += wk;
        }
        sum.map(|s| s / weight)
    };
    let allowance = |v: [f64; 3], carried: f64| [0, 1, 2].map(|k| f16_rounding(v[k]) + carried * v[k].abs() + 1e-6);
    compare("mips mip1 (Karis)", w1, &got1, |x, y| {
        let c = karis(x, y);
        let a = allowance(c, 0.0);
        Some(([c[0], c[1], c[2], 1.0], [a[0], a[1], a[2], 0.0]))
    })?;
    compare("mips mip2 (box of the f64 mip1)", w2, &got2, |x, y| {
        let mut c = [0.0; 3];
        for (bx, by) in block(x, y) {
            let k = karis(bx, by);
            (0..3).for_each(|i| c[i] += 0.25 * k[i]);
        }
        // mip1's own rounding (2^-10 of each, so of their mean) carried on.
        let a = allowance(c, 2f64.powi(-10));
        Some(([c[0], c[1], c[2], 1.0], [a[0], a[1], a[2], 0.0]))
    })?;
    compare("mips mip2 (box of the GPU's mip1)", w2, &got2, |x, y| {
        let mut c = [0.0; 3];
        for (bx, by) in block(x, y) {
            let k = got1[(by * w1 + bx) as usize];
            (0..3).for_each(|i| c[i] += 0.25 * f64::from(k[i]));
        }
        let a = allowance(c, 0.0);
        Some(([c[0], c[1], c[2], 1.0], [a[0], a[1], a[2], 0.0]))
    })
    .map(|_| ())
}

/// examples/sources, blur (a template the project renders itself through
/// `[source] command`: tools/render_template.py unrolls the taps) at 64 x
/// 64: the source PNG (16-bit, v / 65535) blurred by the Gaussian
/// exp(-i^2 / (2 sigma^2)), i in -4..4, sigma 1.75, normalised, along rows
/// then columns, edges clamped; alpha 1. Both passes store rgba32float:
/// nine f32 products summed twice, well inside 2e-6.
fn sources_blur() -> Result<(), String> {
    let (radius, sigma) = (4i64, 1.75f64);
    let source = vista_image::read_png16(&example("sources/inputs/ridges.png")).map_err(|e| e.to_string())?;
    let (sw, sh) = (source.width as i64, source.height as i64);
    let raw: Vec<f64> = (-radius..=radius).map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp()).collect();
    let total: f64 = raw.iter().sum();
    let weight = |i: i64| raw[(i + radius) as usize] / total;
    let texel = |x: i64, y: i64| source.data[(y.clamp(0, sh - 1) * sw + x.clamp(0, sw - 1)) as usize].map(f64::from);
    let row = |x: i64, y: i64| {
        let mut c = [0.0; 3];
        for i in -radius..=radius {
            let t = texel(x + i, y);
            (0..3).for_each(|k| c[k] += weight(i) * t[k]);
        }
        c
    };
    let (w, h, got) = texels(&render_example("sources", "blur", 64, 64)?)?;
    if (w, h) != (64, 64) {
        return Err(format!("blur: {w}x{h}, want 64x64"));
    }
    compare("blur", w, &got, |x, y| {
        let mut c = [0.0; 3];
        for j in -radius..=radius {
            // The rows pass's texture is 64 x 64 too: its edge clamps the same way.
            let r = row(i64::from(x), (i64::from(y) + j).clamp(0, i64::from(h) - 1));
            (0..3).for_each(|k| c[k] += weight(j) * r[k]);
        }
        Some(([c[0], c[1], c[2], 1.0], [2e-6, 2e-6, 2e-6, 0.0]))
    })
    .map(|_| ())
}

/// examples/render, view_rays: an engine-style View uniform given by leaf
/// path (inputs/view.toml; the dense-fog case sets three leaves over it
/// inline), drawn by a full-screen pass at 64 x 48. The reference builds
/// each fragment's ray from the camera itself, not the file's matrices:
/// eye (0, 2, 6) looking at (0, 1, 0), y up, 60 deg vertical field of view
/// at aspect 64 / 48, through the texel centre; above the horizon
/// mix(fog colour, zenith (0.18, 0.36, 0.85), dir.y), below it the ground
/// plane y = 0 at t = 2 / -dir.y, mix(fog colour, (0.32, 0.27, 0.2),
/// exp(-density max(t - 1, 0))); then the grade (columns (1, 0, 0),
/// (0.08, 0.95, 0), (0, 0, 0.9)) and the exposure. A matrix packed row by
/// row, a mat3x3 column without its padding or a fog block at the wrong
/// offset moves every texel. Texels within 0.02 of the horizon are left
/// out (the fog's slope there); allowance: f16 storage plus 2e-5 for the
/// f32 ray (the near point's subtraction from the eye).
fn render_view_rays_case(case: &str, exposure: f64, density: f64, fog: [f64; 3]) -> Result<(), String> {
    let (w, h, got) = texels(&render_case("render", case)?)?;
    let (eye, target) = ([0.0, 2.0, 6.0], [0.0, 1.0, 0.0]);
    let norm = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / l)
    };
    let cross =
        |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let f = norm([target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]]);
    let side = norm(cross(f, [0.0, 1.0, 0.0]));
    let up = cross(side, f);
    let (tan, aspect) = (30f64.to_radians().tan(), f64::from(w) / f64::from(h));
    compare(case, w, &got, |x, y| {
        let ndc = [2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0, 1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h)];
        let (a, b) = (ndc[0] * aspect * tan, ndc[1] * tan);
        let dir = norm([0, 1, 2].map(|k| a * side[k] + b * up[k] + f[k]));
        if dir[1].abs() < 0.02 {
            return None;
        }
        let mix = |p: [f64; 3], q: [f64; 3], t: f64| [0, 1, 2].map(|k| p[k] + (q[k] - p[k]) * t);
        let c = match dir[1] >= 0.0 {
            true => mix(fog, [0.18, 0.36, 0.85], dir[1]),
            false => {
                let t = -eye[1] / dir[1];
                mix(fog, [0.32, 0.27, 0.2], (-density * (t - 1.0).max(0.0)).exp())
            }
        };
        let graded = [c[0] + 0.08 * c[1], 0.95 * c[1], 0.9 * c[2]].map(|v| v * exposure);
        let allow = graded.map(|v| f16_rounding(v) + 2e-5);
        Some(([graded[0], graded[1], graded[2], 1.0], [allow[0], allow[1], allow[2], 0.0]))
    })
    .map(|_| ())
}

fn render_view_rays() -> Result<(), String> {
    render_view_rays_case("view-rays", 1.25, 0.08, [0.7, 0.75, 0.8])
}

fn render_view_rays_dense_fog() -> Result<(), String> {
    render_view_rays_case("view-rays-dense-fog", 1.5, 0.3, [0.55, 0.6, 0.7])
}

/// examples/sources, tonemap (WESL: curves under module-scope @if blocks,
/// the method a feature each case turns on by enum value or def, stops and
/// bands from [source] modules) at 64 x 24: radiance 2^s tint, s = -4 +
/// 9 (x + 0.5) / 64, tint by band of 8 rows (1, 0.6, 0.3), (1, 1, 1),
/// (0.3, 0.6, 1); then Reinhard c / (1 + c), exponential 1 - e^-c or
/// Narkowicz's ACES fit c (2.51 c + 0.03) / (c (2.43 c + 0.59) + 0.14)
/// clamped to [0, 1]; alpha (4 curve + asked) / 16: the compiled curve's
/// index and the method param's (the ACES case turns the feature on by a
/// def and leaves the param at reinhard). Allowance: f16 storage plus
/// 1e-5 for f32 (exp2 within a few ulp of 2^5).
fn sources_tonemap_case(case: &str, method: &str, asked: f64) -> Result<(), String> {
    let (w, h, got) = texels(&render_case("sources", case)?)?;
    let (curve, id): (fn(f64) -> f64, f64) = match method {
        "reinhard" => (|c| c / (1.0 + c), 0.0),
        "exponential" => (|c| 1.0 - (-c).exp(), 1.0),
        _ => (|c| (c * (2.51 * c + 0.03) / (c * (2.43 * c + 0.59) + 0.14)).clamp(0.0, 1.0), 2.0),
    };
    let tints = [[1.0, 0.6, 0.3], [1.0, 1.0, 1.0], [0.3, 0.6, 1.0]];
    compare(case, w, &got, |x, y| {
        let s = -4.0 + 9.0 * (f64::from(x) + 0.5) / f64::from(w);
        let band = ((y * 3) / h).min(2) as usize;
        let c = tints[band].map(|t| curve(s.exp2() * t));
        let allow = c.map(|v| f16_rounding(v) + 1e-5);
        Some(([c[0], c[1], c[2], (4.0 * id + asked) / 16.0], [allow[0], allow[1], allow[2], 0.0]))
    })
    .map(|_| ())
}

fn sources_tonemap_reinhard() -> Result<(), String> {
    sources_tonemap_case("tonemap-reinhard", "reinhard", 0.0)
}

fn sources_tonemap_exponential() -> Result<(), String> {
    sources_tonemap_case("tonemap-exponential", "exponential", 1.0)
}

fn sources_tonemap_aces() -> Result<(), String> {
    sources_tonemap_case("tonemap-aces", "aces", 0.0)
}

/// examples/graphs, mip_chain: one rgba32float texture's levels 1, 2 and 3,
/// each its own output at its own size (32, 16, 8), each texel the mean of
/// the 2^k x 2^k block of the photo (16-bit PNG, v / 65535) under it: the
/// level by level 2 x 2 means are that block's mean. Allowance: f32 sums
/// of four (an ulp per level), 1e-6.
fn graphs_mip_chain() -> Result<(), String> {
    let source = vista_image::read_png16(&example("graphs/inputs/photo.png")).map_err(|e| e.to_string())?;
    let out = render_example("graphs", "mip_chain", 64, 64)?;
    for level in 1..=3u32 {
        let (w, h, got) = texels_named(&out, &format!("chain@{level}"))?;
        let side = 64 >> level;
        if (w, h) != (side, side) {
            return Err(format!("chain@{level} is {w}x{h}; want {side}x{side}"));
        }
        let block = 1usize << level;
        compare(&format!("mip_chain level {level}"), w, &got, |x, y| {
            let mut c = [0.0f64; 4];
            for by in 0..block {
                for bx in 0..block {
                    let t = source.data[(y as usize * block + by) * 64 + x as usize * block + bx];
                    (0..4).for_each(|k| c[k] += f64::from(t[k]));
                }
            }
            let n = (block * block) as f64;
            Some((c.map(|v| v / n), [1e-6; 4]))
        })?;
    }
    Ok(())
}

/// PCG hash (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT
/// 2020): one LCG step, then the RXS-M-XS output permutation.
fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Bilinear blend of four lattice values (a: (0, 0), b: (1, 0), c: (0, 1),
/// d: (1, 1)) by fade weights (tx, ty).
fn blend(a: f64, b: f64, c: f64, d: f64, tx: f64, ty: f64) -> f64 {
    let (x0, x1) = (a + (b - a) * tx, c + (d - c) * tx);
    x0 + (x1 - x0) * ty
}

/// examples/sources, cells (textual #include in four spellings) at 64 x
/// 48: value noise v at uv * cells, cells = 6, seed 7, over lattice values
/// (pcg(x ^ pcg(y ^ pcg(seed))) >> 8) / 2^24 (x, y the cell's i32 bits),
/// quintic fade; the texel (v, v^2, 1 - v, 1) in rgba8unorm. The hash is
/// exact in u32; the noise's f32 error is ~1e-6 (uv * 6 to an ulp of 6,
/// times the fade's slope <= 15/8), so one 8-bit step plus 1e-5.
fn sources_cells() -> Result<(), String> {
    let (cells, seed) = (6.0, 7u32);
    let lattice =
        |x: i64, y: i64| f64::from(pcg(x as i32 as u32 ^ pcg(y as i32 as u32 ^ pcg(seed))) >> 8) / 16_777_216.0;
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (w, h, got) = texels(&render_example("sources", "cells", 64, 48)?)?;
    let allowed = [UNORM8_STEP + 1e-5, UNORM8_STEP + 1e-5, UNORM8_STEP + 1e-5, 0.0];
    compare("cells", w, &got, |x, y| {
        let p = [cells * (f64::from(x) + 0.5) / f64::from(w), cells * (f64::from(y) + 0.5) / f64::from(h)];
        let (i, j) = (p[0].floor() as i64, p[1].floor() as i64);
        let (tx, ty) = (fade(p[0] - p[0].floor()), fade(p[1] - p[1].floor()));
        let v = blend(lattice(i, j), lattice(i + 1, j), lattice(i, j + 1), lattice(i + 1, j + 1), tx, ty);
        Some(([v, v * v, 1.0 - v, 1.0], allowed))
    })
    .map(|_| ())
}

/// Thomas Wang's 32-bit integer hash.
fn wang(v: u32) -> u32 {
    let mut x = (v ^ 61) ^ (v >> 16);
    x = x.wrapping_mul(9);
    x ^= x >> 4;
    x = x.wrapping_mul(0x27d4_eb2d);
    x ^ (x >> 15)
}

/// examples/sources, clouds_joined (noise library prepended, tone curves
/// appended, {OCTAVES} and {TONE} written in from params) at 64 x 48: fBm
/// n of `octaves` octaves of value noise (corner values wang(x +
/// wang(y)) & 0xffff over 65535, cubic Hermite fade), each octave at
/// 2 q + (17, 31) with half the amplitude, at q = 5 uv; cloud = (n - (1 -
/// coverage)) / coverage in [0, 1]; colour = tone(mix(sky(v), 1.2,
/// cloud)) 1.5, sky(v) = mix((0.25, 0.45, 0.8), (0.55, 0.7, 0.95), v),
/// in rgba8unorm (clamped to 1). Allowance: n's f32 error is ~1e-5 (the
/// lattice point q, up to ~350, to an ulp of 350 = 3e-5 times the fade's
/// slope 1.5, per octave amplitude), multiplied by at most 1 / coverage
/// (2.2, 3.3) times 1.5 times the curve's slope (<= 1): 2e-4 with the 8-bit step.
fn sources_clouds(octaves: u32, coverage: f64, tone: &str) -> Result<(), String> {
    let corner =
        |x: f64, y: f64| f64::from(wang((x as i32 as u32).wrapping_add(wang(y as i32 as u32))) & 0xffff) / 65535.0;
    let smooth = |t: f64| t * t * (3.0 - 2.0 * t);
    let fbm = |mut q: [f64; 2]| {
        let (mut sum, mut amp) = (0.0, 0.5);
        for _ in 0..octaves {
            let (i, j) = (q[0].floor(), q[1].floor());
            let (tx, ty) = (smooth(q[0] - i), smooth(q[1] - j));
            sum += amp * blend(corner(i, j), corner(i + 1.0, j), corner(i, j + 1.0), corner(i + 1.0, j + 1.0), tx, ty);
            q = [2.0 * q[0] + 17.0, 2.0 * q[1] + 31.0];
            amp *= 0.5;
        }
        sum
    };
    let curve = |c: f64| match tone {
        "reinhard" => c / (1.0 + c),
        _ => 1.0 - (-c).exp(),
    };
    let set = [("octaves", &octaves.to_string()[..]), ("coverage", &coverage.to_string()[..]), ("tone", tone)];
    let (w, h, got) = texels(&render_example_with("sources", "clouds_joined", &set, 64, 48)?)?;
    let allowed = [UNORM8_STEP + 2e-4, UNORM8_STEP + 2e-4, UNORM8_STEP + 2e-4, 0.0];
    compare(&format!("clouds_joined ({octaves} octaves, {tone})"), w, &got, |x, y| {
        let (u, v) = ((f64::from(x) + 0.5) / f64::from(w), (f64::from(y) + 0.5) / f64::from(h));
        let n = fbm([5.0 * u, 5.0 * v]);
        let cloud = ((n - (1.0 - coverage)) / coverage.max(1e-3)).clamp(0.0, 1.0);
        let sky = [0.25 + 0.30 * v, 0.45 + 0.25 * v, 0.8 + 0.15 * v];
        let c = sky.map(|s| (1.5 * curve(s + (1.2 - s) * cloud)).clamp(0.0, 1.0));
        Some(([c[0], c[1], c[2], 1.0], allowed))
    })
    .map(|_| ())
}

fn sources_clouds_joined() -> Result<(), String> {
    sources_clouds(5, 0.45, "reinhard")
}

/// The same kernel with {OCTAVES} = 2 and {TONE} = exponential from params:
/// a module of its own.
fn sources_clouds_joined_thin_exponential() -> Result<(), String> {
    sources_clouds(2, 0.3, "exponential")
}

/// pcg2d (Jarzynski and Olano 2020): a 2 x 32-bit LCG step with the lanes
/// mixed, twice, with xorshift 16.
fn pcg2d(v: [u32; 2]) -> [u32; 2] {
    let mut v = v.map(|c| c.wrapping_mul(1_664_525).wrapping_add(1_013_904_223));
    v[0] = v[0].wrapping_add(v[1].wrapping_mul(1_664_525));
    v[1] = v[1].wrapping_add(v[0].wrapping_mul(1_664_525));
    v = v.map(|c| c ^ (c >> 16));
    v[0] = v[0].wrapping_add(v[1].wrapping_mul(1_664_525));
    v[1] = v[1].wrapping_add(v[0].wrapping_mul(1_664_525));
    v.map(|c| c ^ (c >> 16))
}

/// examples/sources, relief (WESL: package and second-package imports,
/// @if(SNOW) from a bool def) at 64 x 48: elevation h = four octaves of
/// value noise (lattice (pcg2d(cell bits + (seed, 0)).x >> 8) / 2^24,
/// smoothstep fade, doubling frequency, halving amplitude from 0.5) over
/// 0.9375, at 4 uv, seed 3; colour = mix(ramp(h), (0.95, 0.96, 1),
/// smoothstep(0.68, 0.78, h)), ramp(h) = mix((0.12, 0.32, 0.1), (0.45,
/// 0.36, 0.27), h), in rgba8unorm. Allowance: h's f32 error is ~2e-6, the
/// snow blend's slope is at most 15 per unit of h: 1e-4 with the 8-bit step.
fn sources_relief() -> Result<(), String> {
    let (scale, seed) = (4.0, 3u32);
    let lattice = |x: f64, y: f64| {
        let cell = [x as i32 as u32, y as i32 as u32];
        f64::from(pcg2d([cell[0].wrapping_add(seed), cell[1]])[0] >> 8) / 16_777_216.0
    };
    let elevation = |p: [f64; 2]| {
        let (mut sum, mut amp, mut q) = (0.0, 0.5, p);
        for _ in 0..4 {
            let (i, j) = (q[0].floor(), q[1].floor());
            let (tx, ty) = (smoothstep(0.0, 1.0, q[0] - i), smoothstep(0.0, 1.0, q[1] - j));
            sum +=
                amp * blend(lattice(i, j), lattice(i + 1.0, j), lattice(i, j + 1.0), lattice(i + 1.0, j + 1.0), tx, ty);
            q = q.map(|c| 2.0 * c);
            amp *= 0.5;
        }
        sum / 0.9375
    };
    let (low, high, snow) = ([0.12, 0.32, 0.1], [0.45, 0.36, 0.27], [0.95, 0.96, 1.0]);
    let (w, h, got) = texels(&render_example("sources", "relief", 64, 48)?)?;
    let allowed = [UNORM8_STEP + 1e-4, UNORM8_STEP + 1e-4, UNORM8_STEP + 1e-4, 0.0];
    let snowy = std::cell::Cell::new(0);
    compare("relief", w, &got, |x, y| {
        let (u, v) = ((f64::from(x) + 0.5) / f64::from(w), (f64::from(y) + 0.5) / f64::from(h));
        let e = elevation([scale * u, scale * v]);
        let s = smoothstep(0.68, 0.78, e);
        snowy.set(snowy.get() + usize::from(s > 0.5));
        let c: [f64; 3] = std::array::from_fn(|k| {
            let ramp = low[k] + (high[k] - low[k]) * e.clamp(0.0, 1.0);
            ramp + (snow[k] - ramp) * s
        });
        Some(([c[0], c[1], c[2], 1.0], allowed))
    })?;
    // Not vacuous for @if(SNOW): some texels are snow.
    match snowy.get() > 0 {
        true => Ok(()),
        false => Err("relief: no texel above the snow line; the check says nothing of @if(SNOW)".into()),
    }
}

/// One reference check: Ok, or what differs from the math.
type Check = fn() -> Result<(), String>;

fn main() {
    let args = Arguments::from_args();
    let no_gpu = match args.list {
        true => None,
        false => vista_gpu::Context::shared(&common::config().gpu).err().map(|e| e.to_string()),
    };
    let skip = no_gpu.is_some() && allow_no_gpu();
    let tests: [(&str, Check); 21] = [
        ("references::graphs::mip_chain", graphs_mip_chain),
        ("references::graphs::row_offsets", graphs_row_offsets),
        ("references::harness_crate::glow", harness_crate_glow),
        ("references::project::marble", project_marble),
        ("references::real_kernels::mandelbrot", real_kernels_mandelbrot),
        ("references::render::bloom", render_bloom),
        ("references::render::grass", render_grass),
        ("references::render::sky_fullscreen_fisheye", render_sky_fisheye),
        ("references::render::sky_fullscreen_latlong", render_sky_latlong),
        ("references::render::view_rays", render_view_rays),
        ("references::render::view_rays_dense_fog", render_view_rays_dense_fog),
        ("references::sources::blur", sources_blur),
        ("references::sources::cells", sources_cells),
        ("references::sources::clouds_joined", sources_clouds_joined),
        ("references::sources::clouds_joined_thin_exponential", sources_clouds_joined_thin_exponential),
        ("references::sources::mips", sources_mips),
        ("references::sources::relief", sources_relief),
        ("references::sources::tonemap_aces", sources_tonemap_aces),
        ("references::sources::tonemap_exponential", sources_tonemap_exponential),
        ("references::sources::tonemap_reinhard", sources_tonemap_reinhard),
        ("references::sources::transmittance", sources_transmittance),
    ];
    if let Some(e) = no_gpu.as_ref().filter(|_| skip) {
        let n = tests.len();
        eprintln!(
            "\n!!! VISTA_ALLOW_NO_GPU=1 and no adapter: {e}\n!!! SKIPPED {n} reference tests (reported ignored)\n"
        );
    }
    let trials = tests
        .into_iter()
        .map(|(name, f)| Trial::test(name, move || f().map_err(Into::into)).with_ignored_flag(skip))
        .collect();
    libtest_mimic::run(&args, trials).exit()
}
