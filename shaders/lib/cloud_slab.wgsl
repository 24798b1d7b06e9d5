// A cloud layer between two altitudes (SPEC 3.6), y up, lengths in km: a
// flat slab, or a shell between two spheres around the atmosphere's planet
// (`layer`); the density field, the light march toward the sun, the primary
// march with its two integrators, and the per-pixel jitter. Shared by the clouds and
// landscape kernels; each builds the settings from its own params, with the
// derived values (noise frequency, fBm normaliser, light-step layout)
// computed in WGSL by `cloud_slab` below.
#define_import_path vista::cloud_slab

#import vista::noise::{basis_noise, PERLIN_MAX_ABS}
#import vista::hash::{pcg3d, unit_from_hash}
#import vista::phase::dual_hg_phase
#import vista::fractal::fbm_amplitude
#import vista::geometry::ray_sphere_bc
#import vista::sky::R_GROUND

const INTEGRATOR_ANALYTIC: u32 = 1u;
const JITTER_WHITE: u32 = 1u;
const JITTER_IGN: u32 = 2u;
const JITTER_STEPS_GOLDEN: u32 = 1u;
// 1 / golden ratio: offsets fract(xi + k / phi) stay evenly spread along the ray.
const INV_PHI: f32 = 0.6180339887498949;
const PROFILE_CUMULIFORM: u32 = 1u;
const PROFILE_ANVIL: u32 = 2u;
const LAYER_SHELL: u32 = 1u;
// The atmosphere's ground radius in km: the shell's planet is the sky's.
const PLANET_RADIUS_KM: f32 = R_GROUND / 1000.0;
// Same cutoffs as the reference (T_CUTOFF, TAU_SUN_CUTOFF).
const T_CUTOFF: f32 = 1e-4;
const TAU_SUN_CUTOFF: f32 = 16.0;
// Slack for f32 rounding in the density's skip test (G is in [0, 1]).
const SKIP_MARGIN: f32 = 1e-4;

// The slab's shape, density and lighting, as the caller's params give them.
struct CloudParams {
    base_km: f32,
    top_km: f32,
    coverage: f32,
    density_scale: f32,
    absorption: f32,
    profile: u32,
    profile_bottom: f32,
    profile_top: f32,
    noise_scale: f32,
    noise_stretch: vec3<f32>,
    wind_offset: vec3<f32>,
    octaves: u32,
    lacunarity: f32,
    gain: f32,
    seed: u32,
    max_distance_km: f32,
    steps: u32,
    light_steps: u32,
    light_spread: f32,
    step_spread: f32,
    step_km: f32,
    jitter_steps: u32,
    integrator: u32,
    forward_g: f32,
    backward_g: f32,
    phase_blend: f32,
    powder: f32,
    ambient: vec3<f32>,
    ambient_bottom: f32,
    layer: u32,
    basis: u32,
}

// CloudParams plus what is derived from them once per invocation.
struct CloudSlab {
    c: CloudParams,
    amplitude_sum: f32, // A = sum gain^i
    inv_amplitude: f32, // 1 / A
    frequency: vec3<f32>, // noise_scale * noise_stretch
    light_first: f32, // first light step, fraction of the path
    light_growth: f32, // ratio of consecutive light steps
    // The shell's centre is (centre_xz.x, -R, centre_xz.y): under the
    // camera, as the atmosphere places its planet.
    centre_xz: vec2<f32>,
}

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

fn cloud_slab(c: CloudParams, camera: vec3<f32>) -> CloudSlab {
    let a = fbm_amplitude(c.octaves, c.gain);
    let light = light_step_layout(c.light_steps, c.light_spread);
    return CloudSlab(c, a, 1.0 / a, c.noise_scale * c.noise_stretch, light.x, light.y, camera.xz);
}

// The point's altitude: y for the slab; for the shell |q| - R with
// q = p - centre, as (|q|^2 - R^2) / (|q| + R) where |q|^2 - R^2 =
// dx^2 + dz^2 + y (y + 2R) is formed without the cancellation of squares
// near 6360^2 (an f32 ulp there is 4 km^2).
fn altitude(s: CloudSlab, p: vec3<f32>) -> f32 {
    if s.c.layer != LAYER_SHELL {
        return p.y;
    }
    let dx = p.x - s.centre_xz.x;
    let dz = p.z - s.centre_xz.y;
    let k = dx * dx + dz * dz + p.y * (p.y + 2.0 * PLANET_RADIUS_KM);
    let len = sqrt(dx * dx + dz * dz + (p.y + PLANET_RADIUS_KM) * (p.y + PLANET_RADIUS_KM));
    return k / (len + PLANET_RADIUS_KM);
}

fn height01(s: CloudSlab, y: f32) -> f32 {
    return (y - s.c.base_km) / (s.c.top_km - s.c.base_km);
}

// Where the ray o + t d (unit d) meets the sphere of radius R + h around the
// shell's centre: ray_sphere_bc with b = q . d and c = |q|^2 - (R + h)^2 =
// dx^2 + dz^2 + (y - h)(y + h + 2R), q = o - centre (no cancellation).
fn shell_sphere(s: CloudSlab, o: vec3<f32>, d: vec3<f32>, h: f32) -> vec2<f32> {
    let q = vec3(o.x - s.centre_xz.x, o.y + PLANET_RADIUS_KM, o.z - s.centre_xz.y);
    let c = q.x * q.x + q.z * q.z + (o.y - h) * (o.y + h + 2.0 * PLANET_RADIUS_KM);
    return ray_sphere_bc(dot(q, d), c);
}

// The first part (t0, t1) of t >= 0 inside the outer sphere and outside the
// inner one; t1 <= t0 when there is none. A ray that crosses the inner
// sphere and comes out of it again (from above the layer, past the limb)
// keeps only its first crossing.
fn shell_segment(s: CloudSlab, o: vec3<f32>, d: vec3<f32>) -> vec2<f32> {
    let outer = shell_sphere(s, o, d, s.c.top_km);
    if outer.y <= 0.0 {
        return vec2(0.0, 0.0);
    }
    let inner = shell_sphere(s, o, d, s.c.base_km);
    var t0 = max(outer.x, 0.0);
    var t1 = outer.y;
    let crosses_inner = inner.y > 0.0;
    if crosses_inner && inner.x <= t0 {
        t0 = max(t0, inner.y);
    } else if crosses_inner {
        t1 = min(t1, inner.x);
    }
    return vec2(t0, min(t1, s.c.max_distance_km));
}

// Plateau smoothstep(0, bottom, h) * smoothstep(0, top, 1 - h) times the genus shape.
fn height_profile(s: CloudSlab, h: f32) -> f32 {
    let plateau = smoothstep(0.0, s.c.profile_bottom, h) * smoothstep(0.0, s.c.profile_top, 1.0 - h);
    if s.c.profile == PROFILE_CUMULIFORM {
        return plateau * (1.0 - 0.5 * h);
    }
    if s.c.profile == PROFILE_ANVIL {
        return plateau * (0.45 + 0.55 * smoothstep(0.5, 0.7, h));
    }
    return plateau;
}

// d(p) = density_scale * profile(h) * max(0, remap(G, 1 - coverage, 1, 0, 1)),
// G = 0.5 + 0.5 fbm3 / A (fBm normalised to [0, 1] like the fbm kernel), with
// fbm3 = sum_i gain^i N(lacunarity^i q). The octave loop stops as soon as the
// octaves left, at |N| <= PERLIN_MAX_ABS, cannot lift G above 1 - coverage:
// the density is then exactly 0 either way, so the output is unchanged (the
// sum runs in the same order as a full evaluation) while most empty samples
// cost one or two octaves instead of all of them.
fn cloud_density(s: CloudSlab, p: vec3<f32>) -> f32 {
    let h = height01(s, altitude(s, p));
    if h < 0.0 || h > 1.0 || s.c.coverage <= 0.0 {
        return 0.0;
    }
    let profile = height_profile(s, h);
    if profile <= 0.0 {
        return 0.0;
    }
    var q = p * s.frequency + s.c.wind_offset;
    let threshold = 1.0 - s.c.coverage;
    var amplitude = 1.0;
    // Sum of the amplitudes of the octaves not yet added (A at the start).
    var left = s.amplitude_sum;
    var sum = 0.0;
    for (var i = 0u; i < s.c.octaves; i++) {
        sum += amplitude * basis_noise(s.c.basis, s.c.seed, q);
        left = max(0.0, left - amplitude);
        let g_max = 0.5 + 0.5 * (sum + PERLIN_MAX_ABS * left) * s.inv_amplitude;
        if g_max < threshold - SKIP_MARGIN {
            return 0.0;
        }
        amplitude *= s.c.gain;
        q *= s.c.lacunarity;
    }
    let g = 0.5 + 0.5 * sum * s.inv_amplitude;
    // remap(g, 1 - c, 1, 0, 1); coverage > 0 here, so the interval is never empty.
    let shape = max(0.0, (g - threshold) / s.c.coverage);
    return s.c.density_scale * profile * shape;
}

// Optical depth toward the sun (unit sun_dir, above the horizon) through
// the layer from p: midpoint rule on steps growing geometrically (first =
// light_first of the path, ratio light_growth) from where the sun ray is
// first inside the layer (p itself for a point in it; the base for a
// point below it, so a cloud shadow on the ground spends no step in the
// empty air under the layer) up to its top, cut at max_distance from there.
fn sun_optical_depth(s: CloudSlab, p_from: vec3<f32>, sun_dir: vec3<f32>) -> f32 {
    var p = p_from + sun_dir * max(0.0, (s.c.base_km - p_from.y) / sun_dir.y);
    var len = clamp((s.c.top_km - p.y) / sun_dir.y, 0.0, s.c.max_distance_km);
    if s.c.layer == LAYER_SHELL {
        // Below the base p_from is inside the inner sphere: start where the sun ray leaves it.
        let inner = shell_sphere(s, p_from, sun_dir, s.c.base_km);
        let start = select(0.0, inner.y, inner.x <= 0.0 && inner.y > 0.0);
        p = p_from + sun_dir * start;
        len = clamp(shell_sphere(s, p_from, sun_dir, s.c.top_km).y - start, 0.0, s.c.max_distance_km);
    }
    let ext = 1.0 + s.c.absorption;
    var dt = len * s.light_first;
    var t = 0.0;
    var tau = 0.0;
    for (var j = 0u; j < s.c.light_steps; j++) {
        tau += cloud_density(s, p + sun_dir * (t + 0.5 * dt)) * ext * dt;
        if tau > TAU_SUN_CUTOFF {
            break;
        }
        t += dt;
        dt *= s.light_growth;
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
fn jitter_offset(jitter: u32, seed: u32, pixel: vec2<u32>) -> f32 {
    if jitter == JITTER_WHITE {
        return unit_from_hash(pcg3d(vec3(pixel, seed)).x);
    }
    if jitter == JITTER_IGN {
        // Jimenez 2014; the seed shifts the pattern by 5.588238 px (period 64).
        let shift = 5.588238 * f32(seed % 64u);
        let px = f32(pixel.x) + shift;
        let py = f32(pixel.y) + shift;
        return fract(52.9829189 * fract(0.06711056 * px + 0.00583715 * py));
    }
    return 0.5;
}

// The part (t0, t1) of the ray o + t d inside the layer and within
// max_distance; t1 <= t0 when there is none. The camera may be inside.
fn layer_segment(s: CloudSlab, o: vec3<f32>, d: vec3<f32>) -> vec2<f32> {
    if s.c.layer == LAYER_SHELL {
        return shell_segment(s, o, d);
    }
    var t0 = 0.0;
    var t1 = 0.0;
    if abs(d.y) < 1e-6 {
        if o.y >= s.c.base_km && o.y <= s.c.top_km {
            t1 = s.c.max_distance_km;
        }
    } else {
        let ta = (s.c.base_km - o.y) / d.y;
        let tb = (s.c.top_km - o.y) / d.y;
        t0 = max(min(ta, tb), 0.0);
        t1 = min(max(ta, tb), s.c.max_distance_km);
    }
    return vec2(t0, t1);
}

// Marches [t0, t1] of the ray o + t d (unit d) in `steps` steps, equal or
// (step_spread > 1) growing geometrically from the camera, each sample xi of
// its step in (jitter_steps golden: fract(xi + k / phi) for step k); `sun` is
// the sun's radiance arriving at the slab from sun_dir. Returns (L_cloud, T):
// the radiance the cloud sends along the ray and its transmittance (0 after
// the cutoff).
fn cloud_march(s: CloudSlab, o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, xi: f32, sun_dir: vec3<f32>,
               sun: vec3<f32>) -> vec4<f32> {
    var radiance = vec3(0.0);
    var transmittance = 1.0;
    let phase = dual_hg_phase(dot(d, sun_dir), s.c.forward_g, s.c.backward_g, s.c.phase_blend);
    let ext = 1.0 + s.c.absorption;
    let uniform = s.c.step_spread == 1.0;
    // step_km > 0: as many steps as the segment needs at that length, at
    // most `steps` (short paths through the slab need fewer).
    var n = s.c.steps;
    if s.c.step_km > 0.0 {
        n = u32(clamp(ceil((t1 - t0) / s.c.step_km), 1.0, f32(s.c.steps)));
    }
    let dt_uniform = (t1 - t0) / f32(n);
    // Geometric steps: the ends of step k come from r^k in closed form; a
    // running product over hundreds of steps drifts by ~1e-5 in f32
    // (measured 93 dB against the f64 reference).
    let log_r = log(s.c.step_spread) / f32(max(n, 2u) - 1u);
    let total = expm1(f32(n) * log_r);
    var dt = dt_uniform;
    var end_frac = 0.0; // where step k - 1 ended, fraction of the segment
    for (var k = 0u; k < n; k++) {
        var xk = xi;
        if s.c.jitter_steps == JITTER_STEPS_GOLDEN {
            xk = fract(xi + f32(k) * INV_PHI);
        }
        var t = t0 + (f32(k) + xk) * dt_uniform;
        if !uniform {
            let start_frac = end_frac;
            end_frac = expm1(f32(k + 1u) * log_r) / total;
            dt = (t1 - t0) * (end_frac - start_frac);
            t = t0 + (t1 - t0) * start_frac + xk * dt;
        }
        let p = o + d * t;
        let sigma_s = cloud_density(s, p);
        if sigma_s > 0.0 {
            let tau_sun = sun_optical_depth(s, p, sun_dir);
            let sun_vis = exp(-tau_sun) * (1.0 - s.c.powder * exp(-2.0 * tau_sun));
            let amb = s.c.ambient_bottom + (1.0 - s.c.ambient_bottom) * clamp(height01(s, altitude(s, p)), 0.0, 1.0);
            let l_in = sun * (phase * sun_vis) + s.c.ambient * amb;
            let x = sigma_s * ext * dt;
            var w = dt;
            if s.c.integrator == INTEGRATOR_ANALYTIC {
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
    return vec4(radiance, transmittance);
}
