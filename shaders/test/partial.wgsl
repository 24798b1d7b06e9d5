// Test-only kernel: writes (1, y, x, 1) to the columns x < cut and nothing
// elsewhere, so tests can prove that an unwritten pixel reads 0 in every
// run, never a value an earlier run of the same size left in a reused
// output texture, and that each row comes back in its place.
struct Params {
    width: u32,
    height: u32,
    cut: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height || id.x >= params.cut {
        return;
    }
    textureStore(output, id.xy, vec4(1.0, f32(id.y), f32(id.x), 1.0));
}
