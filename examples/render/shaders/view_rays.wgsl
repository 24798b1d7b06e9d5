// An engine's view uniform, as its host fills it each frame: matrices,
// camera position, viewport, a colour-grading matrix (a mat3x3, its
// columns padded to 16 bytes) and a nested fog block. A full-screen pass
// turns each fragment into a world-space ray through world_from_clip and
// shades a sky gradient above the horizon and a fogged ground plane below.

struct Fog {
    color: vec4<f32>,
    density: f32,
    start: f32,
}

struct View {
    clip_from_world: mat4x4<f32>,
    world_from_clip: mat4x4<f32>,
    world_position: vec3<f32>,
    exposure: f32,
    viewport: vec4<f32>,
    color_grading: mat3x3<f32>,
    fog: Fog,
    frame_count: u32,
}

@group(0) @binding(0) var<uniform> view: View;

const ZENITH: vec3<f32> = vec3<f32>(0.18, 0.36, 0.85);
const GROUND: vec3<f32> = vec3<f32>(0.32, 0.27, 0.2);

fn world_ray(frag: vec2<f32>) -> vec3<f32> {
    let ndc = (frag - view.viewport.xy) / view.viewport.zw * 2.0 - 1.0;
    // WebGPU's clip space: y up, depth 0 at the near plane.
    let near = view.world_from_clip * vec4<f32>(ndc.x, -ndc.y, 0.0, 1.0);
    return normalize(near.xyz / near.w - view.world_position);
}

fn shade(dir: vec3<f32>) -> vec3<f32> {
    if dir.y >= 0.0 {
        return mix(view.fog.color.rgb, ZENITH, dir.y);
    }
    let t = -view.world_position.y / dir.y;
    let seen = exp(-view.fog.density * max(t - view.fog.start, 0.0));
    return mix(view.fog.color.rgb, GROUND, seen);
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let graded = view.color_grading * shade(world_ray(frag.xy));
    return vec4<f32>(graded * view.exposure, 1.0);
}
