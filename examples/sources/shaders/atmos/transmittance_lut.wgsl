// Transmittance LUT: x is the view zenith cosine from -1 to 1, y the
// altitude from the top of the atmosphere down to the ground.
#import atmos::{
    bindings::settings,
    functions::{transmittance_to_top, distance_to_top},
}
#import atmos::bindings::atmosphere as air

@group(0) @binding(13) var transmittance_lut_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(16, 16, 1)
fn main(@builtin(global_invocation_id) idx: vec3<u32>) {
    if any(idx.xy >= vec2(settings.width, settings.height)) {
        return;
    }
    let uv = (vec2<f32>(idx.xy) + 0.5) / vec2<f32>(f32(settings.width), f32(settings.height));
    let mu = 2.0 * uv.x - 1.0;
    let r = mix(air.top_radius, air.bottom_radius, uv.y);
    // alpha: the path length as a share of the longest, for the report
    let reach = distance_to_top(r, mu) / distance_to_top(air.bottom_radius, 0.0);
    textureStore(transmittance_lut_out, idx.xy, vec4(transmittance_to_top(r, mu), clamp(reach, 0.0, 1.0)));
}
