// cloudmap kernel: Hugo Elias's cloud map (seed 004). n = 0.5 + 0.5 f / A
// from the fBm of SPEC 3.2 at z = time, clamped to [0, 1]; density
// d = 1 - sharpness^(255 max(n - cover, 0)); R = G = B = d, alpha = 1.
// Params are packed by name from kernels/cloudmap.toml.
#import vista::fractal::{FbmSettings, fbm2, fbm_amplitude}

struct Params {
    width: u32,
    height: u32,
    basis: u32,
    octaves: u32,
    seed: u32,
    lacunarity: f32,
    gain: f32,
    frequency: f32,
    cover: f32,
    sharpness: f32,
    time: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(f32(params.width), f32(params.height));
    let settings = FbmSettings(params.basis, params.seed, params.octaves, params.lacunarity, params.gain, 1.0, 0.0);
    let f = fbm2(settings, params.frequency * uv, params.time);
    // Perlin's |N| reaches 1.0364, so n can leave [0, 1] by a hair.
    let n = clamp(0.5 + 0.5 * f / fbm_amplitude(params.octaves, params.gain), 0.0, 1.0);
    let d = 1.0 - pow(params.sharpness, 255.0 * max(n - params.cover, 0.0));
    textureStore(output, id.xy, vec4(d, d, d, 1.0));
}
