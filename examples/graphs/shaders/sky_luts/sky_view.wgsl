// Sky-view LUT: the sky's luminance seen from a camera at camera_height,
// azimuth relative to the sun across, elevation down (finer near the
// horizon), single scattering from the transmittance LUT plus every higher
// order from the multiple-scattering LUT.
#import sky_luts::common::{Atmosphere, PI, medium_at, distance_to_sphere, distance_to_ground, transmittance_uv}

struct SkyViewSettings {
    camera_height: f32,
    sun_elevation_deg: f32,
    sun_illuminance: f32,
    sky_steps: u32,
}

@group(0) @binding(0) var<uniform> atmosphere: Atmosphere;
@group(0) @binding(1) var<uniform> sky: SkyViewSettings;
@group(1) @binding(0) var transmittance_lut: texture_2d<f32>;
@group(1) @binding(1) var multiscattering_lut: texture_2d<f32>;
@group(1) @binding(2) var lut_sampler: sampler;
@group(2) @binding(0) var sky_view_out: texture_storage_2d<rgba16float, write>;

fn rayleigh_phase(c: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + c * c);
}

// Cornette-Shanks.
fn mie_phase(c: f32, g: f32) -> f32 {
    let g2 = g * g;
    return 3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + c * c) / ((2.0 + g2) * pow(1.0 + g2 - 2.0 * g * c, 1.5));
}

@compute @workgroup_size(8, 8)
fn render_sky_view_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(sky_view_out);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let azimuth = 2.0 * PI * uv.x;
    let l = 1.0 - 2.0 * uv.y;
    let elevation = sign(l) * l * l * 0.5 * PI;
    let view = vec3<f32>(cos(elevation) * cos(azimuth), cos(elevation) * sin(azimuth), sin(elevation));
    let sun_el = radians(sky.sun_elevation_deg);
    let sun = vec3<f32>(cos(sun_el), 0.0, sin(sun_el));
    let r = atmosphere.bottom_radius + sky.camera_height;
    let origin = vec3<f32>(0.0, 0.0, r);
    let ground = distance_to_ground(r, view.z, atmosphere.bottom_radius);
    var ray_length = distance_to_sphere(r, view.z, atmosphere.top_radius);
    if (ground >= 0.0) {
        ray_length = ground;
    }
    let c = dot(view, sun);
    let phase_r = rayleigh_phase(c);
    let phase_m = mie_phase(c, atmosphere.mie_g);
    let n = sky.sky_steps;
    let dt = ray_length / f32(n);
    var view_t = vec3<f32>(1.0);
    var luminance = vec3<f32>(0.0);
    for (var i = 0u; i < n; i = i + 1u) {
        let p = origin + (f32(i) + 0.5) * dt * view;
        let pr = length(p);
        let mu_sun = dot(p, sun) / pr;
        let m = medium_at(atmosphere, pr - atmosphere.bottom_radius);
        var sun_t = textureSampleLevel(transmittance_lut, lut_sampler, transmittance_uv(atmosphere, pr, mu_sun), 0.0).rgb;
        if (distance_to_ground(pr, mu_sun, atmosphere.bottom_radius) >= 0.0) {
            sun_t = vec3<f32>(0.0);
        }
        let psi = textureSampleLevel(multiscattering_lut, lut_sampler, transmittance_uv(atmosphere, pr, mu_sun), 0.0).rgb;
        let source = m.rayleigh * (sun_t * phase_r + psi) + m.mie * (sun_t * phase_m + psi);
        let step_t = exp(-m.extinction * dt);
        luminance = luminance + view_t * source * (vec3<f32>(1.0) - step_t) / max(m.extinction, vec3<f32>(1e-9));
        view_t = view_t * step_t;
    }
    textureStore(sky_view_out, id.xy, vec4<f32>(sky.sun_illuminance * luminance, 1.0));
}
