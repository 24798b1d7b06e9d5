// Hydraulic erosion with the pipe model (virtual pipes between the four
// edge neighbours), after Mei, Decaudin and Hu 2007, "Fast Hydraulic
// Erosion Simulation and Visualization on GPU".
//
// A time step is two passes, run together as one repeated group: the
// outflow pass (rain, then each cell's outflow through its pipes from the
// last step's) and the update pass (the water that arrives and leaves,
// velocity, sediment transport, erosion or deposition, evaporation), which
// reads the outflow the first pass wrote. Suspended sediment moves
// through the pipes with the water (a conservative upwind scheme) rather
// than by the paper's semi-Lagrangian back-trace.
//
// Terrain height b is an r32float storage texture (read here, written as
// the next step's); the fluid texel holds x water depth d, y suspended
// sediment s, zw the flow velocity; the flux texel holds the outflow
// towards -x, +x, -y, +y (left, right, top, bottom), volume per unit
// time. Fluid and flux are read as sampled textures with textureLoad: in
// the outflow pass flux_in is the last step's outflow, in the update pass
// (after the swap) this step's. Lengths in cells of `cell_size`.

struct PipeModel {
    gravity: f32,
    pipe_area: f32,
    cell_size: f32,
    _pad0: f32,
}

struct SedimentModel {
    capacity: f32,
    dissolve_rate: f32,
    deposit_rate: f32,
    min_tilt: f32,
    erosion_depth: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

@group(0) @binding(0) var terrain_in: texture_storage_2d<r32float, read>;
@group(0) @binding(1) var fluid_in: texture_2d<f32>;
@group(0) @binding(2) var flux_in: texture_2d<f32>;
@group(0) @binding(3) var terrain_out: texture_storage_2d<r32float, write>;
@group(0) @binding(4) var fluid_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var flux_out: texture_storage_2d<rgba32float, write>;

@group(1) @binding(0) var<uniform> time_step: f32;
@group(1) @binding(1) var<uniform> rain_rate: f32;
@group(1) @binding(2) var<uniform> evaporation_rate: f32;

@group(2) @binding(0) var<uniform> pipes: PipeModel;
@group(2) @binding(1) var<uniform> sediment: SedimentModel;

fn grid() -> vec2<i32> {
    return vec2<i32>(textureDimensions(terrain_in));
}

// Terrain height, water depth and suspended sediment at p, clamped to the
// grid (a closed basin: the border repeats).
fn state_at(p: vec2<i32>) -> vec3<f32> {
    let q = clamp(p, vec2<i32>(0), grid() - vec2<i32>(1));
    let fluid = textureLoad(fluid_in, q, 0);
    return vec3<f32>(textureLoad(terrain_in, q).x, fluid.x, fluid.y);
}

// Water depth after this step's rain.
fn rained(s: vec3<f32>) -> f32 {
    return s.y + time_step * rain_rate;
}

// Height of the water surface after rain.
fn surface(p: vec2<i32>) -> f32 {
    let s = state_at(p);
    return s.x + rained(s);
}

// This step's outflow from cell p (inside the grid) towards its left,
// right, top and bottom neighbours, from the last step's (flux_in in the
// outflow pass). Each pipe accelerates with the surface difference; no
// pipe leaves the grid; the total is scaled down so that a cell never
// ships more water than it holds.
fn outflow(p: vec2<i32>) -> vec4<f32> {
    let n = grid();
    let here = state_at(p);
    let depth = rained(here);
    let level = here.x + depth;
    let drop = vec4<f32>(level) - vec4<f32>(
        surface(p + vec2<i32>(-1, 0)),
        surface(p + vec2<i32>(1, 0)),
        surface(p + vec2<i32>(0, -1)),
        surface(p + vec2<i32>(0, 1)),
    );
    let accel = time_step * pipes.pipe_area * pipes.gravity / pipes.cell_size;
    var f = max(vec4<f32>(0.0), textureLoad(flux_in, p, 0) + accel * drop);
    let border = vec4<bool>(p.x == 0, p.x == n.x - 1, p.y == 0, p.y == n.y - 1);
    f = select(f, vec4<f32>(0.0), border);
    let shipped = (f.x + f.y + f.z + f.w) * time_step;
    let volume = depth * pipes.cell_size * pipes.cell_size;
    if (shipped > volume) {
        f = f * (volume / shipped);
    }
    return f;
}

// The share of cell p's water (after rain) that leaves through pipes
// carrying flow f this step: sediment leaves in the same proportion.
fn leaving(p: vec2<i32>, f: f32) -> f32 {
    let volume = rained(state_at(p)) * pipes.cell_size * pipes.cell_size;
    if (volume <= 0.0) {
        return 0.0;
    }
    return min(1.0, f * time_step / volume);
}

@compute @workgroup_size(8, 8)
fn outflow_step(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = grid();
    let p = vec2<i32>(id.xy);
    if (p.x >= n.x || p.y >= n.y) {
        return;
    }
    textureStore(flux_out, id.xy, outflow(p));
}

// This step's outflow of cell p, as the outflow pass wrote it (flux_in in
// the update pass).
fn shipped_by(p: vec2<i32>) -> vec4<f32> {
    return textureLoad(flux_in, p, 0);
}

@compute @workgroup_size(8, 8)
fn update_step(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = grid();
    let p = vec2<i32>(id.xy);
    if (p.x >= n.x || p.y >= n.y) {
        return;
    }
    let here = state_at(p);
    let depth = rained(here);
    let out_here = shipped_by(p);

    // What the neighbours ship towards p this step, and the sediment
    // suspended in it (it rides with the water, mixed evenly).
    var from_left = 0.0;
    var from_right = 0.0;
    var from_top = 0.0;
    var from_bottom = 0.0;
    var sediment_in = 0.0;
    if (p.x > 0) {
        let q = p + vec2<i32>(-1, 0);
        from_left = shipped_by(q).y;
        sediment_in = sediment_in + state_at(q).z * leaving(q, from_left);
    }
    if (p.x < n.x - 1) {
        let q = p + vec2<i32>(1, 0);
        from_right = shipped_by(q).x;
        sediment_in = sediment_in + state_at(q).z * leaving(q, from_right);
    }
    if (p.y > 0) {
        let q = p + vec2<i32>(0, -1);
        from_top = shipped_by(q).w;
        sediment_in = sediment_in + state_at(q).z * leaving(q, from_top);
    }
    if (p.y < n.y - 1) {
        let q = p + vec2<i32>(0, 1);
        from_bottom = shipped_by(q).z;
        sediment_in = sediment_in + state_at(q).z * leaving(q, from_bottom);
    }
    let area = pipes.cell_size * pipes.cell_size;
    let net = from_left + from_right + from_top + from_bottom - (out_here.x + out_here.y + out_here.z + out_here.w);
    let new_depth = max(0.0, depth + time_step * net / area);

    // Velocity: the mean flow through the cell along each axis over the
    // mean depth times the cell's width.
    let through = 0.5 * vec2<f32>(
        from_left - out_here.x + out_here.y - from_right,
        from_top - out_here.z + out_here.w - from_bottom,
    );
    let mean_depth = 0.5 * (depth + new_depth);
    var velocity = vec2<f32>(0.0);
    if (mean_depth > 1e-4) {
        velocity = through / (pipes.cell_size * mean_depth);
    }

    // Sediment transport: what stays plus what arrives.
    let shipped = out_here.x + out_here.y + out_here.z + out_here.w;
    let carried = here.z * (1.0 - leaving(p, shipped)) + sediment_in;

    // Tilt: the steepest way down to a neighbour, so that crests (where
    // central differences vanish) still count as steep.
    let b = here.x;
    let fall = max(
        max(b - state_at(p + vec2<i32>(-1, 0)).x, b - state_at(p + vec2<i32>(1, 0)).x),
        max(b - state_at(p + vec2<i32>(0, -1)).x, b - state_at(p + vec2<i32>(0, 1)).x),
    ) / pipes.cell_size;
    let tilt = max(fall, 0.0) / sqrt(1.0 + fall * fall);
    // Capacity grows with the tilt and the flow speed; it fades to zero as
    // the water layer gets thinner than erosion_depth.
    let wet = clamp(new_depth / sediment.erosion_depth, 0.0, 1.0);
    let capacity = sediment.capacity * max(tilt, sediment.min_tilt) * length(velocity) * wet;

    var terrain = here.x;
    var suspended = carried;
    if (capacity > carried) {
        let taken = min(1.0, sediment.dissolve_rate * time_step) * (capacity - carried);
        terrain = terrain - taken;
        suspended = suspended + taken;
    } else {
        let dropped = min(1.0, sediment.deposit_rate * time_step) * (carried - capacity);
        terrain = terrain + dropped;
        suspended = suspended - dropped;
    }

    let remaining = new_depth * max(0.0, 1.0 - evaporation_rate * time_step);
    textureStore(terrain_out, id.xy, vec4<f32>(terrain, 0.0, 0.0, 1.0));
    textureStore(fluid_out, id.xy, vec4<f32>(remaining, suspended, velocity));
}
