//! The f32 build of the CPU references (`vista_kernels::cpu32`, the
//! throughput baseline of `cargo bench --bench kernels`) computes the same
//! images as the f64 oracles: every preset of every kernel, within the bars
//! the GPU itself must meet against the oracle (display PSNR >= 70 dB; the
//! raw output of display kernels whose reference is the shader's algorithm
//! (the noise fields) within 1e-4). Also checks that it really is a
//! different build.

use vista_image::metrics::psnr;
use vista_kernels::Output;

/// Small: the f64 heightfield oracle (a brute-force march) is the slow one.
const SIZE: (u32, u32) = (32, 20);

#[test]
fn f32_build_matches_the_f64_oracle_on_every_preset() {
    let mut failures = vec![];
    for k in vista_kernels::registry() {
        let (w, h) = SIZE;
        // Fields are compared raw; kernels with hits or HDR radiance by display PSNR only.
        let field =
            k.output() == Output::Display && k.shader_algorithm_f32(&k.resolve(None, &[]).unwrap(), 1, 1).is_none();
        for preset in k.presets() {
            let p = k.resolve(Some(&preset.name), &[]).expect("presets are valid");
            let (r64, r32) = (k.reference(&p, w, h), k.reference_f32(&p, w, h));
            let nonfinite = r32.nonfinite_count();
            let max_abs = vista_image::metrics::max_abs(&r64, &r32);
            let db = psnr(&k.display(&r64, &p), &k.display(&r32, &p));
            eprintln!("{} {}: f32 vs f64 display PSNR {db:.1} dB, raw max |diff| {max_abs:.2e}", k.name(), preset.name);
            if nonfinite > 0 || db < 70.0 || (field && max_abs > 1e-4) {
                failures.push(format!(
                    "{} {}: {nonfinite} non-finite, PSNR {db:.1} dB, max |diff| {max_abs:.2e}",
                    k.name(),
                    preset.name
                ));
            }
        }
    }
    assert!(failures.is_empty(), "f32 build differs from the f64 oracle:\n{}", failures.join("\n"));
}

#[test]
fn f32_build_is_a_separate_f32_computation() {
    // Its width is checked by a unit test of the private f32 build. f32 rounding shows in the output: reference_f32 is not the f64 image.
    for name in ["fbm", "atmosphere"] {
        let k = vista_kernels::find(name).unwrap();
        let p = k.resolve(None, &[]).unwrap();
        assert!(!k.reference(&p, 32, 16).bit_identical(&k.reference_f32(&p, 32, 16)), "{name}");
    }
}
