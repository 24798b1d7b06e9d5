// Fractal sums over a basis: fBm (SPEC 3.2), ridged multifractal (SPEC 3.3).
// (The clouds kernel sums its 3D fBm itself, to stop early; see clouds.wgsl.)
#define_import_path vista::fractal

#import vista::noise::{slice_noise, PERLIN_MAX_ABS}

struct FbmSettings {
    basis: u32,
    seed: u32,
    octaves: u32,
    lacunarity: f32,
    gain: f32,
    rot_cos: f32,
    rot_sin: f32,
}

// A = sum_{i < octaves} gain^i, the fBm amplitude normaliser (SPEC 3.2).
fn fbm_amplitude(octaves: u32, gain: f32) -> f32 {
    var sum = 0.0;
    var amplitude = 1.0;
    for (var i = 0u; i < octaves; i++) {
        sum += amplitude;
        amplitude *= gain;
    }
    return sum;
}

// f(p) = sum_i gain^i N(p_i, z), p_{i+1} = lacunarity * R(theta) * p_i.
fn fbm2(s: FbmSettings, p0: vec2<f32>, z: f32) -> f32 {
    let rot = mat2x2<f32>(s.rot_cos, s.rot_sin, -s.rot_sin, s.rot_cos);
    var p = p0;
    var amplitude = 1.0;
    var sum = 0.0;
    for (var i = 0u; i < s.octaves; i++) {
        sum += amplitude * slice_noise(s.basis, s.seed, vec3(p, z));
        amplitude *= s.gain;
        p = s.lacunarity * (rot * p);
    }
    return sum;
}

struct RidgedSettings {
    basis: u32,
    seed: u32,
    octaves: u32,
    lacunarity: f32,
    h: f32,
    offset: f32,
    gain: f32,
}

// The largest value ridged2 can reach: with |N| <= PERLIN_MAX_ABS (a bound
// for both bases) each signal is at most max(offset, M - offset)^2 and each
// weight at most 1, so max = that square times sum_i lacunarity^(-i H).
fn ridged_max(s: RidgedSettings) -> f32 {
    let peak = max(s.offset, PERLIN_MAX_ABS - s.offset);
    var weights = 0.0;
    for (var i = 0u; i < s.octaves; i++) {
        weights += pow(s.lacunarity, -f32(i) * s.h);
    }
    return peak * peak * weights;
}

// Musgrave: each octave's squared ridge signal is weighted by the previous
// signal (clamped feedback) and by lacunarity^(-i H).
fn ridged2(s: RidgedSettings, p0: vec2<f32>, z: f32) -> f32 {
    var p = p0;
    var signal = s.offset - abs(slice_noise(s.basis, s.seed, vec3(p, z)));
    signal *= signal;
    var result = signal;
    for (var i = 1u; i < s.octaves; i++) {
        p *= s.lacunarity;
        let weight = clamp(signal * s.gain, 0.0, 1.0);
        let ridge = s.offset - abs(slice_noise(s.basis, s.seed, vec3(p, z)));
        signal = ridge * ridge * weight;
        result += signal * pow(s.lacunarity, -f32(i) * s.h);
    }
    return result;
}
