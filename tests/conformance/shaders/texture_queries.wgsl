// What a shader sees of a texture's shape: textureDimensions (of the
// whole texture and of one level), textureNumLevels and textureNumLayers,
// for 1d, 2d with mips, 2d-array, 3d, cube views, and a storage view of
// one mip level (`name@level`).

@group(0) @binding(0) var line: texture_1d<f32>;
@group(0) @binding(1) var plane: texture_2d<f32>;
@group(0) @binding(2) var layers: texture_2d_array<f32>;
@group(0) @binding(3) var volume: texture_3d<f32>;
@group(0) @binding(4) var sky: texture_cube<f32>;
@group(0) @binding(5) var level2: texture_storage_2d<rgba8unorm, write>;
@group(1) @binding(0) var<storage, read_write> shape: array<u32>;

// Writes one texel of each texture first (vista refuses to read a texture
// nothing wrote): storage views for 1d, 2d, 2d-array and 3d, a render pass
// (`paint`) for a cube face.
@group(0) @binding(0) var w_line: texture_storage_1d<rgba8unorm, write>;
@group(0) @binding(1) var w_plane: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(2) var w_layers: texture_storage_2d_array<rgba8unorm, write>;
@group(0) @binding(3) var w_volume: texture_storage_3d<rgba8unorm, write>;

@compute @workgroup_size(1)
fn touch_all() {
    textureStore(w_line, 0, vec4<f32>(1.0));
    textureStore(w_plane, vec2<i32>(0, 0), vec4<f32>(1.0));
    textureStore(w_layers, vec2<i32>(0, 0), 0, vec4<f32>(1.0));
    textureStore(w_volume, vec3<i32>(0, 0, 0), vec4<f32>(1.0));
}

@fragment
fn paint() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}

@compute @workgroup_size(1)
fn query_shapes() {
    shape[0] = textureDimensions(line);
    shape[1] = textureNumLevels(line);
    let p0 = textureDimensions(plane);
    let p2 = textureDimensions(plane, 2);
    let p3 = textureDimensions(plane, 3);
    shape[2] = p0.x; shape[3] = p0.y;
    shape[4] = p2.x; shape[5] = p2.y;
    shape[6] = p3.x; shape[7] = p3.y;
    shape[8] = textureNumLevels(plane);
    let a = textureDimensions(layers);
    shape[9] = a.x; shape[10] = a.y;
    shape[11] = textureNumLayers(layers);
    shape[12] = textureNumLevels(layers);
    let v0 = textureDimensions(volume);
    let v1 = textureDimensions(volume, 1);
    shape[13] = v0.x; shape[14] = v0.y; shape[15] = v0.z;
    shape[16] = v1.x; shape[17] = v1.y; shape[18] = v1.z;
    shape[19] = textureNumLevels(volume);
    let c = textureDimensions(sky);
    shape[20] = c.x; shape[21] = c.y;
    shape[22] = textureNumLevels(sky);
    let s = textureDimensions(level2);
    shape[23] = s.x; shape[24] = s.y;
    shape[25] = 0xD1Au;
    textureStore(level2, vec2<i32>(0, 0), vec4<f32>(1.0));
}
