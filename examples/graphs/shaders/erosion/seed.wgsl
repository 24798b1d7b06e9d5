// Erosion, pass 1: the terrain from a heightmap. Terrain height is the
// image's red channel times `height_scale` (in cells); water, sediment
// and flux start at zero. The heightmap is read with textureLoad, nearest
// texel, so a grid of any size can be seeded from it.

@group(0) @binding(0) var heightmap: texture_2d<f32>;
@group(0) @binding(1) var terrain_out: texture_storage_2d<r32float, write>;

@group(1) @binding(0) var<uniform> height_scale: f32;

@compute @workgroup_size(16, 16)
fn seed_terrain(@builtin(global_invocation_id) id: vec3<u32>) {
    let grid = textureDimensions(terrain_out);
    if (id.x >= grid.x || id.y >= grid.y) {
        return;
    }
    let src = textureDimensions(heightmap);
    let texel = min(id.xy * src / grid, src - vec2<u32>(1u));
    let h = textureLoad(heightmap, texel, 0).r;
    textureStore(terrain_out, id.xy, vec4<f32>(height_scale * h, 0.0, 0.0, 1.0));
}
