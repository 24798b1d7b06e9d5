// Sphere-traced heightfield terrain (SPEC 3.4), 1 unit = 1 km: the height
// function, the relax march with its hit refinement, normals, the soft
// shadow and the surface shading. Shared by the heightfield and landscape
// kernels; each builds the settings from its own params (derived values,
// such as the normaliser, computed by the caller's WGSL).
#define_import_path vista::terrain

#import vista::fractal::{FbmSettings, RidgedSettings, fbm2, fbm_amplitude, ridged2, ridged_max}

const TERRAIN_FBM: u32 = 0u;
const TERRAIN_RIDGED: u32 = 1u;
const TERRAIN_PLANE: u32 = 2u;
const TERRAIN_SINE: u32 = 3u;
const REFINE_ITERS: u32 = 16u;
const REFINE_TOL: f32 = 0.01;

// Surface colours (linear), the same constants as crates/vista-kernels/src/cpu/heightfield.rs.
const ROCK = vec3(0.36, 0.31, 0.27);
const GRASS = vec3(0.16, 0.26, 0.08);
const SNOW = vec3(0.85, 0.87, 0.90);
const SNOW_FADE: f32 = 0.2;

struct Terrain {
    kind: u32,
    fbm: FbmSettings,
    ridged: RidgedSettings,
    amplitude: f32,
    scale: f32,
    plane_slope: vec2<f32>,
    // T's normaliser: 1 / A (fbm) or 1 / ridged max (ridged); 1 otherwise.
    inv_norm: f32,
}

// The terrain params as a kernel's manifest names them (heightfield, landscape).
struct TerrainParams {
    kind: u32,
    basis: u32,
    seed: u32,
    octaves: u32,
    lacunarity: f32,
    gain: f32,
    octave_rotation_deg: f32,
    ridge_h: f32,
    ridge_offset: f32,
    ridge_gain: f32,
    amplitude: f32,
    scale: f32,
    plane_slope: vec2<f32>,
}

// The terrain of those params, with what is derived from them (the octave
// rotation's cos/sin; T's normaliser: 1 / A for fbm, 1 / max for ridged)
// computed here, once per invocation.
fn terrain_of(p: TerrainParams) -> Terrain {
    let theta = radians(p.octave_rotation_deg);
    let fbm = FbmSettings(p.basis, p.seed, p.octaves, p.lacunarity, p.gain, cos(theta), sin(theta));
    let ridged = RidgedSettings(p.basis, p.seed, p.octaves, p.lacunarity, p.ridge_h, p.ridge_offset, p.ridge_gain);
    var inv_norm = 1.0;
    if is_kind(p.kind, TERRAIN_FBM) {
        inv_norm = 1.0 / fbm_amplitude(p.octaves, p.gain);
    } else if is_kind(p.kind, TERRAIN_RIDGED) {
        inv_norm = 1.0 / ridged_max(ridged);
    }
    return Terrain(p.kind, fbm, ridged, p.amplitude, p.scale, p.plane_slope, inv_norm);
}

// Whether the terrain kind (the `terrain` param) is k. A kernel whose
// manifest lists `terrain` under `specialize` is composed with
// TERRAIN_IS_<KIND>: the answer is then a constant and the other kinds'
// height functions are not compiled in (llvmpipe would run every one of
// them, masked, at each height sample). Without the def, the run-time test.
fn is_kind(kind: u32, k: u32) -> bool {
#ifdef TERRAIN_IS_FBM
    return k == TERRAIN_FBM;
#else ifdef TERRAIN_IS_RIDGED
    return k == TERRAIN_RIDGED;
#else ifdef TERRAIN_IS_PLANE
    return k == TERRAIN_PLANE;
#else ifdef TERRAIN_IS_SINE
    return k == TERRAIN_SINE;
#else
    return kind == k;
#endif
}

// The relax march (SPEC 3.4).
struct March {
    t_max: f32,
    relax: f32,
    eps: f32,
    max_steps: u32,
}

fn terrain_height(s: Terrain, xz: vec2<f32>) -> f32 {
    let q = xz * s.scale;
    if is_kind(s.kind, TERRAIN_FBM) {
        return s.amplitude * fbm2(s.fbm, q, 0.0) * s.inv_norm;
    }
    if is_kind(s.kind, TERRAIN_RIDGED) {
        return s.amplitude * ridged2(s.ridged, q, 0.0) * s.inv_norm;
    }
    if is_kind(s.kind, TERRAIN_PLANE) {
        return s.amplitude + dot(s.plane_slope, xz);
    }
    return s.amplitude * sin(q.x) * cos(q.y);
}

// D(t): height of the ray point above the terrain.
fn above(s: Terrain, o: vec3<f32>, d: vec3<f32>, t: f32) -> f32 {
    let p = o + t * d;
    return p.y - terrain_height(s, p.xz);
}

// Zero of D interpolated between the last two samples a (D > 0) and b
// (D < eps t), repeated with the newest two points until |D| <= eps t / 100:
// secant steps while above the terrain (stop when D stops falling), Illinois
// false position keeping the sign change once under it. Keeps the best |D|.
fn refine(s: Terrain, eps: f32, o: vec3<f32>, d: vec3<f32>, a0: vec2<f32>, b0: vec2<f32>) -> f32 {
    var a = a0;
    var b = b0;
    var best_t = b.x;
    var best_d = abs(b.y);
    var last = 0;
    for (var i = 0u; i < REFINE_ITERS; i++) {
        if a.y <= b.y || best_d <= REFINE_TOL * eps * best_t {
            break;
        }
        let tr = b.x + b.y * (b.x - a.x) / (a.y - b.y);
        let dr = above(s, o, d, tr);
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

// t_{k+1} = t_k + relax D(t_k) from 0; a hit at the first D < eps t (refined),
// a miss past t_max or after max_steps.
fn march(s: Terrain, m: March, o: vec3<f32>, d: vec3<f32>) -> Hit {
    var t = 0.0;
    var prev = vec2(0.0, 0.0);
    for (var k = 0u; k < m.max_steps; k++) {
        if t > m.t_max {
            return Hit(false, t, k);
        }
        let dh = above(s, o, d, t);
        if dh < m.eps * t {
            if k == 0u {
                return Hit(true, t, k);
            }
            return Hit(true, refine(s, m.eps, o, d, prev, vec2(t, dh)), k);
        }
        prev = vec2(t, dh);
        t += m.relax * dh;
    }
    return Hit(false, t, m.max_steps);
}

fn normal_at(s: Terrain, eps: f32, xz: vec2<f32>, t: f32) -> vec3<f32> {
    let delta = max(eps * t, 1e-4 * (1.0 + max(abs(xz.x), abs(xz.y))));
    let hx = (terrain_height(s, xz + vec2(delta, 0.0)) - terrain_height(s, xz - vec2(delta, 0.0))) / (2.0 * delta);
    let hz = (terrain_height(s, xz + vec2(0.0, delta)) - terrain_height(s, xz - vec2(0.0, delta))) / (2.0 * delta);
    return normalize(vec3(-hx, 1.0, -hz));
}

// The soft shadow's fixed samples: count, farthest distance, penumbra softness.
struct Shadow {
    steps: u32,
    distance: f32,
    softness: f32,
}

// Fixed samples t_i = distance ((i + 1) / n)^2 toward the sun from the
// surface point p; penumbra from min softness * D / t.
fn soft_shadow(s: Terrain, sh: Shadow, p: vec3<f32>, sun: vec3<f32>) -> f32 {
    var res = 1.0;
    let n = sh.steps;
    for (var i = 0u; i < n; i++) {
        let f = f32(i + 1u) / f32(n);
        let t = sh.distance * f * f;
        res = min(res, sh.softness * above(s, p, sun, t) / t);
        if res <= 0.0 {
            break;
        }
    }
    return smoothstep(0.0, 1.0, res);
}

// What lights a terrain point: the direction toward the sun, the sun's
// colour arriving there and the sky's ambient colour (times 0.5 + 0.5 n.y).
struct Light {
    sun_dir: vec3<f32>,
    sun: vec3<f32>,
    ambient: vec3<f32>,
}

// The terrain point under the ray point at distance t (on the surface).
fn surface_point(s: Terrain, o: vec3<f32>, d: vec3<f32>, t: f32) -> vec3<f32> {
    let hit = o + t * d;
    return vec3(hit.x, terrain_height(s, hit.xz), hit.z);
}

// Radiance leaving the terrain hit at distance t along d (before any fog or
// aerial perspective): albedo (rock, grass on flat ground, snow above
// snow_line) x (sun x Lambert x soft shadow + ambient x (0.5 + 0.5 n.y)).
fn surface_radiance(s: Terrain, eps: f32, sh: Shadow, snow_line: f32, o: vec3<f32>, d: vec3<f32>, t: f32,
                    light: Light) -> vec3<f32> {
    let p = surface_point(s, o, d, t);
    let h = p.y;
    let n = normal_at(s, eps, p.xz, t);
    let flat_ground = smoothstep(0.75, 0.92, n.y);
    let snow = smoothstep(snow_line, snow_line + SNOW_FADE, h) * smoothstep(0.55, 0.75, n.y);
    let albedo = mix(mix(ROCK, GRASS, flat_ground), SNOW, snow);
    let lambert = max(dot(n, light.sun_dir), 0.0);
    var shadow = 0.0;
    if lambert > 0.0 {
        shadow = soft_shadow(s, sh, p, light.sun_dir);
    }
    return albedo * (light.sun * (lambert * shadow) + light.ambient * (0.5 + 0.5 * n.y));
}
