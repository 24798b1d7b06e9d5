// Unit tests of vista::fractal (`vista test`). Expected values computed in
// f64 (Python's math module) from SPEC 3.2 and 3.3: fBm f = sum_i gain^i
// N(p_i, z), p_{i+1} = lacunarity R(theta) p_i (R the counter-clockwise
// rotation), A = sum_i gain^i; Musgrave's ridged multifractal, signal =
// (offset - |N(p)|)^2, then for i >= 1 p *= lacunarity, weight =
// clamp(signal gain, 0, 1), signal = (offset - |N(p)|)^2 weight, result +=
// signal lacunarity^(-i H); its bound max(offset, M - offset)^2 sum_i
// lacunarity^(-i H) with M = PERLIN_MAX_ABS (1.0364 as an f32). The bases
// N: Improved Noise (Perlin 2002) written from its published reference
// (seed-0 table), value noise from pcg3d as published (JCGT 2020), as in
// noise.test.wgsl. Points and non-dyadic settings are taken at their f32
// values (what the shader receives).
//
// Bases by their index in kernels/fbm.toml: perlin 0, value 1.
#import vista::fractal::{FbmSettings, RidgedSettings, fbm_amplitude, fbm2, ridged_max, ridged2}
#import wgsl_test::{expectNear}

// No octave rotation (cos 1, sin 0).
fn fbm_settings(basis: u32, seed: u32, octaves: u32, lacunarity: f32, gain: f32) -> FbmSettings {
    return FbmSettings(basis, seed, octaves, lacunarity, gain, 1.0, 0.0);
}

@test
fn fbm_amplitude_sums_the_octave_gains() {
    // sum_{i < n} gain^i: (8, 0.5) 2 - 2^-7, (5, 0.8) (1 - 0.8^5) / 0.2,
    // (3, 0.6) 1 + 0.6 + 0.36, one octave 1, no octave 0.
    expectNear(fbm_amplitude(8u, 0.5), 1.9921875);
    expectNear(fbm_amplitude(5u, 0.8), 3.3616000000000006);
    expectNear(fbm_amplitude(3u, 0.6), 1.960000052452088);
    expectNear(fbm_amplitude(1u, 0.7), 1.0, 0.0);
    expectNear(fbm_amplitude(0u, 0.5), 0.0, 0.0);
}

@test
fn fbm2_of_one_octave_is_the_basis() {
    // SPEC 3.2's invariant: perlin(0.3, 0.7, 0) and value(-1.6, 2.35, 0), seed 5.
    expectNear(fbm2(fbm_settings(0u, 0u, 1u, 2.0, 0.5), vec2<f32>(0.3, 0.7), 0.0), -0.11415600909590728);
    expectNear(fbm2(fbm_settings(1u, 5u, 1u, 2.0, 0.5), vec2<f32>(-1.6, 2.35), 0.0), 0.004827352223670797);
}

@test
fn fbm2_sums_the_octaves() {
    // Perlin, 4 octaves, lacunarity 2, gain 0.5 at (0.3, 0.7), z = 0.
    expectNear(fbm2(fbm_settings(0u, 0u, 4u, 2.0, 0.5), vec2<f32>(0.3, 0.7), 0.0), 0.004784572602905384);
    // Perlin, 5 octaves off the integer plane: (4.2, 0.15), z = 0.5.
    expectNear(fbm2(fbm_settings(0u, 0u, 5u, 2.0, 0.5), vec2<f32>(4.2, 0.15), 0.5), 0.27668090743799717);
    // Value noise, seed 5, 4 octaves at (-1.6, 2.35).
    expectNear(fbm2(fbm_settings(1u, 5u, 4u, 2.0, 0.5), vec2<f32>(-1.6, 2.35), 0.0), -0.3658603387207868);
}

@test
fn fbm2_rotates_each_octave() {
    // theta = 30 degrees, lacunarity 1.9, gain 0.6, 6 octaves of Perlin at
    // (1.37, -2.81): p_{i+1} = 1.9 (x cos - y sin, x sin + y cos).
    let s = FbmSettings(0u, 0u, 6u, 1.9, 0.6, 0.8660254037844387, 0.5);
    expectNear(fbm2(s, vec2<f32>(1.37, -2.81), 0.0), -0.10905164739892734);
}

@test
fn ridged_max_bounds_the_sum() {
    // offset 1, H 1, lacunarity 2, 8 octaves: max(1, 0.0364)^2 (2 - 2^-7).
    expectNear(ridged_max(RidgedSettings(0u, 0u, 8u, 2.0, 1.0, 1.0, 2.0)), 1.9921875);
    // offset 0.4, H 0.8, 4 octaves: (M - 0.4)^2 sum_{i < 4} 2^(-0.8 i).
    expectNear(ridged_max(RidgedSettings(0u, 0u, 4u, 2.0, 0.8, 0.4, 2.0)), 0.8479550016084817);
    // One octave: the peak alone.
    expectNear(ridged_max(RidgedSettings(1u, 3u, 1u, 2.0, 1.0, 1.0, 2.0)), 1.0);
}

@test
fn ridged2_of_one_octave_is_the_squared_ridge() {
    // SPEC 3.3's invariant: (1 - |perlin(0.3, 0.7, 0)|)^2.
    expectNear(ridged2(RidgedSettings(0u, 0u, 1u, 2.0, 1.0, 1.0, 2.0), vec2<f32>(0.3, 0.7), 0.0), 0.7847195762208903);
}

@test
fn ridged2_weights_each_octave_by_the_last() {
    // Perlin, 6 octaves, lacunarity 2, H 1, offset 1, gain 2 (SPEC 3.3's
    // defaults) at (1.37, -2.81).
    expectNear(ridged2(RidgedSettings(0u, 0u, 6u, 2.0, 1.0, 1.0, 2.0), vec2<f32>(1.37, -2.81), 0.0), 1.3223082383923492);
    // Value noise, seed 5, 4 octaves, H 0.8, offset 0.9, gain 1.5 at (-1.6, 2.35).
    expectNear(ridged2(RidgedSettings(1u, 5u, 4u, 2.0, 0.8, 0.9, 1.5), vec2<f32>(-1.6, 2.35), 0.0), 0.9302361749281455);
}
