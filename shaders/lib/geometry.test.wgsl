// Unit tests of vista::geometry (`vista test`).
// Expected values worked by hand: a unit sphere at the origin seen from
// z = -5 and z = +5 along +z, and a ray that misses it. The latlong and
// pinhole directions computed in f64 (Python's math module) from SPEC 3.5
// (phi = 2 pi u, e = (pi / 2)(1 - v), (cos e sin phi, sin e, cos e cos phi))
// and SPEC 3.4 (f = normalize(target - pos), r = normalize(f x (0, 1, 0)),
// up = r x f, ray normalize(f + (2u - 1) tan(fov / 2) (W / H) r +
// (1 - 2v) tan(fov / 2) up)).
#import vista::geometry::{Pinhole, latlong_direction, pinhole_look_at, pinhole_ray, ray_sphere}
#import wgsl_test::{expect, expectNear, expectNearV2f, expectNearV3f}

@test
fn ray_sphere_in_front_b_negative() {
    // b = -5, c = 24: roots 4 and 6 (the stable form's b < 0 branch).
    expectNearV2f(ray_sphere(vec3<f32>(0.0, 0.0, -5.0), vec3<f32>(0.0, 0.0, 1.0), 1.0), vec2<f32>(4.0, 6.0));
}

@test
fn ray_sphere_behind_b_positive() {
    // b = 5, c = 24: both roots behind the origin, -6 and -4.
    expectNearV2f(ray_sphere(vec3<f32>(0.0, 0.0, 5.0), vec3<f32>(0.0, 0.0, 1.0), 1.0), vec2<f32>(-6.0, -4.0));
}

@test
fn ray_sphere_miss() {
    let t = ray_sphere(vec3<f32>(0.0, 2.0, -5.0), vec3<f32>(0.0, 0.0, 1.0), 1.0);
    expect(t.x == -1.0 && t.y == -1.0);
}

@test
fn latlong_direction_zenith_horizon_and_between() {
    // v = 0 is the zenith whatever u; v = 1 the horizon, here at phi = pi.
    expectNearV3f(latlong_direction(0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0));
    expectNearV3f(latlong_direction(0.7, 0.0), vec3<f32>(0.0, 1.0, 0.0));
    expectNearV3f(latlong_direction(0.5, 1.0), vec3<f32>(0.0, 0.0, -1.0));
    // u = 0.25, v = 0.5: phi = pi / 2, e = pi / 4: (sqrt 1/2, sqrt 1/2, 0).
    expectNearV3f(latlong_direction(0.25, 0.5), vec3<f32>(0.7071067811865476, 0.7071067811865475, 0.0));
    // u = 0.6, v = 0.3 and u = 0.875, v = 0.9.
    expectNearV3f(latlong_direction(0.6, 0.3), vec3<f32>(-0.26684892042779546, 0.8910065241883678, -0.3672860295740686));
    expectNearV3f(latlong_direction(0.875, 0.9), vec3<f32>(-0.6984011233337105, 0.15643446504023084, 0.6984011233337102));
}

@test
fn pinhole_ray_through_a_hand_built_camera() {
    // Looking along +z from the origin: r = (0,0,1) x (0,1,0) = (-1, 0, 0),
    // up = (0, 1, 0); tan(fov / 2) = 0.5, aspect 2.
    let c = Pinhole(vec3<f32>(0.0), vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(-1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), 0.5, 2.0);
    // The centre is the forward axis.
    expectNearV3f(pinhole_ray(c, vec2<f32>(0.5, 0.5)), vec3<f32>(0.0, 0.0, 1.0));
    // uv (0, 0), the top-left corner: sx = -1, sy = 0.5: normalize(1, 0.5, 1)
    // = (2, 1, 2) / 3.
    expectNearV3f(pinhole_ray(c, vec2<f32>(0.0, 0.0)), vec3<f32>(0.6666666666666666, 0.3333333333333333, 0.6666666666666666));
    // uv (1, 0.5): sx = 1, sy = 0: normalize(-1, 0, 1).
    expectNearV3f(pinhole_ray(c, vec2<f32>(1.0, 0.5)), vec3<f32>(-0.7071067811865475, 0.0, 0.7071067811865475));
    // uv (0.75, 1): sx = 0.5, sy = -0.5: normalize(-0.5, -0.5, 1) = (-1, -1, 2) / sqrt 6.
    expectNearV3f(pinhole_ray(c, vec2<f32>(0.75, 1.0)), vec3<f32>(-0.4082482904638631, -0.4082482904638631, 0.8164965809277261));
}

@test
fn pinhole_rays_of_a_look_at_camera() {
    // pos (0, 2.5, -4) toward (0, 0.5, 0), fov 60, aspect 16 / 9:
    // f = (0, -1, 2) / sqrt 5, r = (-1, 0, 0), up = (0, 2, 1) / sqrt 5,
    // tan 30 = 0.5773502691896257. tan is compared to 1e-4: WGSL's tan
    // inherits sin / cos's absolute error bound (2^-11) and SwiftShader's
    // tan(pi / 8) is off by 1.3e-5 (3e-5 relative), so the rays below are
    // taken through the camera's basis with tan given exactly.
    let c = pinhole_look_at(vec3<f32>(0.0, 2.5, -4.0), vec3<f32>(0.0, 0.5, 0.0), 60.0, 16.0 / 9.0);
    expectNearV3f(c.forward, vec3<f32>(0.0, -0.4472135954999579, 0.8944271909999159));
    expectNearV3f(c.right, vec3<f32>(-1.0, 0.0, 0.0));
    expectNearV3f(c.up, vec3<f32>(0.0, 0.8944271909999159, 0.4472135954999579));
    expectNear(c.tan_half_fov, 0.5773502691896257, 1e-4);
    expectNear(c.aspect, 1.7777777777777777);
    let e = Pinhole(c.pos, c.forward, c.right, c.up, 0.5773502691896257, c.aspect);
    expectNearV3f(pinhole_ray(e, vec2<f32>(0.5, 0.5)), vec3<f32>(0.0, -0.4472135954999579, 0.8944271909999159));
    expectNearV3f(pinhole_ray(e, vec2<f32>(0.0, 0.0)), vec3<f32>(0.6643638388299197, 0.04478122431248872, 0.7460665731717558));
    expectNearV3f(pinhole_ray(e, vec2<f32>(1.0, 1.0)), vec3<f32>(-0.6643638388299198, -0.623721993124898, 0.4118149644530626));
    expectNearV3f(pinhole_ray(e, vec2<f32>(0.2, 0.7)), vec3<f32>(0.5145253131074651, -0.54621728060053, 0.6609919701063144));
    // An oblique camera: pos (1, 2, 3) toward (4, 0, -1), fov 45, aspect 1.5:
    // r = (0.8, 0, 0.6), tan 22.5 = sqrt 2 - 1.
    let o = pinhole_look_at(vec3<f32>(1.0, 2.0, 3.0), vec3<f32>(4.0, 0.0, -1.0), 45.0, 1.5);
    expectNearV3f(o.forward, vec3<f32>(0.5570860145311556, -0.3713906763541037, -0.7427813527082074));
    expectNearV3f(o.right, vec3<f32>(0.8, 0.0, 0.6));
    expectNearV3f(o.up, vec3<f32>(0.22283440581246222, 0.9284766908852593, -0.297112541083283));
    expectNear(o.tan_half_fov, 0.41421356237309503, 1e-4);
    let q = Pinhole(o.pos, o.forward, o.right, o.up, 0.41421356237309503, o.aspect);
    expectNearV3f(pinhole_ray(q, vec2<f32>(0.1, 0.25)), vec3<f32>(0.18101616798032447, -0.15768854781894764, -0.97075613251551));
    expectNearV3f(pinhole_ray(q, vec2<f32>(0.9, 0.8)), vec3<f32>(0.7861168833450777, -0.5263298647605591, -0.3240325896896069));
}
