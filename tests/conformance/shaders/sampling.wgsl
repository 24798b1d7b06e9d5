// Sampler filtering and addressing: a 4 x 4 rgba16float texture written
// from its texel coordinates (r = x/8 + y/2, g = x, b = y, a = 1), then
// sampled at fixed coordinates, inside and outside [0, 1], by six samplers
// (nearest and linear, each clamp-to-edge, repeat and mirror-repeat).
// expected.py computes each sample in f64 as WebGPU defines filtering;
// every coordinate puts the linear weights on multiples of 1/16.

@group(0) @binding(0) var grid_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(4, 4)
fn write_grid(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = f32(id.x);
    let y = f32(id.y);
    textureStore(grid_out, vec2<i32>(id.xy), vec4<f32>(x / 8.0 + y / 2.0, x, y, 1.0));
}

@group(0) @binding(0) var grid: texture_2d<f32>;
@group(0) @binding(1) var nearest_clamp: sampler;
@group(0) @binding(2) var nearest_repeat: sampler;
@group(0) @binding(3) var nearest_mirror: sampler;
@group(0) @binding(4) var linear_clamp: sampler;
@group(0) @binding(5) var linear_repeat: sampler;
@group(0) @binding(6) var linear_mirror: sampler;
@group(1) @binding(0) var<storage, read_write> samples: array<vec4<f32>>;

// u and v in 64ths.
const COORDS = array<vec2<f32>, 8>(
    vec2<f32>(8.0, 8.0), vec2<f32>(20.0, 28.0), vec2<f32>(-12.0, 84.0), vec2<f32>(68.0, -28.0),
    vec2<f32>(148.0, 36.0), vec2<f32>(-90.0, -70.0), vec2<f32>(63.0, 1.0), vec2<f32>(200.0, 130.0),
);

@compute @workgroup_size(1)
fn sample_grid() {
    for (var i = 0u; i < 8u; i++) {
        let uv = COORDS[i] / 64.0;
        samples[i * 6u + 0u] = textureSampleLevel(grid, nearest_clamp, uv, 0.0);
        samples[i * 6u + 1u] = textureSampleLevel(grid, nearest_repeat, uv, 0.0);
        samples[i * 6u + 2u] = textureSampleLevel(grid, nearest_mirror, uv, 0.0);
        samples[i * 6u + 3u] = textureSampleLevel(grid, linear_clamp, uv, 0.0);
        samples[i * 6u + 4u] = textureSampleLevel(grid, linear_repeat, uv, 0.0);
        samples[i * 6u + 5u] = textureSampleLevel(grid, linear_mirror, uv, 0.0);
    }
}
