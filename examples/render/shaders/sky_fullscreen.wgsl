// The atmosphere kernel's sky (shaders/atmosphere.wgsl) as a full-screen
// fragment pass, the way an engine draws its sky: the same single-
// scattering integral (vista::sky), evaluated per fragment at the uv the
// full-screen triangle interpolates (texel centres, (0, 0) top left).
#import vista::geometry::latlong_direction
#import vista::sky::{Atmosphere, sky_radiance}
#import vista::enums::PROJECTION_LATLONG

struct Params {
    width: u32,
    height: u32,
    projection: u32,
    view_samples: u32,
    light_samples: u32,
    sun_elevation_deg: f32,
    camera_altitude_m: f32,
    sun_intensity: f32,
    mie_g: f32,
}

@group(0) @binding(0) var<uniform> params: Params;

const PI: f32 = 3.141592653589793;

@fragment
fn sky(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let e = radians(params.sun_elevation_deg);
    let a = Atmosphere(vec3(0.0, sin(e), cos(e)), params.camera_altitude_m, params.sun_intensity, params.mie_g,
                       params.view_samples, params.light_samples, vec2(1.0, 1.0));
    let size = vec2<f32>(f32(params.width), f32(params.height));
    var l = vec3(0.0);
    if params.projection == PROJECTION_LATLONG {
        l = sky_radiance(a, latlong_direction(uv.x, uv.y));
    } else {
        // Equidistant fisheye: zenith at the centre, the sun's azimuth up.
        let xy = vec2(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y) * size / min(size.x, size.y);
        let r = length(xy);
        if r <= 1.0 {
            let phi = atan2(xy.x, xy.y);
            let el = 0.5 * PI * (1.0 - r);
            l = sky_radiance(a, vec3(cos(el) * sin(phi), sin(el), cos(el) * cos(phi)));
        }
    }
    return vec4(l, 1.0);
}
