// Transmittance LUT: exp(-optical depth) from a point at radius r toward
// cos-zenith mu, to the top of the atmosphere (midpoint rule).
#import sky_luts::common::{Atmosphere, medium_at, distance_to_sphere, radius_after, lut_radius}

struct TransmittanceSettings {
    transmittance_steps: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> atmosphere: Atmosphere;
@group(0) @binding(1) var<uniform> transmittance_settings: TransmittanceSettings;
@group(1) @binding(0) var transmittance_lut_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(16, 16)
fn render_transmittance_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(transmittance_lut_out);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let r = lut_radius(atmosphere, uv.y);
    let mu = 2.0 * uv.x - 1.0;
    let ray_length = distance_to_sphere(r, mu, atmosphere.top_radius);
    let n = transmittance_settings.transmittance_steps;
    let dt = ray_length / f32(n);
    var depth = vec3<f32>(0.0);
    for (var i = 0u; i < n; i = i + 1u) {
        let h = radius_after(r, mu, (f32(i) + 0.5) * dt) - atmosphere.bottom_radius;
        depth = depth + medium_at(atmosphere, h).extinction * dt;
    }
    textureStore(transmittance_lut_out, id.xy, vec4<f32>(exp(-depth), 1.0));
}
