// Concentric rings posterized into bands: the kernel imports its project's
// studio::color::grade module, which reads the GRADE_STEPS def the manifest
// sets. Output rgba16float, uniform `look` at group 0 binding 1.
#import studio::color::grade::{posterize, contrast}

struct Look {
    width: u32,
    height: u32,
    rings: f32,
    center: vec2<f32>,
    punch: f32,
}

@group(0) @binding(1) var<uniform> look: Look;
@group(0) @binding(0) var poster_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= look.width || id.y >= look.height {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2(f32(look.width), f32(look.height));
    let r = length(uv - look.center);
    let wave = 0.5 + 0.5 * cos(6.283185307 * look.rings * r);
    let v = posterize(contrast(wave, look.punch));
    textureStore(poster_out, id.xy, vec4(v, 0.5 * v + 0.25, 1.0 - v, 1.0));
}
