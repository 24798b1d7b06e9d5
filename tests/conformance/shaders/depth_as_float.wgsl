// A depth32float resource read back as texture_2d<f32> (WebGPU's
// unfilterable-float view of a depth format): a full-screen triangle at
// depth 0.25 written with compare "always", then a compute pass loads each
// texel through the float view and stores it.

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let p = array<vec2<f32>, 3>(vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
    return vec4<f32>(p[i], 0.25, 1.0);
}
@fragment
fn fs() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }

@group(0) @binding(0) var depth_tex: texture_2d<f32>;
@group(0) @binding(1) var out: texture_storage_2d<rgba32float, write>;
@compute @workgroup_size(8, 8)
fn read_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    let d = textureLoad(depth_tex, id.xy, 0).r;
    textureStore(out, id.xy, vec4<f32>(d, 0.0, 0.0, 1.0));
}
