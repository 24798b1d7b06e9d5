// Unit tests of vista::noise (`vista test`). Expected values from SPEC 3.1,
// computed in f64 (Python's math module): the fade 6t^5 - 15t^4 + 10t^3;
// Improved Noise (Perlin 2002) written from its published reference (its
// permutation, its 12 edge gradients plus 4 repeats), which gives SPEC's
// reference perlin(3.14, 42, 7) = 0.13691995878400012; value noise from pcg3d as
// published (Jarzynski & Olano, JCGT 2020) with 32-bit wrapping, lattice
// value (h.x >> 8) * 2^-24 * 2 - 1, seed folded into z as seed * 0x9E3779B9.
// The kernels' table is Perlin's seed-0 permutation (no seed param here).
#import vista::noise::{quintic, perlin, perlin_grad, perlin_hashes, lattice_value, value_noise, PERLIN_MAX_ABS}
#import wgsl_test::{expect, expectEqU, expectNear, expectNearV3f}

@test
fn quintic_fade_ends_middle_and_inside() {
    // 6t^5 - 15t^4 + 10t^3 at t = 0, 0.5, 1: 0, 0.5, 1.
    expectNearV3f(quintic(vec3<f32>(0.0, 0.5, 1.0)), vec3<f32>(0.0, 0.5, 1.0));
    // At t = 0.3, 0.8 and 0.5: 0.16308, 0.94208, 0.5.
    expectNearV3f(quintic(vec3<f32>(0.3, 0.8, 0.5)), vec3<f32>(0.16308, 0.94208, 0.5));
}

@test
fn perlin_is_zero_on_the_lattice() {
    // Every corner's offset is 0 there, so every gradient dot is 0 (the
    // second point has a negative cell, the third one past the 256 wrap).
    expectNear(perlin(vec3<f32>(3.0, 42.0, 7.0)), 0.0, 0.0);
    expectNear(perlin(vec3<f32>(-5.0, 0.0, 12.0)), 0.0, 0.0);
    expectNear(perlin(vec3<f32>(300.0, -17.0, 1.0)), 0.0, 0.0);
}

@test
fn perlin_reference_values() {
    // SPEC 3.1's required value (integer z: the lower face only).
    expectNear(perlin(vec3<f32>(3.14, 42.0, 7.0)), 0.13691995878400012);
    // Off integer z (both faces), from the same f64 Improved Noise:
    // perlin(0.5, 1.25, 2.75), perlin(-2.3, 4.6, 0.1), perlin(10.7, -3.2, 5.55).
    expectNear(perlin(vec3<f32>(0.5, 1.25, 2.75)), -0.4665393829345703);
    expectNear(perlin(vec3<f32>(-2.3, 4.6, 0.1)), -0.41029048556083203);
    expectNear(perlin(vec3<f32>(10.7, -3.2, 5.55)), 0.3794100934713073);
}

@test
fn perlin_grad_dots_the_edge_gradients() {
    // g(h & 15) . p for p = (0.3, -0.7, 0.45), g in the reference's hash order:
    // (1,1,0) (-1,1,0) (1,-1,0) (-1,-1,0) (1,0,1) (-1,0,1) (1,0,-1) (-1,0,-1)
    // (0,1,1) (0,-1,1) (0,1,-1) (0,-1,-1), then (1,1,0) (0,-1,1) (-1,1,0) (0,-1,-1).
    let p = vec3<f32>(0.3, -0.7, 0.45);
    expectNear(perlin_grad(0u, p), -0.4);
    expectNear(perlin_grad(1u, p), -1.0);
    expectNear(perlin_grad(2u, p), 1.0);
    expectNear(perlin_grad(3u, p), 0.4);
    expectNear(perlin_grad(4u, p), 0.75);
    expectNear(perlin_grad(5u, p), 0.15);
    expectNear(perlin_grad(6u, p), -0.15);
    expectNear(perlin_grad(7u, p), -0.75);
    expectNear(perlin_grad(8u, p), -0.25);
    expectNear(perlin_grad(9u, p), 1.15);
    expectNear(perlin_grad(10u, p), -1.15);
    expectNear(perlin_grad(11u, p), 0.25);
    expectNear(perlin_grad(12u, p), -0.4);
    expectNear(perlin_grad(13u, p), 1.15);
    expectNear(perlin_grad(14u, p), -1.0);
    expectNear(perlin_grad(15u, p), 0.25);
    // Only the low 4 bits choose: 0x1F3 is 3, 0xFFFFFFFE is 14.
    expectNear(perlin_grad(0x1F3u, p), 0.4);
    expectNear(perlin_grad(0xFFFFFFFEu, p), -1.0);
}

@test
fn lattice_value_from_pcg3d() {
    // (pcg3d(cell + (0, 0, seed * 0x9E3779B9)).x >> 8) * 2^-24 * 2 - 1:
    // exact in f32 (a multiple of 2^-23 in [-1, 1)), so compared exactly.
    expectNear(lattice_value(vec3<i32>(0, 0, 0), 0u), 0.21630370616912842, 0.0);
    expectNear(lattice_value(vec3<i32>(2, -3, 5), 0u), 0.5202836990356445, 0.0);
    expectNear(lattice_value(vec3<i32>(2, -3, 5), 7u), -0.5398356914520264, 0.0);
    expectNear(lattice_value(vec3<i32>(-1, 7, -4), 7u), -0.3729746341705322, 0.0);
}

@test
fn value_noise_on_and_between_the_lattice() {
    // At a lattice point every weight is 0: the lattice value, bit for bit
    // (SPEC 3.1).
    expectNear(value_noise(vec3<f32>(2.0, -3.0, 5.0), 7u), -0.5398356914520264, 0.0);
    expectNear(value_noise(vec3<f32>(-1.0, 7.0, -4.0), 7u), -0.3729746341705322, 0.0);
    // Halfway along x (fade 0.5): the mean of L(2,-3,5) and L(3,-3,5), seed 7.
    expectNear(value_noise(vec3<f32>(2.5, -3.0, 5.0), 7u), 0.1692519187927246);
    // Inside a cell, seed 7: the trilinear blend of the 8 corners with
    // fade weights, value(0.3, 1.7, -2.4) and value(-5.25, 0.5, 3.125).
    expectNear(value_noise(vec3<f32>(0.3, 1.7, -2.4), 7u), 0.028530988273300056);
    expectNear(value_noise(vec3<f32>(-5.25, 0.5, 3.125), 7u), 0.22083963296869058);
}

@test
fn noise_stays_bounded_on_a_grid() {
    // 7^3 points across several cells: |perlin| <= PERLIN_MAX_ABS and value
    // noise in [-1, 1) (the f64 maximum of both over these points is 0.953).
    for (var i = 0; i < 7; i++) {
        for (var j = 0; j < 7; j++) {
            for (var k = 0; k < 7; k++) {
                let q = vec3<f32>(f32(i) * 0.37 - 1.1, f32(j) * 0.41 + 0.2, f32(k) * 0.29 - 0.6);
                expect(abs(perlin(q)) <= PERLIN_MAX_ABS);
                let v = value_noise(q, 3u);
                expect(v >= -1.0 && v < 1.0);
            }
        }
    }
}

@test
fn perlin_hashes_follow_the_reference_chain() {
    // Perlin's chain through the doubled table P: A = P[x] + y, B = P[x + 1] + y,
    // AA = P[A] + z, BA = P[B] + z, AB = P[A + 1] + z, BB = P[B + 1] + z; the
    // corners (x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1) hash to
    // P[k] | P[k + 1] << 8 for k = AA, BA, AB, BB (byte 1: the corner at z + 1).
    var h = perlin_hashes(vec3<u32>(0u, 0u, 0u));
    expectEqU(h.x, 26404u);
    expectEqU(h.y, 42070u);
    expectEqU(h.z, 28268u);
    expectEqU(h.w, 50048u);
    h = perlin_hashes(vec3<u32>(3u, 42u, 7u));
    expectEqU(h.x, 64226u);
    expectEqU(h.y, 31994u);
    expectEqU(h.z, 59842u);
    expectEqU(h.w, 64226u);
    h = perlin_hashes(vec3<u32>(17u, 200u, 131u));
    expectEqU(h.x, 2025u);
    expectEqU(h.y, 11266u);
    expectEqU(h.z, 51369u);
    expectEqU(h.w, 47538u);
    // At the top of the table the chain reads past 255 into the doubled half.
    h = perlin_hashes(vec3<u32>(255u, 255u, 255u));
    expectEqU(h.x, 15831u);
    expectEqU(h.y, 32020u);
    expectEqU(h.z, 7783u);
    expectEqU(h.w, 9356u);
    h = perlin_hashes(vec3<u32>(254u, 0u, 255u));
    expectEqU(h.x, 40298u);
    expectEqU(h.y, 7783u);
    expectEqU(h.z, 28268u);
    expectEqU(h.w, 16153u);
}
