// Escape-time Mandelbrot set over [-2.2, 0.8] x [-1.2, 1.2]: z <- z^2 + c
// from z = 0 until |z| > 2 or 96 steps; the colour ramps with the step
// count. No uniform: the size comes from the texture itself.
@group(0) @binding(0) var frame: texture_storage_2d<rgba8unorm, write>;

const MAX_STEPS: u32 = 96u;

@compute @workgroup_size(1)
fn mandelbrot(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(frame);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let c = vec2(-2.2 + 3.0 * uv.x, -1.2 + 2.4 * uv.y);
    var z = vec2(0.0);
    var n = 0u;
    while n < MAX_STEPS && dot(z, z) <= 4.0 {
        z = vec2(z.x * z.x - z.y * z.y, 2.0 * z.x * z.y) + c;
        n += 1u;
    }
    let t = f32(n) / f32(MAX_STEPS);
    textureStore(frame, id.xy, vec4(t, t * t, sqrt(t), 1.0));
}
