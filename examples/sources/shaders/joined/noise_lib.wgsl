// A noise library hosts prepend to their kernels as a string. Integer
// hash after Wang, cubic Hermite fade, fBm over OCTAVES (which the kernel
// defines).
fn wang(v: u32) -> u32 {
    var x = (v ^ 61u) ^ (v >> 16u);
    x = x * 9u;
    x = x ^ (x >> 4u);
    x = x * 0x27d4eb2du;
    return x ^ (x >> 15u);
}

fn corner(c: vec2<f32>) -> f32 {
    let i = vec2<u32>(bitcast<u32>(i32(c.x)), bitcast<u32>(i32(c.y)));
    return f32(wang(i.x + wang(i.y)) & 0xffffu) / 65535.0;
}

fn smooth_noise(p: vec2<f32>) -> f32 {
    let i = floor(p);
    let f = fract(p);
    let u = f * f * (3.0 - 2.0 * f);
    return mix(mix(corner(i), corner(i + vec2(1.0, 0.0)), u.x), mix(corner(i + vec2(0.0, 1.0)), corner(i + 1.0), u.x), u.y);
}

fn fbm(p: vec2<f32>) -> f32 {
    var sum = 0.0;
    var amp = 0.5;
    var q = p;
    for (var o = 0u; o < OCTAVES; o++) {
        sum += amp * smooth_noise(q);
        q = q * 2.0 + vec2(17.0, 31.0);
        amp *= 0.5;
    }
    return sum;
}
