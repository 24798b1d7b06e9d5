//! Every example project checked against a reference written from the
//! math, not from its golden (SPEC 18): a change to vista's host layer
//! that moves a result is caught here even where `bless` and `check` agree
//! with each other. Each reference is computed in f64 (or exactly, for
//! integers) from the formula the example's shader documents; the WGSL is
//! not transliterated.

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
    let ctx = vista_gpu::Context::shared(&common::config().gpu).map_err(|e| e.to_string())?;
    common::render_in_project(ctx, &example(name), kernel, &[], (width, height))
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

/// One reference check: Ok, or what differs from the math.
type Check = fn() -> Result<(), String>;

fn main() {
    let args = Arguments::from_args();
    let no_gpu = match args.list {
        true => None,
        false => vista_gpu::Context::shared(&common::config().gpu).err().map(|e| e.to_string()),
    };
    let skip = no_gpu.is_some() && allow_no_gpu();
    if let Some(e) = no_gpu.as_ref().filter(|_| skip) {
        eprintln!("\n!!! VISTA_ALLOW_NO_GPU=1 and no adapter: {e}\n!!! SKIPPED 3 reference tests (reported ignored)\n");
    }
    let tests: [(&str, Check); 3] = [
        ("references::graphs::row_offsets", graphs_row_offsets),
        ("references::harness_crate::glow", harness_crate_glow),
        ("references::real_kernels::mandelbrot", real_kernels_mandelbrot),
    ];
    let trials = tests
        .into_iter()
        .map(|(name, f)| Trial::test(name, move || f().map_err(Into::into)).with_ignored_flag(skip))
        .collect();
    libtest_mimic::run(&args, trials).exit()
}
