// Separable Gaussian blur: one entry point run twice, along x and then
// along y (`flip.value`), sampling its source at texel centres through a
// clamp-to-edge sampler and writing rgba16float.

struct BlurSettings {
    radius: i32,
    sigma: f32,
}

struct Flip {
    value: u32,
}

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var src_sampler: sampler;
@group(0) @binding(2) var dst: texture_storage_2d<rgba16float, write>;
@group(1) @binding(0) var<uniform> blur: BlurSettings;
@group(1) @binding(1) var<uniform> flip: Flip;

@compute @workgroup_size(16, 16)
fn blur_axis(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if (gid.x >= size.x || gid.y >= size.y) {
        return;
    }
    let axis = select(vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0), flip.value == 1u);
    let texel = axis / vec2<f32>(size);
    let uv = (vec2<f32>(gid.xy) + 0.5) / vec2<f32>(size);
    let two_sigma_sq = 2.0 * blur.sigma * blur.sigma;
    var sum = vec4<f32>(0.0);
    var weights = 0.0;
    for (var i = -blur.radius; i <= blur.radius; i = i + 1) {
        let w = exp(-f32(i * i) / two_sigma_sq);
        sum = sum + w * textureSampleLevel(src, src_sampler, uv + f32(i) * texel, 0.0);
        weights = weights + w;
    }
    textureStore(dst, gid.xy, sum / weights);
}
