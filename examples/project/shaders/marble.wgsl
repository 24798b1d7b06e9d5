// marble: Perlin-bent sine veins. Every field of Params is a param of
// kernels/marble.toml (plus width and height); vista packs them by name.
#import vista::noise::perlin

struct Params {
    width: u32,
    height: u32,
    stripes: f32,
    turbulence: f32,
    scale: f32,
    z: f32,
    base: vec3<f32>,
    vein: vec3<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(f32(params.width), f32(params.height));
    let bend = params.turbulence * perlin(vec3(params.scale * uv, params.z));
    let v = 0.5 + 0.5 * sin(6.283185307 * (params.stripes * uv.x + bend));
    textureStore(output, id.xy, vec4(mix(params.vein, params.base, v), 1.0));
}
