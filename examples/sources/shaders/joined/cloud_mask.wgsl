// A cloud cover mask whose host joins noise_lib.wgsl before it and
// tone.wgsl after it, and writes the octave count in for {OCTAVES} and the
// tone curve's name in for {TONE}.
const OCTAVES: u32 = {OCTAVES}u;

struct Cover {
    width: u32,
    height: u32,
    coverage: f32,
    scale: f32,
}

@group(0) @binding(0) var<uniform> cover: Cover;
@group(0) @binding(1) var mask_out: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 4)
fn cloud_mask(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= cover.width || id.y >= cover.height {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2(f32(cover.width), f32(cover.height));
    let n = fbm(uv * cover.scale);
    // Remap so that `coverage` of the density range is cloud.
    let cloud = clamp((n - (1.0 - cover.coverage)) / max(cover.coverage, 1e-3), 0.0, 1.0);
    let c = mix(sky(uv.y), vec3(1.2), cloud);
    textureStore(mask_out, id.xy, vec4(tone_{TONE}(c) * 1.5, 1.0));
}
