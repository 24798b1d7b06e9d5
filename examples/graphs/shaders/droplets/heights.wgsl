// Droplets, first and last passes: the heightmap goes from a 16-bit PNG
// into a storage buffer of f32 (which the droplet pass declares as
// array<atomic<u32>> and adds to with compare-exchange loops on the bit
// patterns, WebGPU having no float atomics), and the eroded terrain is
// drawn as a shaded relief.

struct Grid {
    width: u32,
    height: u32,
}

@group(0) @binding(0) var terrain: texture_2d<f32>;
@group(0) @binding(1) var<storage, read_write> heights: array<f32>;
@group(0) @binding(2) var<storage, read> eroded: array<f32>;
@group(0) @binding(3) var relief: texture_storage_2d<rgba8unorm, write>;

@group(1) @binding(0) var<uniform> grid: Grid;
@group(1) @binding(1) var<uniform> relief_scale: f32;

// The heightmap (red channel, nearest texel) into a grid.width x
// grid.height row-major buffer.
@compute @workgroup_size(16, 16)
fn load_heights(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= grid.width || id.y >= grid.height) {
        return;
    }
    let src = textureDimensions(terrain);
    let texel = min(id.xy * src / vec2<u32>(grid.width, grid.height), src - vec2<u32>(1u));
    heights[id.y * grid.width + id.x] = textureLoad(terrain, texel, 0).r;
}

fn height_at(x: i32, y: i32) -> f32 {
    let cx = u32(clamp(x, 0, i32(grid.width) - 1));
    let cy = u32(clamp(y, 0, i32(grid.height) - 1));
    return eroded[cy * grid.width + cx];
}

// Hillshade lit from the upper left, tinted from green lowlands to grey
// peaks; `relief_scale` exaggerates the slopes.
@compute @workgroup_size(8, 8)
fn draw_relief(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(relief);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let x = i32(id.x * grid.width / size.x);
    let y = i32(id.y * grid.height / size.y);
    let h = height_at(x, y);
    let dx = height_at(x + 1, y) - height_at(x - 1, y);
    let dy = height_at(x, y + 1) - height_at(x, y - 1);
    let normal = normalize(vec3<f32>(-relief_scale * dx, -relief_scale * dy, 2.0));
    let light = normalize(vec3<f32>(-1.0, -1.0, 1.5));
    let shade = 0.25 + 0.75 * max(dot(normal, light), 0.0);
    let tint = mix(vec3<f32>(0.35, 0.55, 0.25), vec3<f32>(0.8, 0.78, 0.75), clamp(h, 0.0, 1.0));
    textureStore(relief, id.xy, vec4<f32>(shade * tint, 1.0));
}
