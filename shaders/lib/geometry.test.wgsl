// Unit tests of vista::geometry (`vista test`).
// Expected values worked by hand: a unit sphere at the origin seen from
// z = -5 and z = +5 along +z, and a ray that misses it.
#import vista::geometry::{ray_sphere}
#import wgsl_test::{expect, expectNear, expectNearV2f}

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
