// The assertions of `vista test` (`#import wgsl_test`), named as wgsl-test
// names them. A test file's calls are rewritten by vista to the `_at`
// forms, which carry the call's place (a site id the host maps back to
// file, line and column); the plain forms exist so that a file imports
// and type-checks as written.
//
// Each test runs in one invocation (`begin` names it) and records up to
// KEPT failures in its row of `wgsl_test_results`: the failure count, then
// per failure its site and the actual, expected and tolerance words (f32
// bits, or the integers as they are).

#define_import_path wgsl_test

@group(3) @binding(0) var<storage, read_write> wgsl_test_results: array<u32>;

const KEPT: u32 = 16u;
const RECORD: u32 = 10u;
const ROW: u32 = 161u; // 1 + KEPT * RECORD

// The default tolerance of expectNear: relative and absolute.
const NEAR_TOL: f32 = 1e-5;

var<private> test_row: u32;

fn begin(test: u32) {
    test_row = test * ROW;
}

fn fail(site: u32, actual: vec4<u32>, expected: vec4<u32>, tol: u32) {
    let n = wgsl_test_results[test_row];
    wgsl_test_results[test_row] = n + 1u;
    if (n < KEPT) {
        let at = test_row + 1u + n * RECORD;
        wgsl_test_results[at] = site;
        wgsl_test_results[at + 1u] = actual.x;
        wgsl_test_results[at + 2u] = actual.y;
        wgsl_test_results[at + 3u] = actual.z;
        wgsl_test_results[at + 4u] = actual.w;
        wgsl_test_results[at + 5u] = expected.x;
        wgsl_test_results[at + 6u] = expected.y;
        wgsl_test_results[at + 7u] = expected.z;
        wgsl_test_results[at + 8u] = expected.w;
        wgsl_test_results[at + 9u] = tol;
    }
}

// |a - b| <= tol * max(1, |a|, |b|), per component: relative for large
// values, absolute near zero.
fn near4(a: vec4<f32>, b: vec4<f32>, tol: f32) -> bool {
    let scale = max(vec4<f32>(1.0), max(abs(a), abs(b)));
    return all(abs(a - b) <= tol * scale);
}

fn expect_at(site: u32, cond: bool) {
    if (!cond) {
        fail(site, vec4<u32>(0u), vec4<u32>(1u, 0u, 0u, 0u), 0u);
    }
}

fn expectEq_at(site: u32, a: i32, b: i32) {
    if (a != b) {
        fail(site, vec4<u32>(bitcast<u32>(a), 0u, 0u, 0u), vec4<u32>(bitcast<u32>(b), 0u, 0u, 0u), 0u);
    }
}

fn expectEqU_at(site: u32, a: u32, b: u32) {
    if (a != b) {
        fail(site, vec4<u32>(a, 0u, 0u, 0u), vec4<u32>(b, 0u, 0u, 0u), 0u);
    }
}

fn expectNear_at(site: u32, a: f32, b: f32, tol: f32) {
    let a4 = vec4<f32>(a, 0.0, 0.0, 0.0);
    let b4 = vec4<f32>(b, 0.0, 0.0, 0.0);
    if (!near4(a4, b4, tol)) {
        fail(site, bitcast<vec4<u32>>(a4), bitcast<vec4<u32>>(b4), bitcast<u32>(tol));
    }
}

fn expectNearV2f_at(site: u32, a: vec2<f32>, b: vec2<f32>, tol: f32) {
    let a4 = vec4<f32>(a, 0.0, 0.0);
    let b4 = vec4<f32>(b, 0.0, 0.0);
    if (!near4(a4, b4, tol)) {
        fail(site, bitcast<vec4<u32>>(a4), bitcast<vec4<u32>>(b4), bitcast<u32>(tol));
    }
}

fn expectNearV3f_at(site: u32, a: vec3<f32>, b: vec3<f32>, tol: f32) {
    let a4 = vec4<f32>(a, 0.0);
    let b4 = vec4<f32>(b, 0.0);
    if (!near4(a4, b4, tol)) {
        fail(site, bitcast<vec4<u32>>(a4), bitcast<vec4<u32>>(b4), bitcast<u32>(tol));
    }
}

fn expectNearV4f_at(site: u32, a: vec4<f32>, b: vec4<f32>, tol: f32) {
    if (!near4(a, b, tol)) {
        fail(site, bitcast<vec4<u32>>(a), bitcast<vec4<u32>>(b), bitcast<u32>(tol));
    }
}

// Within n units in the last place (same sign; -0 and +0 equal).
fn expectUlp_at(site: u32, a: f32, b: f32, n: u32) {
    let ia = bitcast<i32>(a);
    let ib = bitcast<i32>(b);
    let oa = select(ia, i32(0x80000000u) - ia, ia < 0);
    let ob = select(ib, i32(0x80000000u) - ib, ib < 0);
    let d = abs(oa - ob);
    if (d < 0 || u32(d) > n) {
        fail(site, vec4<u32>(bitcast<u32>(a), 0u, 0u, 0u), vec4<u32>(bitcast<u32>(b), 0u, 0u, 0u), n);
    }
}

// As written in a test file; vista rewrites each call to its `_at` form.
fn expect(cond: bool) {
    expect_at(0u, cond);
}

fn expectEq(a: i32, b: i32) {
    expectEq_at(0u, a, b);
}

fn expectEqU(a: u32, b: u32) {
    expectEqU_at(0u, a, b);
}

fn expectNear(a: f32, b: f32) {
    expectNear_at(0u, a, b, NEAR_TOL);
}

fn expectNearV2f(a: vec2<f32>, b: vec2<f32>) {
    expectNearV2f_at(0u, a, b, NEAR_TOL);
}

fn expectNearV3f(a: vec3<f32>, b: vec3<f32>) {
    expectNearV3f_at(0u, a, b, NEAR_TOL);
}

fn expectNearV4f(a: vec4<f32>, b: vec4<f32>) {
    expectNearV4f_at(0u, a, b, NEAR_TOL);
}

fn expectUlp(a: f32, b: f32, n: u32) {
    expectUlp_at(0u, a, b, n);
}
