//! clouds (SPEC 3.6) on the GPU: against the f64 CPU reference, the
//! invariants that need a render, and the seed experiment of SPEC 7/8.

mod common;

use vista_image::Image;
use vista_image::metrics::{hdr_peak, psnr_with_peak};
use vista_kernels::ParamSet;
use vista_kernels::clouds::CloudsKernel;
use vista_render::render;

fn params(preset: &str, set: &[(&str, &str)]) -> ParamSet {
    common::params(&CloudsKernel, Some(preset), set)
}

fn gpu(ctx: &vista_render::Renderer, p: &ParamSet, w: u32, h: u32) -> Image {
    render(ctx, &CloudsKernel, p, w, h).expect("render").into_raw()
}

/// Coverage 0: exactly the background (bit for bit) and alpha exactly 0.
fn zero_coverage_is_exactly_the_background(ctx: &vista_render::Renderer) {
    let sky = [0.3f32, 0.5, 0.9];
    for preset in ["clear", "cumulus", "cumulonimbus"] {
        let p = params(preset, &[("coverage", "0"), ("sky_zenith", "0.3,0.5,0.9"), ("sky_horizon", "0.3,0.5,0.9")]);
        let img = gpu(ctx, &p, 32, 32);
        for (i, px) in img.data.iter().enumerate() {
            assert!(
                px[..3] == sky[..] && px[3] == 0.0,
                "clouds {preset} coverage 0: pixel {i} = {px:?}, want {sky:?} with alpha 0"
            );
        }
    }
    // With the sky gradient: equal to the CPU background to f32 rounding.
    let p = params("cumulus", &[("coverage", "0")]);
    let img = gpu(ctx, &p, 32, 32);
    let c = vista_kernels::clouds::Clouds::from_params(&p);
    for y in 0..32 {
        for x in 0..32 {
            let bg = c.background(c.ray(x, y, 32, 32).1);
            let g = img.get(x, y);
            for ch in 0..3 {
                assert!((g[ch] as f64 - bg[ch]).abs() < 1e-6, "({x}, {y}) ch {ch}: {} vs {}", g[ch], bg[ch]);
            }
            assert_eq!(g[3], 0.0);
        }
    }
}

/// Doubling density_scale never raises T: alpha = 1 - T never falls.
fn doubling_density_never_raises_transmittance(ctx: &vista_render::Renderer) {
    for (preset, d) in [("cumulus", "40"), ("cirrostratus", "0.25"), ("stratocumulus", "4")] {
        let d2 = (d.parse::<f64>().unwrap() * 2.0).to_string();
        let a = gpu(ctx, &params(preset, &[("density_scale", d)]), 40, 40);
        let b = gpu(ctx, &params(preset, &[("density_scale", &d2)]), 40, 40);
        let mut raised = 0;
        for (pa, pb) in a.data.iter().zip(&b.data) {
            // 1e-6: slack for a non-monotone f32 exp in the driver.
            if pb[3] < pa[3] - 1e-6 {
                raised += 1;
            }
        }
        let mean = |img: &Image| img.data.iter().map(|p| p[3] as f64).sum::<f64>() / img.data.len() as f64;
        eprintln!("clouds {preset}: mean alpha {:.4} at density {d}, {:.4} at {d2}", mean(&a), mean(&b));
        assert_eq!(raised, 0, "clouds {preset}: {raised} pixels gained transmittance when density doubled");
        assert!(mean(&b) > mean(&a) + 0.01, "clouds {preset}: doubling density barely changed alpha");
    }
}

/// With the sun behind the camera the backward lobe keeps clouds lit.
fn dual_lobe_hg_is_brighter_than_single_lobe_with_the_sun_behind(ctx: &vista_render::Renderer) {
    let sun_behind = [("sun_azimuth_deg", "180"), ("sun_elevation_deg", "30"), ("yaw_deg", "0")];
    let dual = gpu(ctx, &params("cumulus", &[&sun_behind[..], &[("phase_blend", "0.5")]].concat()), 40, 40);
    let single = gpu(ctx, &params("cumulus", &[&sun_behind[..], &[("phase_blend", "0")]].concat()), 40, 40);
    let (mut sum_dual, mut sum_single, mut n) = (0.0, 0.0, 0);
    for (d, s) in dual.data.iter().zip(&single.data) {
        if d[3] > 0.5 {
            let lum = |p: &[f32; 4]| (p[0] + p[1] + p[2]) as f64;
            sum_dual += lum(d);
            sum_single += lum(s);
            n += 1;
            assert!(lum(d) >= lum(s) - 1e-5, "a cloudy pixel got darker with the backward lobe: {d:?} vs {s:?}");
        }
    }
    assert!(n > 100, "too few cloudy pixels ({n}) for the comparison");
    let ratio = sum_dual / sum_single;
    eprintln!("clouds dual/single-lobe brightness over {n} cloudy pixels: {ratio:.3}");
    assert!(ratio > 1.1, "dual-lobe HG only {ratio:.3}x as bright as single-lobe with the sun behind");
}

fn renders_are_deterministic_and_jitter_follows_its_seed(ctx: &vista_render::Renderer) {
    let (w, h) = (32, 32);
    let none = params("cumulus", &[]);
    assert!(gpu(ctx, &none, w, h).bit_identical(&gpu(ctx, &none, w, h)), "jitter none: renders differ");
    let ign = params("cumulus", &[("jitter", "ign"), ("jitter_seed", "3")]);
    assert!(gpu(ctx, &ign, w, h).bit_identical(&gpu(ctx, &ign, w, h)), "ign seed 3: renders differ");
    let white = |seed: &str| gpu(ctx, &params("cumulus", &[("jitter", "white"), ("jitter_seed", seed)]), w, h);
    let (a, b) = (white("1"), white("2"));
    let differ = a.data.iter().zip(&b.data).filter(|(p, q)| p != q).count();
    assert!(differ > (w * h / 4) as usize, "white jitter seed 1 vs 2: only {differ} pixels differ");
    let ign2 = params("cumulus", &[("jitter", "ign"), ("jitter_seed", "4")]);
    assert!(!gpu(ctx, &ign2, w, h).bit_identical(&gpu(ctx, &ign, w, h)), "ign seed 3 vs 4: identical");
}

/// The seed experiment (SPEC 7/8) with the candidates rendered on the GPU;
/// the 512 x 32 reference comes from the f64 CPU march (the same march,
/// 10x faster than lavapipe here). The full-size version is the CPU test
/// `seed_experiment_analytic_ign_at_half_the_steps_beats_riemann_64x12`.
fn seed_experiment_on_the_gpu(ctx: &vista_render::Renderer) {
    let (w, h) = (48, 48);
    let mut hq: Vec<(&str, &str)> = CloudsKernel.high_quality();
    hq.push(("jitter", "none"));
    let reference = CloudsKernel.reference(&params("cumulus", &hq), w, h);
    let peak = hdr_peak(&reference);
    let base = gpu(ctx, &params("cumulus", &[("steps", "64"), ("light_steps", "12")]), w, h);
    let fast_p =
        params("cumulus", &[("integrator", "analytic"), ("jitter", "ign"), ("steps", "32"), ("light_steps", "6")]);
    let fast = gpu(ctx, &fast_p, w, h);
    let (pb, pf) = (psnr_with_peak(&reference, &base, peak), psnr_with_peak(&reference, &fast, peak));
    eprintln!(
        "clouds seed experiment on the GPU ({w}x{h}): riemann/none 64x12 {pb:.2} dB, analytic/ign 32x6 {pf:.2} dB"
    );
    assert!(pf >= pb, "GPU analytic/ign 32x6 ({pf:.2} dB) less close than riemann/none 64x12 ({pb:.2} dB)");
    // That the GPU candidate is the CPU candidate up to f32 rounding is
    // tests/agreement.rs's (the same setting, 120.5 dB against 110).
}

/// On the GPU coverage_oktas = n is exactly the preset's table entry for n
/// (the WGSL looks it up; CPU tests check what the table means).
fn coverage_oktas_reads_the_presets_table_on_the_gpu(ctx: &vista_render::Renderer) {
    for (preset, n) in [("cumulus", 0), ("cumulus", 3), ("stratocumulus", 6), ("cirrus", 8)] {
        let p = params(preset, &[("coverage_oktas", &n.to_string())]);
        let table = [p.vector("okta_coverage_low"), p.vector("okta_coverage_high")].concat();
        let coverage = if n == 0 { 0.0 } else { table[n - 1] };
        let by_oktas = gpu(ctx, &p, 48, 48);
        let direct = gpu(ctx, &params(preset, &[("coverage", &format!("{coverage}"))]), 48, 48);
        assert!(by_oktas.data == direct.data, "{preset} {n} oktas differs from coverage = {coverage}");
        let cloudy = by_oktas.data.iter().filter(|px| px[3] > 0.01).count();
        assert_eq!(cloudy == 0, n == 0, "{preset} {n} oktas: {cloudy} cloudy pixels");
    }
}

fn main() {
    common::gpu_tests![
        coverage_oktas_reads_the_presets_table_on_the_gpu,
        zero_coverage_is_exactly_the_background,
        doubling_density_never_raises_transmittance,
        dual_lobe_hg_is_brighter_than_single_lobe_with_the_sun_behind,
        renders_are_deterministic_and_jitter_follows_its_seed,
        seed_experiment_on_the_gpu,
    ];
}
