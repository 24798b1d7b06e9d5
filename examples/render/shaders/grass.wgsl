// Grass as billboard cards (SPEC 17 example c): three aligned layers of
// textured cards from a vertex buffer, alpha-tested against a blade
// texture, depth-tested, with the upper vertices swayed by the wind.
// Written from the math in examples/render/README.md.

struct Params {
    width: u32,
    height: u32,
    time: f32,
    wind: f32,     // sway amplitude, world units
    eye_y: f32,
    eye_z: f32,
    look_y: f32,
    look_z: f32,
    fov: f32,      // vertical field of view, degrees
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var blade: texture_2d<f32>;
@group(0) @binding(2) var blade_sampler: sampler;

const SKY = vec3<f32>(0.55, 0.70, 0.90);
const NEAR = 0.05;
const FAR = 20.0;

struct Card {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) depth: f32,
}

// The wind: an upper vertex moves by `wind` along (cos a, 0, sin a), with
// a = |position| sin(time) 20.
fn sway(p: vec3<f32>) -> vec3<f32> {
    let a = length(p) * sin(params.time) * 20.0;
    return p + params.wind * vec3(cos(a), 0.0, sin(a));
}

@vertex
fn grass_vertex(@location(0) position: vec3<f32>, @location(1) uv: vec2<f32>) -> Card {
    // v = 0 is a card's top edge; the roots stay put.
    var p = position;
    if uv.y < 0.5 {
        p = sway(position);
    }
    let eye = vec3(0.0, params.eye_y, params.eye_z);
    let forward = normalize(vec3(0.0, params.look_y, params.look_z) - eye);
    let right = normalize(cross(vec3(0.0, 1.0, 0.0), forward));
    let up = cross(forward, right);
    let d = p - eye;
    let c = vec3(dot(d, right), dot(d, up), dot(d, forward));
    let t = tan(radians(params.fov) * 0.5);
    let aspect = f32(params.width) / f32(params.height);
    var out: Card;
    out.clip = vec4(c.x / (t * aspect), c.y / t, (c.z - NEAR) * FAR / (FAR - NEAR), c.z);
    out.uv = uv;
    out.depth = c.z;
    return out;
}

@fragment
fn grass_fragment(in: Card) -> @location(0) vec4<f32> {
    let texel = textureSample(blade, blade_sampler, in.uv);
    if texel.a < 0.5 {
        discard;
    }
    // Aerial perspective: far cards fade towards the sky.
    let fog = exp(-0.12 * in.depth);
    return vec4(mix(SKY, texel.rgb, fog), 1.0);
}
