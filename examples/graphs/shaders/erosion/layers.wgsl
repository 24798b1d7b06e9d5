// Erosion, last pass: the water depth out of the packed fluid state
// (depth, sediment, velocity) as its own r32float layer, as a terrain
// editor would export it.

@group(0) @binding(0) var fluid: texture_2d<f32>;
@group(0) @binding(1) var water: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn export_water(@builtin(global_invocation_id) id: vec3<u32>) {
    let grid = textureDimensions(water);
    if (id.x >= grid.x || id.y >= grid.y) {
        return;
    }
    textureStore(water, id.xy, vec4<f32>(textureLoad(fluid, id.xy, 0).x, 0.0, 0.0, 1.0));
}
