// A picture of the flock: every boid a soft Gaussian dot coloured by its
// flock, on a dark sky spanning [-view_extent, view_extent]^2 (y up).

struct Boid {
    position: vec2<f32>,
    velocity: vec2<f32>,
    flock: u32,
    _pad0: u32,
}

@group(0) @binding(0) var<storage, read> flock: array<Boid>;
@group(0) @binding(1) var picture: texture_storage_2d<rgba8unorm, write>;

@group(1) @binding(0) var<uniform> view_extent: f32;
@group(1) @binding(1) var<uniform> dot_radius: f32;

@compute @workgroup_size(8, 8)
fn draw_boids(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(picture);
    if (gid.x >= size.x || gid.y >= size.y) {
        return;
    }
    let uv = (vec2<f32>(gid.xy) + 0.5) / vec2<f32>(size);
    let p = view_extent * vec2<f32>(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
    var colour = vec3<f32>(0.02, 0.03, 0.06);
    let inv = 1.0 / (dot_radius * dot_radius);
    for (var i = 0u; i < arrayLength(&flock); i = i + 1u) {
        let b = flock[i];
        let d = p - b.position;
        colour = colour + select(vec3<f32>(1.0, 0.55, 0.15), vec3<f32>(0.2, 0.7, 1.0), b.flock == 1u) * exp(-dot(d, d) * inv);
    }
    textureStore(picture, gid.xy, vec4<f32>(min(colour, vec3<f32>(1.0)), 1.0));
}
