// Unit tests of vista::terrain (`vista test`). Expected values computed in
// f64 (Python's math module) from SPEC 3.4 and the math each function
// documents: h = amplitude T(scale x, scale z) with T = fBm / A or ridged /
// its bound (fractal.test.wgsl's references: Improved Noise from its
// published reference, seed-0 table), amplitude + slope . xz for the plane,
// amplitude sin(q.x) cos(q.y) for the sine; the normal normalize(-h_x, 1,
// -h_z) from central differences of h over delta = eps t; the relax march
// over a plane, where D(t) = D0 - k t is linear so every quantity is in
// closed form (D_n = D0 (1 - relax k)^n, t_n = (D0 - D_n) / k, the hit at
// the root D0 / k, which the secant refinement finds exactly); the soft
// shadow over a plane, where D(t) / t is the constant sun.y - slope .
// sun.xz. Inputs are taken at their f32 values.
//
// Enum params by their index in kernels/heightfield.toml: terrain fbm 0,
// ridged 1, plane 2, sine 3; basis perlin 0, value 1.
#import vista::terrain::{TerrainParams, Terrain, March, Shadow, terrain_of, terrain_height, normal_at, march, soft_shadow, surface_point}
#import vista::enums::{TERRAIN_FBM, TERRAIN_PLANE, TERRAIN_RIDGED, TERRAIN_SINE}
#import wgsl_test::{expect, expectEqU, expectNear, expectNearV3f}

// 4 octaves of Perlin, lacunarity 2, gain 0.5, rotation `rot_deg`; ridged
// H 1, offset 1, gain 2; the plane's slope (0.1, -0.05).
fn params(kind: u32, amplitude: f32, scale: f32, rot_deg: f32) -> TerrainParams {
    return TerrainParams(kind, 0u, 0u, 4u, 2.0, 0.5, rot_deg, 1.0, 1.0, 2.0, amplitude, scale, vec2<f32>(0.1, -0.05));
}

// The plane y = 0.5 + 0.1 x - 0.05 z.
fn plane() -> Terrain {
    return terrain_of(params(TERRAIN_PLANE, 0.5, 1.0, 0.0));
}

@test
fn terrain_of_derives_rotation_and_normaliser() {
    // fbm: 1 / A = 1 / 1.875; the octave rotation's cos and sin of 30 degrees.
    let f = terrain_of(params(TERRAIN_FBM, 1.5, 0.35, 30.0));
    expectNear(f.inv_norm, 0.5333333333333333);
    expectNear(f.fbm.rot_cos, 0.8660254037844387);
    expectNear(f.fbm.rot_sin, 0.5);
    // ridged: 1 / (max(1, M - 1)^2 (1 + 1/2 + 1/4 + 1/8)) = 1 / 1.875.
    var rp = params(TERRAIN_RIDGED, 2.0, 0.5, 0.0);
    expectNear(terrain_of(rp).inv_norm, 0.5333333333333333);
    // offset 0.4, H 0.8: 1 / ((M - 0.4)^2 sum_{i < 4} 2^(-0.8 i)) = 1 / 0.8479550016084817.
    rp.ridge_offset = 0.4;
    rp.ridge_h = 0.8;
    expectNear(terrain_of(rp).inv_norm, 1.1793078619774693);
    // The plane and the sine are not normalised.
    expectNear(plane().inv_norm, 1.0, 0.0);
    expectNear(terrain_of(params(TERRAIN_SINE, 0.8, 0.7, 0.0)).inv_norm, 1.0, 0.0);
}

@test
fn terrain_height_of_each_kind() {
    // Plane: 0.5 + 0.1 x - 0.05 z at (1, -2) and (-3.3, 7.9).
    expectNear(terrain_height(plane(), vec2<f32>(1.0, -2.0)), 0.7);
    expectNear(terrain_height(plane(), vec2<f32>(-3.3, 7.9)), -0.22500000000000003);
    // Sine: 0.8 sin(0.7 * 1.2) cos(0.7 * -0.4).
    expectNear(terrain_height(terrain_of(params(TERRAIN_SINE, 0.8, 0.7, 0.0)), vec2<f32>(1.2, -0.4)), 0.5725146744562517);
    // fbm: 1.5 fbm(0.35 (2, -1.3)) / 1.875.
    expectNear(terrain_height(terrain_of(params(TERRAIN_FBM, 1.5, 0.35, 0.0)), vec2<f32>(2.0, -1.3)), 0.11185486982758337);
    // ridged: 2 ridged(0.5 (1.1, 3.7)) / 1.875.
    expectNear(terrain_height(terrain_of(params(TERRAIN_RIDGED, 2.0, 0.5, 0.0)), vec2<f32>(1.1, 3.7)), 1.284839910866311);
}

@test
fn normal_from_central_differences() {
    // The plane's normal is normalize(-0.1, 1, 0.05) wherever it is taken.
    let n = vec3<f32>(-0.09938079899999067, 0.9938079899999066, 0.04969039949999533);
    expectNearV3f(normal_at(plane(), 0.01, vec2<f32>(1.0, -2.0), 5.0), n);
    expectNearV3f(normal_at(plane(), 0.001, vec2<f32>(-40.0, 12.0), 300.0), n);
    // The sine at (1.2, -0.4), delta = eps t = 0.5: (h(x + d) - h(x - d)) / 2d
    // in x and z. Compared to 1e-4: WGSL's sin and cos may be off by up to
    // 2^-11 absolute, and SwiftShader's are off by about 1e-5 here, which
    // the difference quotient scales by amplitude / (2 delta) = 0.8 (with
    // delta = 0.05 the normal came out 2e-4 off there).
    let s = terrain_of(params(TERRAIN_SINE, 0.8, 0.7, 0.0));
    expectNearV3f(normal_at(s, 0.01, vec2<f32>(1.2, -0.4), 50.0), vec3<f32>(-0.33010770576786475, 0.9379840383191322, -0.1059001721018876), 1e-4);
}

@test
fn march_hits_a_plane_at_its_root() {
    // From (0, 3, 0) along d = normalize(0.3, -0.5, 0.8): D0 = 2.5, k =
    // -(d.y - 0.1 d.x + 0.05 d.z); the first n with D_n < eps t_n (relax
    // 0.5, eps 1e-3) is 22 (D_22 = 0.00480 < 0.00504; D_21 = 0.00638), and
    // the hit is the root 2.5 / k.
    let o = vec3<f32>(0.0, 3.0, 0.0);
    let d = vec3<f32>(0.30304574966430664, -0.5050762891769409, 0.8081220388412476);
    let h = march(plane(), March(100.0, 0.5, 1e-3, 256u), o, d);
    expect(h.hit);
    expectEqU(h.steps, 22u);
    expectNear(h.t, 5.050762565916917);
    // With 23 steps allowed it still hits; with 22 it runs out first.
    expect(march(plane(), March(100.0, 0.5, 1e-3, 23u), o, d).hit);
    let short = march(plane(), March(100.0, 0.5, 1e-3, 22u), o, d);
    expect(!short.hit);
    expectEqU(short.steps, 22u);
}

@test
fn march_misses_upward_and_hits_at_once_from_below() {
    // Straight up from 2.5 above the plane: D = 2.5 + t, t_{k+1} = 1.5 t_k +
    // 1.25 = 0, 1.25, 3.125, ..., 61.57 at k = 8, the first past t_max = 50.
    let up = march(plane(), March(50.0, 0.5, 1e-3, 256u), vec3<f32>(0.0, 3.0, 0.0), vec3<f32>(0.0, 1.0, 0.0));
    expect(!up.hit);
    expectEqU(up.steps, 8u);
    // From under the plane (D(0) = -0.5 < eps 0): a hit at t = 0, no step.
    let below = march(plane(), March(50.0, 0.5, 1e-3, 256u), vec3<f32>(0.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0));
    expect(below.hit);
    expectEqU(below.steps, 0u);
    expectNear(below.t, 0.0, 0.0);
}

@test
fn soft_shadow_over_a_plane() {
    // From the surface at (1, 0.7, -2) toward sun = normalize(0.3, 0.6, -0.2)
    // = (3, 6, -2) / 7: D(t) / t = 6/7 - (0.1 * 3/7 + 0.05 * 2/7) = 0.8, so
    // with softness 1 the result is smoothstep(0, 1, 0.8) = 0.896.
    let p = surface_point(plane(), vec3<f32>(1.0, 5.0, -2.0), vec3<f32>(0.0, -1.0, 0.0), 4.3);
    expectNearV3f(p, vec3<f32>(1.0, 0.7, -2.0));
    let sun = vec3<f32>(0.4285714328289032, 0.8571428656578064, -0.2857142984867096);
    expectNear(soft_shadow(plane(), Shadow(8u, 5.0, 1.0), p, sun), 0.8960000071525572);
    // Softness 3: 2.4 clamps to fully lit.
    expectNear(soft_shadow(plane(), Shadow(8u, 5.0, 3.0), p, sun), 1.0);
    // A sun low toward +x, up the slope: sun = normalize(1, 0.05, 0), D(t) / t
    // = (0.05 - 0.1) / |(1, 0.05)| < 0, in shadow: 0.
    let low = vec3<f32>(0.9987523388778446, 0.04993761694389223, 0.0);
    expectNear(soft_shadow(plane(), Shadow(8u, 5.0, 1.0), p, low), 0.0, 0.0);
}
