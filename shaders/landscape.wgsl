// landscape kernel: the seed's whole frame in one kernel. Ridged
// terrain by the heightfield kernel's march, lit by the sun through the
// atmosphere; the atmosphere kernel's sky; aerial perspective over the
// terrain; the clouds kernel's slab, composited in depth order. Every piece
// is the shared definition in shaders/lib (terrain, sky, cloud_slab).
//
// Units: the scene in km (y up, sea level = the terrain's 0 = the planet's
// ground); the atmosphere in m, its camera at altitude 1000 camera_pos.y, the
// same direction vectors. The terrain and the slab are flat; the planet is a
// sphere (it falls 0.5 km below the tangent plane 80 km out, where the
// terrain march ends).
//
// Along a view ray with its terrain hit at t_hit (or the atmosphere's exit)
// and the slab's part [c0, c1] before it:
//   L = A[0, c0] + T[0, c0] (L_cloud + T_cloud (A[c1, end] + T[c1, end] L_surface))
// with A, T the single-scattering in-scatter and transmittance of that part
// of the ray (seed 002 eq. 3.25: the sky integral ending at the hit), and
// L_surface the terrain's radiance (albedo / pi x irradiance, the heightfield
// kernel's shading) under the sun E_sun T_sun(x) T_slab(x) (T_sun: the
// atmosphere's transmittance toward the sun from the hit; T_slab: the
// slab's, by the clouds' light march: cloud shadows) and the ground_ambient
// sky light. The cloud's sun is E_sun T_sun at the middle of its segment. Without a cloud segment (or
// with coverage or density 0) the ray is one atmosphere segment.
#import vista::cloud_slab::{CloudParams, CloudSlab, cloud_march, cloud_slab, jitter_offset, layer_segment, sun_optical_depth}
#import vista::geometry::{direction, latlong_direction, pinhole_looking, pinhole_ray}
#import vista::sky::{Atmosphere, sky_segment, sun_transmittance_along, view_segment}
#import vista::terrain::{Light, March, REFINE_ITERS, Shadow, Terrain, TerrainParams, march, refine_iterations, surface_point, surface_radiance, terrain_of}
#import vista::enums::{PROJECTION_LATLONG, VIEW_DEPTH, VIEW_REFINE}

// Packed by name from kernels/landscape.toml (exposure is the host's tone map).
struct Params {
    width: u32,
    height: u32,
    view: u32,
    projection: u32,
    camera_pos: vec3<f32>,
    yaw_deg: f32,
    pitch_deg: f32,
    fov_deg: f32,
    sun_azimuth_deg: f32,
    sun_elevation_deg: f32,
    sun_intensity: f32,
    view_samples: u32,
    light_samples: u32,
    mie_g: f32,
    rayleigh_density: f32,
    mie_density: f32,
    terrain: u32,
    basis: u32,
    octaves: u32,
    lacunarity: f32,
    gain: f32,
    octave_rotation_deg: f32,
    seed: u32,
    ridge_h: f32,
    ridge_offset: f32,
    ridge_gain: f32,
    amplitude: f32,
    scale: f32,
    plane_slope: vec2<f32>,
    t_max: f32,
    relax: f32,
    eps: f32,
    max_steps: u32,
    shadow_steps: u32,
    shadow_distance: f32,
    shadow_softness: f32,
    snow_line: f32,
    ground_ambient: vec3<f32>,
    // The clouds' params, by name (kernels/landscape.toml's [[group]]:
    // leaf x is fed by cloud_x where the manifest has one, else by x).
    cloud: CloudParams,
    cloud_jitter: u32,
    cloud_jitter_seed: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

const KM: f32 = 1000.0;
const PI: f32 = 3.141592653589793;

fn terrain() -> Terrain {
    return terrain_of(TerrainParams(params.terrain, params.basis, params.seed, params.octaves, params.lacunarity,
        params.gain, params.octave_rotation_deg, params.ridge_h, params.ridge_offset, params.ridge_gain,
        params.amplitude, params.scale, params.plane_slope));
}

fn slab() -> CloudSlab {
    return cloud_slab(params.cloud, params.camera_pos);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size;
    let o = params.camera_pos;
    var d: vec3<f32>;
    if params.projection == PROJECTION_LATLONG {
        d = latlong_direction(uv.x, uv.y);
    } else {
        // pitch is within +-89 deg (manifest range), so forward is never vertical.
        let forward = direction(radians(params.yaw_deg), radians(params.pitch_deg));
        d = pinhole_ray(pinhole_looking(o, forward, params.fov_deg, size.x / size.y), uv);
    }
    let sun_dir = direction(radians(params.sun_azimuth_deg), radians(params.sun_elevation_deg));
    let air = Atmosphere(sun_dir, KM * o.y, params.sun_intensity, params.mie_g, params.view_samples,
                         params.light_samples, vec2(params.rayleigh_density, params.mie_density));

    // The far end of the ray: the terrain hit, else the atmosphere's exit.
    let s = terrain();
    let hit = march(s, March(params.t_max, params.relax, params.eps, params.max_steps), o, d);
    if params.view == VIEW_DEPTH {
        textureStore(output, id.xy, vec4(vec3(select(1.0, clamp(hit.t / params.t_max, 0.0, 1.0), hit.hit)), 1.0));
        return;
    }
    if params.view == VIEW_REFINE {
        textureStore(output, id.xy, vec4(vec3(f32(refine_iterations) / f32(REFINE_ITERS)), 1.0));
        return;
    }
    let sky = view_segment(air, d);
    let start = sky.x;
    var end = max(sky.y, start);
    let slab = slab();
    let clouds = params.cloud.coverage > 0.0 && params.cloud.density_scale > 0.0;
    var surface = vec3(0.0);
    if hit.hit {
        end = KM * hit.t;
        // Lambert: radiance = albedo / pi x irradiance. The sun reaches the
        // ground through the air and through the slab above it.
        var sun = params.sun_intensity / PI * sun_transmittance_along(air, d, end);
        if clouds {
            sun *= exp(-sun_optical_depth(slab, surface_point(s, o, d, hit.t), sun_dir));
        }
        let shadow = Shadow(params.shadow_steps, params.shadow_distance, params.shadow_softness);
        surface = surface_radiance(s, params.eps, shadow, params.snow_line, o, d, hit.t,
                                   Light(sun_dir, sun, params.ground_ambient));
    }

    // The layer's part of the ray in front of the far end.
    let seg = layer_segment(slab, o, d);
    let c0 = seg.x;
    var c1 = seg.y;
    if hit.hit {
        c1 = min(c1, hit.t);
    }
    var radiance: vec3<f32>;
    if clouds && c1 > c0 {
        let front = sky_segment(air, d, start, max(KM * c0, start));
        let back = sky_segment(air, d, max(KM * c1, start), end);
        let cloud_sun = params.sun_intensity * sun_transmittance_along(air, d, KM * 0.5 * (c0 + c1));
        let xi = jitter_offset(params.cloud_jitter, params.cloud_jitter_seed, id.xy);
        let cloud = cloud_march(slab, o, d, c0, c1, xi, sun_dir, cloud_sun);
        let behind = back.inscatter + back.transmittance * surface;
        radiance = front.inscatter + front.transmittance * (cloud.rgb + cloud.a * behind);
    } else {
        let all = sky_segment(air, d, start, end);
        radiance = all.inscatter + all.transmittance * surface;
    }
    textureStore(output, id.xy, vec4(radiance, 1.0));
}
