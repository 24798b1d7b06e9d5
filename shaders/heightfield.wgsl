// heightfield kernel (SPEC 3.4): sphere-traced terrain, 1 unit = 1 km.
// h(x, z) = amplitude * T(x * scale, z * scale); march t += relax * (p.y - h),
// hit at p.y - h < eps * t, refined by interpolation; Lambert sun, soft
// shadow, sky ambient, fog with extinction sigma = 3.912 / visibility.
// Params are packed by name from kernels/heightfield.toml; the camera basis,
// sun direction and fog extinction are derived here, the octave rotation and
// terrain normaliser in lib/terrain.wgsl: in WGSL, never on the host.
#import vista::geometry::{direction, pinhole_look_at, pinhole_ray}
#import vista::terrain::{Light, March, REFINE_ITERS, Shadow, Terrain, TerrainParams, march, normal_at, refine_iterations, surface_radiance, terrain_of}
#import vista::enums::{VIEW_DEPTH, VIEW_NORMAL, VIEW_REFINE, VIEW_STEPS}

struct Params {
    width: u32,
    height: u32,
    view: u32,
    terrain: u32,
    basis: u32,
    octaves: u32,
    seed: u32,
    max_steps: u32,
    shadow_steps: u32,
    lacunarity: f32,
    gain: f32,
    octave_rotation_deg: f32,
    ridge_h: f32,
    ridge_offset: f32,
    ridge_gain: f32,
    amplitude: f32,
    scale: f32,
    plane_slope: vec2<f32>,
    camera_pos: vec3<f32>,
    camera_target: vec3<f32>,
    fov_deg: f32,
    t_max: f32,
    relax: f32,
    eps: f32,
    shadow_distance: f32,
    shadow_softness: f32,
    sun_azimuth_deg: f32,
    sun_elevation_deg: f32,
    snow_line: f32,
    visibility_km: f32,
    sun_color: vec3<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;


// Shading colours (linear), the same constants as crates/vista-kernels/src/cpu/heightfield.rs.
const AMBIENT = vec3(0.16, 0.22, 0.32);
const SKY_HORIZON = vec3(0.60, 0.70, 0.82);
const SKY_ZENITH = vec3(0.18, 0.34, 0.66);
// Koschmieder: contrast falls to 2% at the visibility distance, ln 50 = 3.912.
const KOSCHMIEDER: f32 = 3.912;

fn terrain() -> Terrain {
    return terrain_of(TerrainParams(params.terrain, params.basis, params.seed, params.octaves, params.lacunarity,
        params.gain, params.octave_rotation_deg, params.ridge_h, params.ridge_offset, params.ridge_gain,
        params.amplitude, params.scale, params.plane_slope));
}

fn sky(d: vec3<f32>) -> vec3<f32> {
    return mix(SKY_HORIZON, SKY_ZENITH, sqrt(clamp(d.y, 0.0, 1.0)));
}

// The terrain's own radiance faded toward the horizon colour by the fog.
fn shade(s: Terrain, o: vec3<f32>, d: vec3<f32>, t: f32) -> vec3<f32> {
    let sun = direction(radians(params.sun_azimuth_deg), radians(params.sun_elevation_deg));
    let shadow = Shadow(params.shadow_steps, params.shadow_distance, params.shadow_softness);
    let lit = surface_radiance(s, params.eps, shadow, params.snow_line, o, d, t, Light(sun, params.sun_color, AMBIENT));
    let fog = exp(-(KOSCHMIEDER / params.visibility_km) * t);
    return lit * fog + SKY_HORIZON * (1.0 - fog);
}

fn encode(c: vec3<f32>) -> vec3<f32> {
    // No upper clamp: the shading stays below 1 by construction, and the
    // host's raw-output guard checks that (the PNG clamps anyway).
    return pow(max(c, vec3(0.0)), vec3(1.0 / 2.2));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size;
    let s = terrain();
    let camera = pinhole_look_at(params.camera_pos, params.camera_target, params.fov_deg, size.x / size.y);
    let o = camera.pos;
    let d = pinhole_ray(camera, uv);
    let m = march(s, March(params.t_max, params.relax, params.eps, params.max_steps), o, d);
    var rgb: vec3<f32>;
    if params.view == VIEW_STEPS {
        rgb = vec3(f32(m.steps) / f32(params.max_steps));
    } else if params.view == VIEW_REFINE {
        rgb = vec3(f32(refine_iterations) / f32(REFINE_ITERS));
    } else if params.view == VIEW_DEPTH {
        rgb = vec3(select(1.0, clamp(m.t / params.t_max, 0.0, 1.0), m.hit));
    } else if params.view == VIEW_NORMAL {
        rgb = select(vec3(0.0), normal_at(s, params.eps, (o + m.t * d).xz, m.t) * 0.5 + 0.5, m.hit);
    } else if m.hit {
        rgb = encode(shade(s, o, d, m.t));
    } else {
        rgb = encode(sky(d));
    }
    textureStore(output, id.xy, vec4(rgb, 1.0));
}
