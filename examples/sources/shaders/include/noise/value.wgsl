#include "hash.wgsl"

// Value noise: lattice values blended by the quintic fade 6t^5 - 15t^4 + 10t^3.
fn value_noise(p: vec2<f32>, seed: u32) -> f32 {
    let cell = vec2<i32>(floor(p));
    let f = fract(p);
    let t = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let a = lattice(cell, seed);
    let b = lattice(cell + vec2(1, 0), seed);
    let c = lattice(cell + vec2(0, 1), seed);
    let d = lattice(cell + vec2(1, 1), seed);
    return mix(mix(a, b, t.x), mix(c, d, t.x), t.y);
}
