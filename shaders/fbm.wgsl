// fbm kernel (SPEC 3.2): R = G = B = 0.5 + 0.5 f / A, alpha = 1.
// Params are packed by name from kernels/fbm.toml; everything derived from
// them (the octave rotation's cos/sin, the normaliser A) is computed here.
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
    offset: vec2<f32>,
    octave_rotation_deg: f32,
    z_slice: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(f32(params.width), f32(params.height));
    let theta = radians(params.octave_rotation_deg);
    let settings = FbmSettings(params.basis, params.seed, params.octaves, params.lacunarity,
                               params.gain, cos(theta), sin(theta));
    let p0 = params.frequency * uv + params.offset;
    let f = fbm2(settings, p0, params.z_slice);
    let value = 0.5 + 0.5 * f / fbm_amplitude(params.octaves, params.gain);
    textureStore(output, id.xy, vec4(value, value, value, 1.0));
}
