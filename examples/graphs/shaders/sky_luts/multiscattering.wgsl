// Multiple-scattering LUT (Hillaire 2020, section 5.5): for a sun
// cos-zenith (across) and an altitude (down), the second-order luminance
// L2 and the transfer f_ms gathered over 64 directions of the sphere, one
// per invocation along z, summed in workgroup memory; the texel holds
// psi = L2 / (1 - f_ms), the isotropic luminance of all orders for a sun
// of illuminance 1.
#import sky_luts::common::{Atmosphere, PI, medium_at, distance_to_sphere, distance_to_ground, transmittance_uv, lut_radius}

struct MultiscatteringSettings {
    ms_steps: u32,
}

@group(0) @binding(0) var<uniform> atmosphere: Atmosphere;
@group(0) @binding(1) var<uniform> ms_settings: MultiscatteringSettings;
@group(1) @binding(0) var transmittance_lut: texture_2d<f32>;
@group(1) @binding(1) var lut_sampler: sampler;
@group(2) @binding(0) var multiscattering_lut_out: texture_storage_2d<rgba16float, write>;

const DIRECTIONS: u32 = 64u;
var<workgroup> gathered: array<vec3<f32>, 64>;
var<workgroup> transfer: array<vec3<f32>, 64>;

// Transmittance toward the sun from point p (planet centre at the origin),
// zero in the planet's shadow.
fn sun_transmittance(p: vec3<f32>, sun: vec3<f32>) -> vec3<f32> {
    let r = length(p);
    let mu = dot(p, sun) / r;
    if (distance_to_ground(r, mu, atmosphere.bottom_radius) >= 0.0) {
        return vec3<f32>(0.0);
    }
    return textureSampleLevel(transmittance_lut, lut_sampler, transmittance_uv(atmosphere, r, mu), 0.0).rgb;
}

@compute @workgroup_size(1, 1, 64)
fn render_multiscattering_lut(@builtin(workgroup_id) texel: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let size = textureDimensions(multiscattering_lut_out);
    let uv = (vec2<f32>(texel.xy) + 0.5) / vec2<f32>(size);
    let mu_sun = 2.0 * uv.x - 1.0;
    let sun = vec3<f32>(sqrt(max(0.0, 1.0 - mu_sun * mu_sun)), 0.0, mu_sun);
    let r = lut_radius(atmosphere, uv.y);
    let origin = vec3<f32>(0.0, 0.0, r);
    // One direction of an 8 x 8 stratified grid of the sphere.
    let cos_theta = 1.0 - 2.0 * (f32(lane / 8u) + 0.5) / 8.0;
    let phi = 2.0 * PI * (f32(lane % 8u) + 0.5) / 8.0;
    let sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    let dir = vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
    let ground = distance_to_ground(r, cos_theta, atmosphere.bottom_radius);
    var ray_length = distance_to_sphere(r, cos_theta, atmosphere.top_radius);
    if (ground >= 0.0) {
        ray_length = ground;
    }
    let n = ms_settings.ms_steps;
    let dt = ray_length / f32(n);
    let isotropic = 1.0 / (4.0 * PI);
    var view_t = vec3<f32>(1.0);
    var luminance = vec3<f32>(0.0);
    var f_ms = vec3<f32>(0.0);
    for (var i = 0u; i < n; i = i + 1u) {
        let p = origin + (f32(i) + 0.5) * dt * dir;
        let m = medium_at(atmosphere, length(p) - atmosphere.bottom_radius);
        let scattering = m.rayleigh + vec3<f32>(m.mie);
        let step_t = exp(-m.extinction * dt);
        // Energy-conserving integration over the step (Hillaire, eq. 12).
        let through = (vec3<f32>(1.0) - step_t) / max(m.extinction, vec3<f32>(1e-9));
        luminance = luminance + view_t * scattering * sun_transmittance(p, sun) * isotropic * through;
        f_ms = f_ms + view_t * scattering * through;
        view_t = view_t * step_t;
    }
    if (ground >= 0.0) {
        let p = origin + ground * dir;
        let lit = max(dot(normalize(p), sun), 0.0);
        luminance = luminance + view_t * sun_transmittance(p, sun) * atmosphere.ground_albedo * lit / PI;
    }
    gathered[lane] = luminance;
    transfer[lane] = f_ms;
    workgroupBarrier();
    for (var stride = DIRECTIONS / 2u; stride > 0u; stride = stride / 2u) {
        if (lane < stride) {
            gathered[lane] = gathered[lane] + gathered[lane + stride];
            transfer[lane] = transfer[lane] + transfer[lane + stride];
        }
        workgroupBarrier();
    }
    if (lane == 0u) {
        let l2 = gathered[0] / f32(DIRECTIONS);
        let f = transfer[0] / f32(DIRECTIONS);
        textureStore(multiscattering_lut_out, texel.xy, vec4<f32>(l2 / (vec3<f32>(1.0) - f), 1.0));
    }
}
