// atmosphere kernel (SPEC 3.5): single-scattering Rayleigh + Mie sky.
// Writes linear radiance L (RGB), alpha 1.
// The integral itself is shaders/lib/sky.wgsl, shared with the landscape kernel.
#import vista::geometry::latlong_direction
#import vista::sky::{Atmosphere, sky_radiance}
#import vista::enums::PROJECTION_LATLONG

// Packed by name from kernels/atmosphere.toml (exposure is the host's tone map).
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
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

const PI: f32 = 3.141592653589793;

fn atmosphere() -> Atmosphere {
    // The sun at azimuth 0: (0, sin e, cos e).
    let e = radians(params.sun_elevation_deg);
    return Atmosphere(vec3(0.0, sin(e), cos(e)), params.camera_altitude_m, params.sun_intensity, params.mie_g,
                      params.view_samples, params.light_samples, vec2(1.0, 1.0));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size;
    let a = atmosphere();
    var l = vec3(0.0);
    if params.projection == PROJECTION_LATLONG {
        l = sky_radiance(a, latlong_direction(uv.x, uv.y));
    } else {
        // Equidistant fisheye: zenith at the centre, horizon on the inscribed
        // circle, azimuth 0 (the sun) up.
        let xy = vec2(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y) * size / min(size.x, size.y);
        let r = length(xy);
        if r <= 1.0 {
            let phi = atan2(xy.x, xy.y);
            let e = 0.5 * PI * (1.0 - r);
            l = sky_radiance(a, vec3(cos(e) * sin(phi), sin(e), cos(e) * cos(phi)));
        }
    }
    textureStore(output, id.xy, vec4(l, 1.0));
}
