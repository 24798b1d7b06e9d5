// ridged kernel (SPEC 3.3): Musgrave's ridged multifractal / its analytic maximum.
// Params are packed by name from kernels/ridged.toml; the normaliser is computed here.
#import vista::fractal::{RidgedSettings, ridged2, ridged_max}

struct Params {
    width: u32,
    height: u32,
    basis: u32,
    octaves: u32,
    seed: u32,
    lacunarity: f32,
    h: f32,
    offset: f32,
    gain: f32,
    frequency: f32,
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
    let settings = RidgedSettings(params.basis, params.seed, params.octaves, params.lacunarity,
                                  params.h, params.offset, params.gain);
    let value = ridged2(settings, params.frequency * uv, params.z_slice) / ridged_max(settings);
    textureStore(output, id.xy, vec4(value, value, value, 1.0));
}
