// Every storable texel format written by textureStore from fixed values
// and read back: what lands is WebGPU's conversion (normalized values
// rounded to the nearest step, float16 rounded, missing channels
// read as 0, 0, 1). Four formats per pass (maxStorageTexturesPerShaderStage
// is 4 in WebGPU); expected.py computes each stored value.

@group(0) @binding(0) var t_rgba8unorm: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(1) var t_rgba8snorm: texture_storage_2d<rgba8snorm, write>;
@group(0) @binding(2) var t_rgba8uint: texture_storage_2d<rgba8uint, write>;
@group(0) @binding(3) var t_rgba8sint: texture_storage_2d<rgba8sint, write>;

@compute @workgroup_size(1)
fn store_group0() {
    textureStore(t_rgba8unorm, vec2<i32>(0, 0), vec4<f32>(0.25, -0.25, 1.0, 0.8));
    textureStore(t_rgba8snorm, vec2<i32>(0, 0), vec4<f32>(0.25, -0.25, 1.0, 0.8));
    textureStore(t_rgba8uint, vec2<i32>(0, 0), vec4<u32>(7u, 200u, 3u, 255u));
    textureStore(t_rgba8sint, vec2<i32>(0, 0), vec4<i32>(-3, 100, -128, 127));
}

@group(0) @binding(0) var t_rgba16float: texture_storage_2d<rgba16float, write>;
@group(0) @binding(1) var t_rgba16uint: texture_storage_2d<rgba16uint, write>;
@group(0) @binding(2) var t_rgba16sint: texture_storage_2d<rgba16sint, write>;
@group(0) @binding(3) var t_rgba32float: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(1)
fn store_group1() {
    textureStore(t_rgba16float, vec2<i32>(0, 0), vec4<f32>(0.25, -0.25, 1.0, 0.8));
    textureStore(t_rgba16uint, vec2<i32>(0, 0), vec4<u32>(7u, 65535u, 300u, 0u));
    textureStore(t_rgba16sint, vec2<i32>(0, 0), vec4<i32>(-3, 32767, -32768, 1000));
    textureStore(t_rgba32float, vec2<i32>(0, 0), vec4<f32>(0.25, -0.25, 1.0, 0.8));
}

@group(0) @binding(0) var t_rgba32uint: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(1) var t_rgba32sint: texture_storage_2d<rgba32sint, write>;
@group(0) @binding(2) var t_r32float: texture_storage_2d<r32float, write>;
@group(0) @binding(3) var t_r32uint: texture_storage_2d<r32uint, write>;

@compute @workgroup_size(1)
fn store_group2() {
    textureStore(t_rgba32uint, vec2<i32>(0, 0), vec4<u32>(7u, 4000000000u, 300u, 0u));
    textureStore(t_rgba32sint, vec2<i32>(0, 0), vec4<i32>(-3, 2147483647, -2147483648, 1000));
    textureStore(t_r32float, vec2<i32>(0, 0), vec4<f32>(0.25, -0.25, 1.0, 0.8));
    textureStore(t_r32uint, vec2<i32>(0, 0), vec4<u32>(7u, 4000000000u, 300u, 0u));
}

@group(0) @binding(0) var t_r32sint: texture_storage_2d<r32sint, write>;
@group(0) @binding(1) var t_rg32float: texture_storage_2d<rg32float, write>;
@group(0) @binding(2) var t_rg32uint: texture_storage_2d<rg32uint, write>;
@group(0) @binding(3) var t_rg32sint: texture_storage_2d<rg32sint, write>;

@compute @workgroup_size(1)
fn store_group3() {
    textureStore(t_r32sint, vec2<i32>(0, 0), vec4<i32>(-3, 2147483647, -2147483648, 1000));
    textureStore(t_rg32float, vec2<i32>(0, 0), vec4<f32>(0.25, -0.25, 1.0, 0.8));
    textureStore(t_rg32uint, vec2<i32>(0, 0), vec4<u32>(7u, 4000000000u, 300u, 0u));
    textureStore(t_rg32sint, vec2<i32>(0, 0), vec4<i32>(-3, 2147483647, -2147483648, 1000));
}
