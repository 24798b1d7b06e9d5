// Mip-level and layer views. Every texel of every level (and layer) is
// written (tag, x, y, 1), x and y its coordinates in that level and tag
// naming the level (and layer): levels 0 and 1 of `pyr` through storage
// views of one level (compute), levels 2 and 3 and each level of each
// layer of `arr` through render targets of one level or layer
// ("pyr@2", "arr@1@layer2"). `read_views` then loads and samples them
// through the whole texture and through views of one level ("pyr@2",
// "arr@1"): a view's level 0 is the texture's level k, its dimensions
// those of level k, its level count 1.

@group(0) @binding(0) var<uniform> tag: f32;
@group(0) @binding(1) var level_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn fill_level(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(level_out);
    if id.x < size.x && id.y < size.y {
        textureStore(level_out, vec2<i32>(id.xy), vec4<f32>(tag, f32(id.x), f32(id.y), 1.0));
    }
}

@fragment
fn paint(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(tag, floor(p.x), floor(p.y), 1.0);
}

@group(1) @binding(0) var whole: texture_2d<f32>;
@group(1) @binding(1) var level1: texture_2d<f32>;
@group(1) @binding(2) var level2: texture_2d<f32>;
@group(1) @binding(3) var layers: texture_2d_array<f32>;
@group(1) @binding(4) var layers_level1: texture_2d_array<f32>;
@group(1) @binding(5) var nearest: sampler;
@group(1) @binding(6) var<storage, read_write> seen: array<vec4<f32>>;

var<private> next: u32 = 0u;

fn put(v: vec4<f32>) {
    seen[next] = v;
    next += 1u;
}

fn put_shape(size: vec2<u32>, levels: u32, layer_count: u32) {
    put(vec4<f32>(f32(size.x), f32(size.y), f32(levels), f32(layer_count)));
}

@compute @workgroup_size(1)
fn read_views() {
    // The whole texture: each level's last column of row 0, then its first column of the last row.
    for (var l = 0u; l < 4u; l++) {
        let last = vec2<u32>(8u >> l, 8u >> l) - 1u;
        put(textureLoad(whole, vec2<u32>(last.x, 0u), l));
        put(textureLoad(whole, vec2<u32>(0u, last.y), l));
    }
    // Views of one level.
    put(textureLoad(level1, vec2<u32>(2u, 3u), 0));
    put(textureLoad(level2, vec2<u32>(1u, 1u), 0));
    put(textureSampleLevel(whole, nearest, vec2<f32>(0.75, 0.25), 2.0));
    put(textureSampleLevel(level2, nearest, vec2<f32>(0.75, 0.25), 0.0));
    put(textureSampleLevel(whole, nearest, vec2<f32>(0.3, 0.8), 1.0));
    put(textureSampleLevel(level1, nearest, vec2<f32>(0.3, 0.8), 0.0));
    put_shape(textureDimensions(whole), textureNumLevels(whole), 1u);
    put_shape(textureDimensions(level1), textureNumLevels(level1), 1u);
    put_shape(textureDimensions(level2), textureNumLevels(level2), 1u);
    // The array: each layer at each level (its last texel), then through the level-1 view.
    for (var layer = 0u; layer < 3u; layer++) {
        put(textureLoad(layers, vec2<u32>(3u, 3u), layer, 0u));
        put(textureLoad(layers, vec2<u32>(1u, 1u), layer, 1u));
        put(textureLoad(layers_level1, vec2<u32>(1u, 0u), layer, 0u));
    }
    put(textureSampleLevel(layers, nearest, vec2<f32>(0.6, 0.1), 2u, 1.0));
    put(textureSampleLevel(layers_level1, nearest, vec2<f32>(0.6, 0.1), 2u, 0.0));
    put_shape(textureDimensions(layers), textureNumLevels(layers), textureNumLayers(layers));
    put_shape(textureDimensions(layers_level1), textureNumLevels(layers_level1), textureNumLayers(layers_level1));
}
