// Unit tests of vista::cloud_slab (`vista test`). Expected values computed
// in f64 (Python's math module) from SPEC 3.6 and the math each function
// documents: math.expm1; n light steps of ratio r = spread^(1 / (n - 1)),
// first (r - 1) / (r^n - 1); h = (y - base) / (top - base); the profile
// smoothstep(0, bottom, h) smoothstep(0, top, 1 - h) (smoothstep t^2 (3 - 2t))
// times 1 - h / 2 (cumuliform) or 0.45 + 0.55 smoothstep(0.5, 0.7, h)
// (anvil); (1 - e^-x) / x; the layer's planes and spheres (R = 6360 km);
// d = density_scale profile max(0, (G - (1 - coverage)) / coverage) with
// G = 0.5 + 0.5 fbm3 / A over Improved Noise (Perlin 2002, from its
// published reference, seed-0 table); pcg3d as published (JCGT 2020) and
// Jimenez's interleaved gradient noise (2014).
//
// The light and primary marches are tested on a uniform layer (noise_scale
// 0 and no wind put every noise sample at the lattice point 0, where
// Improved Noise is 0, so G = 1/2 and, at coverage 1, d = density_scale / 2;
// profile roundings of 0.001 keep every sample on the plateau): there the
// optical depth over a path of length L is d (1 + absorption) L exactly
// (Beer-Lambert), the steps' transmittances multiply to exp(-d ext L), the
// analytic integrator sums an ambient-lit layer to ambient (1 - T) / ext in
// closed form, the Riemann one to a geometric series; with sunlight the
// few samples are summed in Python at the documented positions (k + xi)
// dt, xi advanced by 1 / phi per step (golden), with the sun's optical
// depth d (5 - y) straight up, powder e^-tau (1 - powder e^-2tau), the
// dual Henyey-Greenstein phase mix(HG(mu, g1), HG(mu, g2), blend) and
// ambient ambient_bottom + (1 - ambient_bottom) h.
//
// Enum params by their index in kernels/clouds.toml: profile stratiform 0,
// cumuliform 1, anvil 2; layer slab 0, shell 1; jitter none 0, white 1, ign 2;
// jitter_steps shared 0, golden 1; integrator riemann 0, analytic 1.
// Values well below 1 are compared by their ratio to the expected value,
// so the default tolerance (1e-5) is relative for them too.
#import vista::cloud_slab::{CloudParams, CloudSlab, cloud_slab, expm1, light_step_layout, height01, height_profile, analytic_weight, altitude, layer_segment, cloud_density, jitter_offset, sun_optical_depth, cloud_march}
#import wgsl_test::{expect, expectNear, expectNearV2f, expectNearV3f, expectNearV4f}

// A layer from 2 to 5 km: density_scale 10, profile rounding 0.1 at the
// base and 0.4 at the top, noise_scale 1 (stretch 1), wind (0.25, 0, 0),
// lacunarity 2, gain 0.5, seed 0, perlin, 12 light steps of spread 4,
// max_distance 100 km.
fn params(profile: u32, layer: u32, coverage: f32, octaves: u32) -> CloudParams {
    return CloudParams(2.0, 5.0, coverage, 10.0, 0.0, profile, 0.1, 0.4, 1.0, vec3<f32>(1.0), vec3<f32>(0.25, 0.0, 0.0),
                       octaves, 2.0, 0.5, 0u, 100.0, 64u, 12u, 4.0, 1.0, 0.0, 0u, 0u, 0.7, -0.5, 0.5, 0.0,
                       vec3<f32>(0.1), 0.5, layer, 0u);
}

fn slab(profile: u32, coverage: f32, octaves: u32) -> CloudSlab {
    return cloud_slab(params(profile, 0u, coverage, octaves), vec3<f32>(0.0));
}

// The uniform layer from 2 to 5 km (see the header): coverage 1, so the
// density is density_scale / 2 everywhere in it; 3 octaves; 12 light steps
// of spread 4; 64 equal primary steps, Riemann; ambient (0.1, 0.2, 0.3) at
// every height (ambient_bottom 1), no powder.
fn uniform_params(density_scale: f32, absorption: f32, layer: u32) -> CloudParams {
    return CloudParams(2.0, 5.0, 1.0, density_scale, absorption, 0u, 0.001, 0.001, 0.0, vec3<f32>(1.0), vec3<f32>(0.0),
                       3u, 2.0, 0.5, 0u, 100.0, 64u, 12u, 4.0, 1.0, 0.0, 0u, 0u, 0.7, -0.5, 0.5, 0.0,
                       vec3<f32>(0.1, 0.2, 0.3), 1.0, layer, 0u);
}

@test
fn expm1_matches_math_expm1() {
    // Series side (|x| < 1e-3): math.expm1(1e-4), math.expm1(-5e-4).
    expectNear(expm1(1e-4) / 0.00010000500016667084, 1.0);
    expectNear(expm1(-5e-4) / -0.0004998750208307294, 1.0);
    expectNear(expm1(0.0), 0.0, 0.0);
    // exp side: math.expm1(0.5), (-2), (3).
    expectNear(expm1(0.5), 0.6487212707001282);
    expectNear(expm1(-2.0), -0.8646647167633873);
    expectNear(expm1(3.0), 19.085536923187668);
}

@test
fn light_steps_grow_geometrically() {
    // n = 12, spread 4: r = 4^(1/11) = 1.1343125221954626, first =
    // (r - 1) / (r^12 - 1) = 0.03797088665611335 (so first r^11 = 4 first
    // and the 12 steps sum to the path).
    expectNearV2f(light_step_layout(12u, 4.0) / vec2<f32>(0.03797088665611335, 1.1343125221954626), vec2<f32>(1.0));
    // n = 12, spread 8: r = 8^(1/11) = 1.2080894444044472, first 0.024015727126635012.
    expectNearV2f(light_step_layout(12u, 8.0) / vec2<f32>(0.024015727126635012, 1.2080894444044472), vec2<f32>(1.0));
    // Two steps of spread 3: 1/4 and 3/4 of the path.
    expectNearV2f(light_step_layout(2u, 3.0), vec2<f32>(0.25, 3.0));
    // Uniform (spread 1) and a single step: 1 / n, ratio 1.
    expectNearV2f(light_step_layout(8u, 1.0), vec2<f32>(0.125, 1.0));
    expectNearV2f(light_step_layout(1u, 3.0), vec2<f32>(1.0, 1.0));
    // cloud_slab derives them from light_steps and light_spread, and
    // A = 1 + 0.5 + 0.25 + 0.125 = 1.875 for 4 octaves of gain 0.5.
    var c = params(0u, 0u, 0.5, 4u);
    c.noise_scale = 1.5;
    c.noise_stretch = vec3<f32>(1.0, 2.0, 0.5);
    let s = cloud_slab(c, vec3<f32>(7.0, 1.0, -3.0));
    expectNear(s.light_first / 0.03797088665611335, 1.0);
    expectNear(s.light_growth, 1.1343125221954626);
    expectNear(s.amplitude_sum, 1.875);
    expectNear(s.inv_amplitude, 0.5333333333333333);
    expectNearV3f(s.frequency, vec3<f32>(1.5, 3.0, 0.75));
    expectNearV2f(s.centre_xz, vec2<f32>(7.0, -3.0));
}

@test
fn height01_spans_the_layer() {
    // (y - 2) / (5 - 2).
    let s = slab(0u, 0.5, 1u);
    expectNear(height01(s, 2.0), 0.0);
    expectNear(height01(s, 5.0), 1.0);
    expectNear(height01(s, 3.5), 0.5);
    expectNear(height01(s, 2.6), 0.2);
    expectNear(height01(s, 6.5), 1.5);
}

@test
fn height_profile_plateau_and_genus_shapes() {
    // Stratiform (the plateau alone): 0 at both ends, 1 inside; at h = 0.03
    // t = 0.3 gives 0.216; at 0.65 the top rounding, t = 0.875, 0.95703125;
    // at 0.8 t = 0.5, 0.5.
    let st = slab(0u, 0.5, 1u);
    expectNear(height_profile(st, 0.0), 0.0, 0.0);
    expectNear(height_profile(st, 1.0), 0.0, 0.0);
    expectNear(height_profile(st, 0.03), 0.216);
    expectNear(height_profile(st, 0.5), 1.0);
    expectNear(height_profile(st, 0.65), 0.9570312499999999);
    expectNear(height_profile(st, 0.8), 0.5);
    // Cumuliform, times 1 - h / 2: 0.21276, 0.75, 0.64599609375, 0.3.
    let cu = slab(1u, 0.5, 1u);
    expectNear(height_profile(cu, 0.0), 0.0, 0.0);
    expectNear(height_profile(cu, 0.03), 0.21276);
    expectNear(height_profile(cu, 0.5), 0.75);
    expectNear(height_profile(cu, 0.65), 0.64599609375);
    expectNear(height_profile(cu, 0.8), 0.3);
    // Anvil, times 0.45 + 0.55 smoothstep(0.5, 0.7, h): 0.0972, 0.45,
    // 0.8747863769531251, 0.5; 0 at the top.
    let an = slab(2u, 0.5, 1u);
    expectNear(height_profile(an, 0.03), 0.0972);
    expectNear(height_profile(an, 0.5), 0.45);
    expectNear(height_profile(an, 0.65), 0.8747863769531251);
    expectNear(height_profile(an, 0.8), 0.5);
    expectNear(height_profile(an, 1.0), 0.0, 0.0);
}

@test
fn analytic_weight_is_one_minus_exp_over_x() {
    // (1 - e^-x) / x = -math.expm1(-x) / x: 1 at 0, then at 1e-4 (the
    // series), 1 and 5.
    expectNear(analytic_weight(0.0), 1.0, 0.0);
    expectNear(analytic_weight(1e-4), 0.9999500016666251);
    expectNear(analytic_weight(1.0), 0.6321205588285577);
    expectNear(analytic_weight(5.0), 0.1986524106001829);
}

@test
fn layer_geometry_of_slab_and_shell() {
    let s = slab(0u, 0.5, 1u);
    let o = vec3<f32>(0.0);
    // From the ground straight up: the planes y = 2 and y = 5.
    expectNearV2f(layer_segment(s, o, vec3<f32>(0.0, 1.0, 0.0)), vec2<f32>(2.0, 5.0));
    // 45 degrees up: 2 sqrt 2 and 5 sqrt 2.
    let d45 = vec3<f32>(0.0, 0.7071067811865476, 0.7071067811865476);
    expectNearV2f(layer_segment(s, o, d45), vec2<f32>(2.8284271247461903, 7.0710678118654755));
    // Inside the slab, horizontally: from the camera to max_distance.
    expectNearV2f(layer_segment(s, vec3<f32>(0.0, 3.0, 0.0), vec3<f32>(1.0, 0.0, 0.0)), vec2<f32>(0.0, 100.0));
    // Looking down from under it: nothing (t1 <= t0).
    let down = layer_segment(s, o, vec3<f32>(0.0, -1.0, 0.0));
    expect(down.y <= down.x);
    // The shell around (0, -R, 0), R = 6360 km: altitude |p - centre| - R,
    // sqrt(3^2 + 6362^2 + 4^2) - 6360 = 2.0019647906428872 and
    // sqrt(1.5^2 + 6367^2 + 2^2) - 6360 = 7.000490811980853.
    let sh = cloud_slab(params(0u, 1u, 0.5, 1u), vec3<f32>(0.0));
    expectNear(altitude(sh, vec3<f32>(3.0, 2.0, 4.0)), 2.0019647906428872);
    expectNear(altitude(sh, vec3<f32>(1.5, 7.0, -2.0)), 7.000490811980853);
    // Horizontally from the ground: out of the sphere R + 2 at
    // sqrt(6362^2 - 6360^2) = 159.51175505272332, out of R + 5 at
    // sqrt(6365^2 - 6360^2) = 252.23996511258878; cut at max_distance
    // (100 km) nothing is left (t1 <= t0), at 1000 km all of it.
    expectNearV2f(layer_segment(sh, o, vec3<f32>(1.0, 0.0, 0.0)), vec2<f32>(159.51175505272332, 100.0));
    var far = params(0u, 1u, 0.5, 1u);
    far.max_distance_km = 1000.0;
    let sf = cloud_slab(far, vec3<f32>(0.0));
    expectNearV2f(layer_segment(sf, o, vec3<f32>(1.0, 0.0, 0.0)), vec2<f32>(159.51175505272332, 252.23996511258878));
}

@test
fn cloud_density_from_the_noise() {
    // p = (0.3, 3.5, 1.7): h = 0.5 (profile 1), q = p + wind = (0.55, 3.5,
    // 1.7); perlin(q) = 0.37673479538, perlin(2 q) = 0.04308827136.
    let p = vec3<f32>(0.3, 3.5, 1.7);
    // One octave, coverage 1: 10 * (0.5 + 0.5 * 0.37673479538).
    expectNear(cloud_density(slab(0u, 1.0, 1u), p), 6.8836739769);
    // Two octaves: G = 0.5 + 0.5 (N1 + 0.5 N2) / 1.5 = 0.6327596436866667.
    expectNear(cloud_density(slab(0u, 1.0, 2u), p), 6.327596436866667);
    // Coverage 0.6: 10 * (G - 0.4) / 0.6.
    expectNear(cloud_density(slab(0u, 0.6, 2u), p), 3.8793273947777784);
    // Coverage 0 is empty (SPEC 3.6), and so is the air outside the layer.
    expectNear(cloud_density(slab(0u, 0.0, 2u), p), 0.0, 0.0);
    expectNear(cloud_density(slab(0u, 1.0, 2u), vec3<f32>(0.3, 1.5, 1.7)), 0.0, 0.0);
    expectNear(cloud_density(slab(0u, 1.0, 2u), vec3<f32>(0.3, 5.5, 1.7)), 0.0, 0.0);
}

@test
fn jitter_offsets() {
    // none: the midpoint.
    expectNear(jitter_offset(0u, 9u, vec2<u32>(3u, 5u)), 0.5, 0.0);
    // white: (pcg3d(3, 5, 9).x >> 8) * 2^-24, exact in f32.
    expectNear(jitter_offset(1u, 9u, vec2<u32>(3u, 5u)), 0.10639894008636475, 0.0);
    // ign, seed 0: fract(52.9829189 fract(0.06711056 * 3 + 0.00583715 * 5)).
    expectNear(jitter_offset(2u, 0u, vec2<u32>(3u, 5u)), 0.2134862987264281);
}

@test
fn sun_optical_depth_of_a_uniform_slab() {
    // d = 1, ext 1.5: tau = 1.5 L for the path L to the top (or to
    // max_distance), whatever the 12 growing steps.
    let s = cloud_slab(uniform_params(2.0, 0.5, 0u), vec3<f32>(0.0));
    expectNear(cloud_density(s, vec3<f32>(0.3, 3.0, -1.0)), 1.0);
    let up = vec3<f32>(0.0, 1.0, 0.0);
    let slant = vec3<f32>(0.6, 0.8, 0.0);
    // From y = 3 straight up: L = 2; slanted: L = 2 / 0.8.
    expectNear(sun_optical_depth(s, vec3<f32>(0.0, 3.0, 0.0), up), 3.0);
    expectNear(sun_optical_depth(s, vec3<f32>(0.0, 3.0, 0.0), slant), 3.75);
    // From below the layer (y = 0.5) the path starts at the base: L = 3 / 0.8.
    expectNear(sun_optical_depth(s, vec3<f32>(1.0, 0.5, 2.0), slant), 5.625);
    // Above the layer there is nothing to cross.
    expectNear(sun_optical_depth(s, vec3<f32>(0.0, 6.0, 0.0), up), 0.0, 0.0);
    // max_distance 1 km cuts the path to L = 1.
    var c = uniform_params(2.0, 0.5, 0u);
    c.max_distance_km = 1.0;
    expectNear(sun_optical_depth(cloud_slab(c, vec3<f32>(0.0)), vec3<f32>(0.0, 3.0, 0.0), up), 1.5);
}

@test
fn sun_optical_depth_of_a_uniform_shell() {
    // The shell around (0, -R, 0), R = 6360 km, d = 1, ext 1.5. Straight up
    // from altitude 3: L = 2; from altitude 0.5 the path starts at the
    // inner sphere, 1.5 up, and ends 4.5 up: L = 3.
    let s = cloud_slab(uniform_params(2.0, 0.5, 1u), vec3<f32>(0.0));
    let up = vec3<f32>(0.0, 1.0, 0.0);
    expectNear(sun_optical_depth(s, vec3<f32>(0.0, 3.0, 0.0), up), 3.0);
    expectNear(sun_optical_depth(s, vec3<f32>(0.0, 0.5, 0.0), up), 4.5);
    // Slanted (0.6, 0.8, 0) from radius R + 3 to the sphere R + 5: L = -b +
    // sqrt(b^2 - c), b = 0.8 (R + 3), c = (R + 3)^2 - (R + 5)^2, L = 2.4997791042378594.
    expectNear(sun_optical_depth(s, vec3<f32>(0.0, 3.0, 0.0), vec3<f32>(0.6, 0.8, 0.0)), 3.749668656356789);
}

@test
fn sun_optical_depth_stops_past_the_cutoff() {
    // d = 100, ext 1, L = 2 straight up: the first light step (the layout's
    // first fraction 0.03797088665611335 of L) adds 7.594, the second r =
    // 4^(1/11) times more, 16.208 > 16: the march stops there (the whole
    // path would give 200).
    let s = cloud_slab(uniform_params(200.0, 0.0, 0u), vec3<f32>(0.0));
    expectNear(sun_optical_depth(s, vec3<f32>(0.0, 3.0, 0.0), vec3<f32>(0.0, 1.0, 0.0)), 16.208347773801464);
}

@test
fn cloud_march_through_empty_air() {
    // Coverage 0 (SPEC 3.6: exactly the background): no light, T = 1.
    let s = slab(1u, 0.0, 4u);
    let r = cloud_march(s, vec3<f32>(0.0), vec3<f32>(0.0, 1.0, 0.0), 2.0, 5.0, 0.5, vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(20.0));
    expectNearV4f(r, vec4<f32>(0.0, 0.0, 0.0, 1.0), 0.0);
}

@test
fn cloud_march_analytic_conserves_energy() {
    // Up through the uniform slab (t 2 to 5), d = 1, ext 1.5, no sun, 64
    // steps: T = exp(-4.5) = 0.011108996538242306 (Beer-Lambert) and the
    // analytic steps telescope to ambient (1 - T) / 1.5.
    var c = uniform_params(2.0, 0.5, 0u);
    c.integrator = 1u;
    let r = cloud_march(cloud_slab(c, vec3<f32>(0.0)), vec3<f32>(0.0), vec3<f32>(0.0, 1.0, 0.0), 2.0, 5.0, 0.5,
                        vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0));
    expectNear(r.w / 0.011108996538242306, 1.0);
    expectNearV3f(r.xyz, vec3<f32>(0.06592606689745052, 0.13185213379490104, 0.19777820069235152));
}

@test
fn cloud_march_riemann_steps_of_step_km() {
    // d = 1, ext 1, t 2 to 5, no sun. step_km 0.7: n = ceil(3 / 0.7) = 5,
    // dt = 0.6: radiance ambient dt (1 - e^-3) / (1 - e^-0.6), T = e^-3.
    var c = uniform_params(2.0, 0.0, 0u);
    c.step_km = 0.7;
    let o = vec3<f32>(0.0);
    let up = vec3<f32>(0.0, 1.0, 0.0);
    let r = cloud_march(cloud_slab(c, o), o, up, 2.0, 5.0, 0.5, up, vec3<f32>(0.0));
    expectNear(r.w / 0.049787068367863944, 1.0);
    expectNearV3f(r.xyz, vec3<f32>(0.12636136137103363, 0.25272272274206725, 0.37908408411310085));
    // step_km 0.01 would need 300 steps: capped at steps = 8, dt = 0.375.
    c.step_km = 0.01;
    c.steps = 8u;
    let r8 = cloud_march(cloud_slab(c, o), o, up, 2.0, 5.0, 0.5, up, vec3<f32>(0.0));
    expectNearV3f(r8.xyz, vec3<f32>(0.11394871528049294, 0.22789743056098588, 0.34184614584147877));
}

@test
fn cloud_march_riemann_geometric_steps() {
    // d = 1, ext 1, t 2 to 5, 6 steps of spread 4: step k spans the
    // fractions (r^k - 1) / (r^6 - 1) to (r^(k+1) - 1) / (r^6 - 1) of the
    // path, r = 4^(1/5); radiance ambient sum_k dt_k e^-(t_k - 2), T = e^-3.
    var c = uniform_params(2.0, 0.0, 0u);
    c.steps = 6u;
    c.step_spread = 4.0;
    let o = vec3<f32>(0.0);
    let up = vec3<f32>(0.0, 1.0, 0.0);
    let r = cloud_march(cloud_slab(c, o), o, up, 2.0, 5.0, 0.5, up, vec3<f32>(0.0));
    expectNear(r.w / 0.049787068367863944, 1.0);
    expectNearV3f(r.xyz, vec3<f32>(0.11723559297711464, 0.23447118595422928, 0.3517067789313439));
}

@test
fn cloud_march_sunlit_with_golden_jitter() {
    // d = 0.5, ext 1, along (0.6, 0.8, 0) from t 2.5 to 6.25 (the slab), 4
    // steps of 0.9375, xi = 0.3; sun (2, 1.5, 1) straight up (mu = 0.8,
    // phase 0.10032981883205172), powder 0.5, ambient (0.1, 0.2, 0.3) from
    // half at the base (ambient_bottom 0.5). Golden: samples at y = 2.225,
    // 3.43853, 3.90205, 4.36558; shared: y = 2.225, 2.975, 3.725, 4.475.
    // T = e^-1.875 = 0.15335496684492847 either way.
    var c = uniform_params(1.0, 0.0, 0u);
    c.steps = 4u;
    c.powder = 0.5;
    c.ambient_bottom = 0.5;
    c.jitter_steps = 1u;
    let o = vec3<f32>(0.0);
    let d = vec3<f32>(0.6, 0.8, 0.0);
    let up = vec3<f32>(0.0, 1.0, 0.0);
    let sun = vec3<f32>(2.0, 1.5, 1.0);
    let g = cloud_march(cloud_slab(c, o), o, d, 2.5, 6.25, 0.3, up, sun);
    expectNear(g.w, 0.15335496684492847);
    expectNearV3f(g.xyz, vec3<f32>(0.14911283949585494, 0.2020408805041208, 0.2549689215123867));
    c.jitter_steps = 0u;
    let sh = cloud_march(cloud_slab(c, o), o, d, 2.5, 6.25, 0.3, up, sun);
    expectNear(sh.w, 0.15335496684492847);
    expectNearV3f(sh.xyz, vec3<f32>(0.14152969623327646, 0.1931056166729591, 0.24468153711264173));
}

@test
fn cloud_march_stops_at_the_transmittance_cutoff() {
    // d = 50, ext 1, 64 steps of 3/64 up through the slab: x = 2.34375 per
    // step, T = e^-4x = 8.5e-5 < 1e-4 after the fourth: T is then 0 and the
    // radiance the first four Riemann steps, ambient 50 dt sum_{k<4} e^-kx.
    let o = vec3<f32>(0.0);
    let up = vec3<f32>(0.0, 1.0, 0.0);
    let r = cloud_march(cloud_slab(uniform_params(100.0, 0.0, 0u), o), o, up, 2.0, 5.0, 0.5, up, vec3<f32>(0.0));
    expectNear(r.w, 0.0, 0.0);
    expectNearV3f(r.xyz, vec3<f32>(0.2592329517084144, 0.5184659034168289, 0.7776988551252433));
}
