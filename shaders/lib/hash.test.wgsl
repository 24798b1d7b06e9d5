// Unit tests of vista::hash (`vista test`). Expected words from pcg3d as
// published (Jarzynski & Olano, JCGT 2020), computed in Python with
// 32-bit wrapping.
#import vista::hash::{pcg3d, unit_from_hash}
#import wgsl_test::{expectEqU, expectNear}

@test
fn pcg3d_of_the_origin() {
    let h = pcg3d(vec3<u32>(0u, 0u, 0u));
    expectEqU(h.x, 2611992518u);
    expectEqU(h.y, 2833812075u);
    expectEqU(h.z, 1058359340u);
}

@test
fn pcg3d_of_one_two_three() {
    let h = pcg3d(vec3<u32>(1u, 2u, 3u));
    expectEqU(h.x, 4204755366u);
    expectEqU(h.y, 1223881804u);
    expectEqU(h.z, 1500469937u);
}

@test
fn unit_from_hash_spans_zero_to_below_one() {
    expectNear(unit_from_hash(0u), 0.0);
    expectNear(unit_from_hash(0xFFFFFFFFu), 0.9999999403953552, 0.0);
    expectNear(unit_from_hash(0x80000000u), 0.5, 0.0);
}
