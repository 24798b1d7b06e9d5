// Depth compare functions. One triangle covers a 3 x 1 target whose depth
// buffer is cleared to 0.5; the fragment writes its depth through
// frag_depth (exact, no interpolation): 0.25, 0.5 and 0.75 at pixels 0, 1
// and 2, so each comparison sees the fragment less than, equal to and
// greater than the stored value once. A passing fragment writes colour 1
// and (with depth writes on) its depth; expected.py applies WebGPU's
// compare(fragment depth, stored depth).

struct Shaded {
    @location(0) color: vec4<u32>,
    @builtin(frag_depth) depth: f32,
}

@vertex
fn cover(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // (-1, -1), (3, -1), (-1, 3): the viewport is inside it.
    let x = f32(i & 1u) * 4.0 - 1.0;
    let y = f32(i >> 1u) * 4.0 - 1.0;
    return vec4<f32>(x, y, 0.5, 1.0);
}

@fragment
fn at_depth(@builtin(position) p: vec4<f32>) -> Shaded {
    return Shaded(vec4<u32>(1u, 0u, 0u, 0u), 0.25 * (floor(p.x) + 1.0));
}
