// Test-only kernel: writes NaN at (5, 3) and +Inf at (7, 3), 0.5 elsewhere,
// so tests can prove that non-finite output fails a case and names the pixel.
struct Params {
    width: u32,
    height: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    // Runtime zero (from the uniform) so nothing is folded at compile time.
    let zero = f32(params.width) - f32(params.width);
    var v = 0.5;
    if id.x == 5u && id.y == 3u {
        v = zero / zero;
    } else if id.x == 7u && id.y == 3u {
        v = 1.0 / zero;
    }
    textureStore(output, id.xy, vec4(v, v, v, 1.0));
}
