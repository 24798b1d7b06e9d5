// A mip chain built level by level, as a bloom or screen-space-reflection
// pyramid is: level 0 copied from the input, each next level the 2 x 2
// mean of the level above, one pass per level, each pass seeing only the
// two levels it reads and writes.

@group(0) @binding(0) var level_in: texture_2d<f32>;
@group(0) @binding(1) var level_out: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn copy_base(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(level_out)) {
        return;
    }
    textureStore(level_out, id.xy, textureLoad(level_in, id.xy, 0));
}

@compute @workgroup_size(8, 8)
fn downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(level_out)) {
        return;
    }
    let p = 2u * id.xy;
    let sum = textureLoad(level_in, p, 0) + textureLoad(level_in, p + vec2<u32>(1u, 0u), 0)
        + textureLoad(level_in, p + vec2<u32>(0u, 1u), 0) + textureLoad(level_in, p + vec2<u32>(1u, 1u), 0);
    textureStore(level_out, id.xy, 0.25 * sum);
}
