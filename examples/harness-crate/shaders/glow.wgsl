// A radial glow with a soft ring: I = exp(-(r / radius)^2) + ring * exp(-((r - ring_at) / ring_width)^2),
// tinted, written as rgba8unorm by 16 x 16 workgroups.

struct Glow {
    tint: vec3<f32>,
    radius: f32,
    ring: f32,
    ring_at: f32,
    ring_width: f32,
    _pad0: f32,
}

@group(0) @binding(0) var<uniform> glow: Glow;
@group(0) @binding(1) var target_image: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(16, 16)
fn shade_glow(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(target_image);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let p = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size) * 2.0 - 1.0;
    let r = length(p);
    let core = exp(-(r / glow.radius) * (r / glow.radius));
    let d = (r - glow.ring_at) / glow.ring_width;
    let intensity = core + glow.ring * exp(-d * d);
    textureStore(target_image, id.xy, vec4<f32>(clamp(glow.tint * intensity, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0));
}
