// heightfield kernel (SPEC 3.4): sphere-traced terrain, 1 unit = 1 km.
// h(x, z) = amplitude * T(x * scale, z * scale); march t += relax * (p.y - h),
// hit at p.y - h < eps * t, refined by interpolation; Lambert sun, soft
// shadow, sky ambient, fog with extinction sigma = 3.912 / visibility.
// Params are packed by name from kernels/heightfield.toml; the camera basis,
// sun direction, octave rotation, terrain normaliser and fog extinction are
// derived here, never on the host.
#import vista::fractal::{FbmSettings, RidgedSettings, fbm2, fbm_amplitude, ridged2, ridged_max}
#import vista::geometry::{direction, pinhole_look_at, pinhole_ray}

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
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

const VIEW_DEPTH: u32 = 1u;
const VIEW_STEPS: u32 = 2u;
const VIEW_NORMAL: u32 = 3u;
const TERRAIN_FBM: u32 = 0u;
const TERRAIN_RIDGED: u32 = 1u;
const TERRAIN_PLANE: u32 = 2u;
const REFINE_ITERS: u32 = 16u;
const REFINE_TOL: f32 = 0.01;

// Shading colours (linear), the same constants as crates/vista-kernels/src/cpu/heightfield.rs.
const SUN_COLOR = vec3(1.0, 0.92, 0.78);
const AMBIENT = vec3(0.16, 0.22, 0.32);
const SKY_HORIZON = vec3(0.60, 0.70, 0.82);
const SKY_ZENITH = vec3(0.18, 0.34, 0.66);
const ROCK = vec3(0.36, 0.31, 0.27);
const GRASS = vec3(0.16, 0.26, 0.08);
const SNOW = vec3(0.85, 0.87, 0.90);
const SNOW_FADE: f32 = 0.2;
// Koschmieder: contrast falls to 2% at the visibility distance, ln 50 = 3.912.
const KOSCHMIEDER: f32 = 3.912;

fn fbm_settings() -> FbmSettings {
    let theta = radians(params.octave_rotation_deg);
    return FbmSettings(params.basis, params.seed, params.octaves, params.lacunarity, params.gain,
                       cos(theta), sin(theta));
}

fn ridged_settings() -> RidgedSettings {
    return RidgedSettings(params.basis, params.seed, params.octaves, params.lacunarity, params.ridge_h,
                          params.ridge_offset, params.ridge_gain);
}

// T's normaliser, once per invocation: 1 / A (fbm) or 1 / max (ridged).
var<private> inv_norm: f32 = 1.0;

fn terrain_height(xz: vec2<f32>) -> f32 {
    let q = xz * params.scale;
    if params.terrain == TERRAIN_FBM {
        return params.amplitude * fbm2(fbm_settings(), q, 0.0) * inv_norm;
    }
    if params.terrain == TERRAIN_RIDGED {
        return params.amplitude * ridged2(ridged_settings(), q, 0.0) * inv_norm;
    }
    if params.terrain == TERRAIN_PLANE {
        return params.amplitude + dot(params.plane_slope, xz);
    }
    return params.amplitude * sin(q.x) * cos(q.y);
}

// D(t): height of the ray point above the terrain.
fn above(o: vec3<f32>, d: vec3<f32>, t: f32) -> f32 {
    let p = o + t * d;
    return p.y - terrain_height(p.xz);
}

// Zero of D interpolated between the last two samples a (D > 0) and b
// (D < eps t), repeated with the newest two points until |D| <= eps t / 100:
// secant steps while above the terrain (stop when D stops falling), Illinois
// false position keeping the sign change once under it. Keeps the best |D|.
fn refine(o: vec3<f32>, d: vec3<f32>, a0: vec2<f32>, b0: vec2<f32>) -> f32 {
    var a = a0;
    var b = b0;
    var best_t = b.x;
    var best_d = abs(b.y);
    var last = 0;
    for (var i = 0u; i < REFINE_ITERS; i++) {
        if a.y <= b.y || best_d <= REFINE_TOL * params.eps * best_t {
            break;
        }
        let tr = b.x + b.y * (b.x - a.x) / (a.y - b.y);
        let dr = above(o, d, tr);
        if abs(dr) < best_d {
            best_t = tr;
            best_d = abs(dr);
        }
        if b.y >= 0.0 {
            // Also stops on a non-finite D far out along the ray.
            if !(dr < b.y) {
                break;
            }
            a = b;
            b = vec2(tr, dr);
        } else if dr > 0.0 {
            // Illinois: an end kept twice in a row has its value halved.
            a = vec2(tr, dr);
            if last == 1 {
                b.y *= 0.5;
            }
            last = 1;
        } else {
            b = vec2(tr, dr);
            if last == -1 {
                a.y *= 0.5;
            }
            last = -1;
        }
    }
    return best_t;
}

struct Hit {
    hit: bool,
    t: f32,
    steps: u32,
}

fn march(o: vec3<f32>, d: vec3<f32>) -> Hit {
    var t = 0.0;
    var prev = vec2(0.0, 0.0);
    for (var k = 0u; k < params.max_steps; k++) {
        if t > params.t_max {
            return Hit(false, t, k);
        }
        let dh = above(o, d, t);
        if dh < params.eps * t {
            if k == 0u {
                return Hit(true, t, k);
            }
            return Hit(true, refine(o, d, prev, vec2(t, dh)), k);
        }
        prev = vec2(t, dh);
        t += params.relax * dh;
    }
    return Hit(false, t, params.max_steps);
}

fn normal_at(xz: vec2<f32>, t: f32) -> vec3<f32> {
    let delta = max(params.eps * t, 1e-4 * (1.0 + max(abs(xz.x), abs(xz.y))));
    let hx = (terrain_height(xz + vec2(delta, 0.0)) - terrain_height(xz - vec2(delta, 0.0))) / (2.0 * delta);
    let hz = (terrain_height(xz + vec2(0.0, delta)) - terrain_height(xz - vec2(0.0, delta))) / (2.0 * delta);
    return normalize(vec3(-hx, 1.0, -hz));
}

// Fixed samples t_i = distance ((i + 1) / n)^2 toward the sun from the
// surface point p; penumbra from min softness * D / t.
fn soft_shadow(p: vec3<f32>, sun: vec3<f32>) -> f32 {
    var res = 1.0;
    let n = params.shadow_steps;
    for (var i = 0u; i < n; i++) {
        let f = f32(i + 1u) / f32(n);
        let t = params.shadow_distance * f * f;
        res = min(res, params.shadow_softness * above(p, sun, t) / t);
        if res <= 0.0 {
            break;
        }
    }
    return smoothstep(0.0, 1.0, res);
}

fn sky(d: vec3<f32>) -> vec3<f32> {
    return mix(SKY_HORIZON, SKY_ZENITH, sqrt(clamp(d.y, 0.0, 1.0)));
}

fn shade(o: vec3<f32>, d: vec3<f32>, t: f32) -> vec3<f32> {
    let hit = o + t * d;
    let h = terrain_height(hit.xz);
    let n = normal_at(hit.xz, t);
    let p = vec3(hit.x, h, hit.z);
    let flat_ground = smoothstep(0.75, 0.92, n.y);
    let snow = smoothstep(params.snow_line, params.snow_line + SNOW_FADE, h) * smoothstep(0.55, 0.75, n.y);
    let albedo = mix(mix(ROCK, GRASS, flat_ground), SNOW, snow);
    let sun = direction(radians(params.sun_azimuth_deg), radians(params.sun_elevation_deg));
    let lambert = max(dot(n, sun), 0.0);
    var shadow = 0.0;
    if lambert > 0.0 {
        shadow = soft_shadow(p, sun);
    }
    let light = SUN_COLOR * (lambert * shadow) + AMBIENT * (0.5 + 0.5 * n.y);
    let fog = exp(-(KOSCHMIEDER / params.visibility_km) * t);
    return albedo * light * fog + SKY_HORIZON * (1.0 - fog);
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
    if params.terrain == TERRAIN_FBM {
        inv_norm = 1.0 / fbm_amplitude(params.octaves, params.gain);
    } else if params.terrain == TERRAIN_RIDGED {
        inv_norm = 1.0 / ridged_max(ridged_settings());
    }
    let camera = pinhole_look_at(params.camera_pos, params.camera_target, params.fov_deg, size.x / size.y);
    let o = camera.pos;
    let d = pinhole_ray(camera, uv);
    let m = march(o, d);
    var rgb: vec3<f32>;
    if params.view == VIEW_STEPS {
        rgb = vec3(f32(m.steps) / f32(params.max_steps));
    } else if params.view == VIEW_DEPTH {
        rgb = vec3(select(1.0, clamp(m.t / params.t_max, 0.0, 1.0), m.hit));
    } else if params.view == VIEW_NORMAL {
        rgb = select(vec3(0.0), normal_at((o + m.t * d).xz, m.t) * 0.5 + 0.5, m.hit);
    } else if m.hit {
        rgb = encode(shade(o, d, m.t));
    } else {
        rgb = encode(sky(d));
    }
    textureStore(output, id.xy, vec4(rgb, 1.0));
}
