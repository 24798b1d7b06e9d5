// clouds kernel (SPEC 3.6): a cloud slab between cloud_base and cloud_top
// (km, y up), ray marched with a light march toward the sun at each sample.
// rgb = L_cloud + T * background (linear radiance), alpha = 1 - T.
// The f64 reference, written from the same formulas, is crates/vista-kernels/src/cpu/clouds.rs.
#import vista::noise::{basis_noise, PERLIN_MAX_ABS}
#import vista::hash::{pcg3d, unit_from_hash}
#import vista::phase::dual_hg_phase
#import vista::fractal::fbm_amplitude
#import vista::geometry::{direction, pinhole_looking, pinhole_ray}

// Packed by name from kernels/clouds.toml (exposure is the host's tone map).
// Everything derived from them (camera basis, sun direction and colour, noise
// frequency, fBm normaliser, light-step layout) is computed in this file.
struct Params {
    width: u32,
    height: u32,
    steps: u32,
    light_steps: u32,
    integrator: u32,
    jitter: u32,
    jitter_seed: u32,
    profile: u32,
    octaves: u32,
    seed: u32,
    lacunarity: f32,
    gain: f32,
    cloud_base_km: f32,
    cloud_top_km: f32,
    coverage: f32,
    density_scale: f32,
    absorption: f32,
    profile_bottom: f32,
    profile_top: f32,
    noise_scale: f32,
    noise_stretch: vec3<f32>,
    yaw_deg: f32,
    wind_offset: vec3<f32>,
    pitch_deg: f32,
    camera_pos: vec3<f32>,
    fov_deg: f32,
    sun_color: vec3<f32>,
    max_distance_km: f32,
    ambient: vec3<f32>,
    sun_azimuth_deg: f32,
    sky_zenith: vec3<f32>,
    sun_elevation_deg: f32,
    sky_horizon: vec3<f32>,
    sun_intensity: f32,
    g1: f32,
    g2: f32,
    phase_blend: f32,
    powder: f32,
    ambient_bottom: f32,
    light_spread: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

const INTEGRATOR_ANALYTIC: u32 = 1u;
const JITTER_WHITE: u32 = 1u;
const JITTER_IGN: u32 = 2u;
const PROFILE_CUMULIFORM: u32 = 1u;
const PROFILE_ANVIL: u32 = 2u;
// Same cutoffs as the reference (T_CUTOFF, TAU_SUN_CUTOFF).
const T_CUTOFF: f32 = 1e-4;
const TAU_SUN_CUTOFF: f32 = 16.0;

// Derived once per invocation in main (the same for every pixel).
var<private> amplitude_sum: f32; // A = sum gain^i
var<private> inv_amplitude: f32; // 1 / A
var<private> frequency: vec3<f32>; // noise_scale * noise_stretch
var<private> light_first: f32; // first light step, fraction of the path
var<private> light_growth: f32; // ratio of consecutive light steps

// e^x - 1 without the cancellation of exp(x) - 1 near 0.
fn expm1(x: f32) -> f32 {
    if abs(x) < 1e-3 {
        return x * (1.0 + x * (0.5 + x / 6.0));
    }
    return exp(x) - 1.0;
}

// n light steps whose last is `spread` times the first: ratio r =
// spread^(1 / (n - 1)), first = (r - 1) / (r^n - 1) of the path (1 / n when uniform).
fn light_step_layout(n: u32, spread: f32) -> vec2<f32> {
    if n <= 1u || spread == 1.0 {
        return vec2(1.0 / f32(n), 1.0);
    }
    let log_r = log(spread) / f32(n - 1u);
    return vec2(expm1(log_r) / expm1(f32(n) * log_r), exp(log_r));
}

fn height01(y: f32) -> f32 {
    return (y - params.cloud_base_km) / (params.cloud_top_km - params.cloud_base_km);
}

// Plateau smoothstep(0, bottom, h) * smoothstep(0, top, 1 - h) times the genus shape.
fn height_profile(h: f32) -> f32 {
    let plateau = smoothstep(0.0, params.profile_bottom, h) * smoothstep(0.0, params.profile_top, 1.0 - h);
    if params.profile == PROFILE_CUMULIFORM {
        return plateau * (1.0 - 0.5 * h);
    }
    if params.profile == PROFILE_ANVIL {
        return plateau * (0.45 + 0.55 * smoothstep(0.5, 0.7, h));
    }
    return plateau;
}

// Slack for f32 rounding in the skip test below (G is in [0, 1]).
const SKIP_MARGIN: f32 = 1e-4;

// d(p) = density_scale * profile(h) * max(0, remap(G, 1 - coverage, 1, 0, 1)),
// G = 0.5 + 0.5 fbm3 / A (fBm normalised to [0, 1] like the fbm kernel), with
// fbm3 = sum_i gain^i N(lacunarity^i q). The octave loop stops as soon as the
// octaves left, at |N| <= PERLIN_MAX_ABS, cannot lift G above 1 - coverage:
// the density is then exactly 0 either way, so the output is unchanged (the
// sum runs in the same order as a full evaluation) while most empty samples
// cost one or two octaves instead of all of them.
fn density(p: vec3<f32>) -> f32 {
    let h = height01(p.y);
    if h < 0.0 || h > 1.0 || params.coverage <= 0.0 {
        return 0.0;
    }
    let profile = height_profile(h);
    if profile <= 0.0 {
        return 0.0;
    }
    var q = p * frequency + params.wind_offset;
    let threshold = 1.0 - params.coverage;
    var amplitude = 1.0;
    // Sum of the amplitudes of the octaves not yet added (A at the start).
    var left = amplitude_sum;
    var sum = 0.0;
    for (var i = 0u; i < params.octaves; i++) {
        sum += amplitude * basis_noise(0u, params.seed, q);
        left = max(0.0, left - amplitude);
        let g_max = 0.5 + 0.5 * (sum + PERLIN_MAX_ABS * left) * inv_amplitude;
        if g_max < threshold - SKIP_MARGIN {
            return 0.0;
        }
        amplitude *= params.gain;
        q *= params.lacunarity;
    }
    let g = 0.5 + 0.5 * sum * inv_amplitude;
    // remap(g, 1 - c, 1, 0, 1); coverage > 0 here, so the interval is never empty.
    let shape = max(0.0, (g - threshold) / params.coverage);
    return params.density_scale * profile * shape;
}

// Optical depth toward the sun up to the slab top: midpoint rule on steps
// growing geometrically (first = light_first of the path, ratio light_growth).
fn sun_optical_depth(p: vec3<f32>, s: vec3<f32>) -> f32 {
    let len = clamp((params.cloud_top_km - p.y) / s.y, 0.0, params.max_distance_km);
    let ext = 1.0 + params.absorption;
    var dt = len * light_first;
    var t = 0.0;
    var tau = 0.0;
    for (var j = 0u; j < params.light_steps; j++) {
        tau += density(p + s * (t + 0.5 * dt)) * ext * dt;
        if tau > TAU_SUN_CUTOFF {
            break;
        }
        t += dt;
        dt *= light_growth;
    }
    return tau;
}

// (1 - exp(-x)) / x; a series near 0 where the quotient loses all precision in f32.
fn analytic_weight(x: f32) -> f32 {
    if x < 1e-3 {
        return 1.0 - x * (0.5 - x / 6.0);
    }
    return (1.0 - exp(-x)) / x;
}

// Offset xi of the first sample, in steps: 0.5 (midpoint), white (pcg3d) or IGN.
fn jitter_offset(pixel: vec2<u32>) -> f32 {
    if params.jitter == JITTER_WHITE {
        return unit_from_hash(pcg3d(vec3(pixel, params.jitter_seed)).x);
    }
    if params.jitter == JITTER_IGN {
        // Jimenez 2014; the seed shifts the pattern by 5.588238 px (period 64).
        let shift = 5.588238 * f32(params.jitter_seed % 64u);
        let px = f32(pixel.x) + shift;
        let py = f32(pixel.y) + shift;
        return fract(52.9829189 * fract(0.06711056 * px + 0.00583715 * py));
    }
    return 0.5;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    amplitude_sum = fbm_amplitude(params.octaves, params.gain);
    inv_amplitude = 1.0 / amplitude_sum;
    frequency = params.noise_scale * params.noise_stretch;
    let light = light_step_layout(params.light_steps, params.light_spread);
    light_first = light.x;
    light_growth = light.y;
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size;
    // pitch is within +-89 deg (manifest range), so forward is never vertical.
    let forward = direction(radians(params.yaw_deg), radians(params.pitch_deg));
    let d = pinhole_ray(pinhole_looking(params.camera_pos, forward, params.fov_deg, size.x / size.y), uv);
    let o = params.camera_pos;

    let zenith = params.sky_zenith;
    let horizon = params.sky_horizon;
    let background = horizon + (zenith - horizon) * clamp(d.y, 0.0, 1.0);

    // Segment of the ray inside the slab and within max_distance.
    var t0 = 0.0;
    var t1 = 0.0;
    if abs(d.y) < 1e-6 {
        if o.y >= params.cloud_base_km && o.y <= params.cloud_top_km {
            t1 = params.max_distance_km;
        }
    } else {
        let ta = (params.cloud_base_km - o.y) / d.y;
        let tb = (params.cloud_top_km - o.y) / d.y;
        t0 = max(min(ta, tb), 0.0);
        t1 = min(max(ta, tb), params.max_distance_km);
    }

    var radiance = vec3(0.0);
    var transmittance = 1.0;
    if t1 > t0 {
        let s = direction(radians(params.sun_azimuth_deg), radians(params.sun_elevation_deg));
        let sun = params.sun_color * params.sun_intensity;
        let ambient = params.ambient;
        let phase = dual_hg_phase(dot(d, s), params.g1, params.g2, params.phase_blend);
        let ext = 1.0 + params.absorption;
        let dt = (t1 - t0) / f32(params.steps);
        let xi = jitter_offset(id.xy);
        for (var k = 0u; k < params.steps; k++) {
            let p = o + d * (t0 + (f32(k) + xi) * dt);
            let sigma_s = density(p);
            if sigma_s > 0.0 {
                let tau_sun = sun_optical_depth(p, s);
                let sun_vis = exp(-tau_sun) * (1.0 - params.powder * exp(-2.0 * tau_sun));
                let amb = params.ambient_bottom + (1.0 - params.ambient_bottom) * clamp(height01(p.y), 0.0, 1.0);
                let l_in = sun * (phase * sun_vis) + ambient * amb;
                let x = sigma_s * ext * dt;
                var w = dt;
                if params.integrator == INTEGRATOR_ANALYTIC {
                    w = dt * analytic_weight(x);
                }
                radiance += transmittance * sigma_s * l_in * w;
                transmittance *= exp(-x);
                if transmittance < T_CUTOFF {
                    transmittance = 0.0;
                    break;
                }
            }
        }
    }
    textureStore(output, id.xy, vec4(radiance + transmittance * background, 1.0 - transmittance));
}
