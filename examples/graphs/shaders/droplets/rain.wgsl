// Droplet (particle) hydraulic erosion: every invocation is one raindrop
// that starts at a random cell and runs downhill over the shared
// heightmap for up to `lifetime` steps, picking up sediment where it
// speeds down and dropping it where it slows or climbs.
//
// All droplets run at once on the same heightmap. Their writes are float
// additions done with compare-exchange loops, so no sediment is lost, but
// a droplet reads heights while others are changing them and float
// addition is not associative: which droplet passes first changes the
// paths of the ones after it. The result depends on the order the driver
// runs invocations in (deterministic = false); its statistics do not.

struct Grid {
    width: u32,
    height: u32,
}

struct DropletRules {
    droplet_count: u32,
    lifetime: u32,
    seed: u32,
    inertia: f32,
    capacity_factor: f32,
    min_capacity: f32,
    erode_rate: f32,
    deposit_rate: f32,
    evaporation: f32,
    gravity: f32,
    _pad0: f32,
    _pad1: f32,
}

@group(0) @binding(0) var<storage, read_write> heights: array<atomic<u32>>;
@group(1) @binding(0) var<uniform> grid: Grid;
@group(1) @binding(1) var<uniform> rules: DropletRules;

// PCG-style integer hash (a 32-bit LCG step, then an xorshift-multiply
// output permutation).
fn hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn unit(v: u32) -> f32 {
    return f32(hash(v) >> 8u) / 16777216.0;
}

fn cell(x: i32, y: i32) -> u32 {
    return u32(y) * grid.width + u32(x);
}

fn load(i: u32) -> f32 {
    return bitcast<f32>(atomicLoad(&heights[i]));
}

// heights[i] += amount, atomically: retry until no other droplet wrote
// in between.
fn add(i: u32, amount: f32) {
    var old = atomicLoad(&heights[i]);
    loop {
        let next = bitcast<u32>(bitcast<f32>(old) + amount);
        let r = atomicCompareExchangeWeak(&heights[i], old, next);
        if (r.exchanged) {
            break;
        }
        old = r.old_value;
    }
}

struct Sample {
    height: f32,
    gradient: vec2<f32>,
}

// Bilinear height and its gradient inside the cell whose top-left corner
// is floor(p); p must be at least one cell inside the right/bottom edge.
fn sample(p: vec2<f32>) -> Sample {
    let c = vec2<i32>(floor(p));
    let t = p - floor(p);
    let h00 = load(cell(c.x, c.y));
    let h10 = load(cell(c.x + 1, c.y));
    let h01 = load(cell(c.x, c.y + 1));
    let h11 = load(cell(c.x + 1, c.y + 1));
    let gradient = vec2<f32>(
        mix(h10 - h00, h11 - h01, t.y),
        mix(h01 - h00, h11 - h10, t.x),
    );
    let h = mix(mix(h00, h10, t.x), mix(h01, h11, t.x), t.y);
    return Sample(h, gradient);
}

// Adds amount (negative: removes it) at p, shared among the four
// corners of its cell by bilinear weights.
fn splat(p: vec2<f32>, amount: f32) {
    let c = vec2<i32>(floor(p));
    let t = p - floor(p);
    add(cell(c.x, c.y), amount * (1.0 - t.x) * (1.0 - t.y));
    add(cell(c.x + 1, c.y), amount * t.x * (1.0 - t.y));
    add(cell(c.x, c.y + 1), amount * (1.0 - t.x) * t.y);
    add(cell(c.x + 1, c.y + 1), amount * t.x * t.y);
}

fn inside(p: vec2<f32>) -> bool {
    return p.x >= 0.0 && p.y >= 0.0 && p.x < f32(grid.width - 1u) && p.y < f32(grid.height - 1u);
}

@compute @workgroup_size(64)
fn rain_droplets(@builtin(global_invocation_id) gid: vec3<u32>) {
    let drop = gid.x;
    if (drop >= rules.droplet_count) {
        return;
    }
    let key = hash(drop ^ hash(rules.seed));
    var p = vec2<f32>(unit(key) * f32(grid.width - 1u), unit(key + 1u) * f32(grid.height - 1u));
    var dir = vec2<f32>(0.0);
    var speed = 1.0;
    var water = 1.0;
    var sediment = 0.0;
    for (var step = 0u; step < rules.lifetime; step = step + 1u) {
        let here = sample(p);
        // Turn downhill, keeping some of the old direction.
        dir = dir * rules.inertia - here.gradient * (1.0 - rules.inertia);
        let len = length(dir);
        if (len < 1e-6) {
            let a = 6.2831853 * unit(key + 2u + step);
            dir = vec2<f32>(cos(a), sin(a));
        } else {
            dir = dir / len;
        }
        let next = p + dir;
        if (!inside(next)) {
            break;
        }
        let dh = sample(next).height - here.height;
        let capacity = max(-dh * speed * water * rules.capacity_factor, rules.min_capacity);
        if (dh > 0.0 || sediment > capacity) {
            // Uphill: fill the pit behind; else drop part of the excess.
            var dropped = (sediment - capacity) * rules.deposit_rate;
            if (dh > 0.0) {
                dropped = min(dh, sediment);
            }
            sediment = sediment - dropped;
            splat(p, dropped);
        } else {
            // Never dig deeper than the step down.
            let taken = min((capacity - sediment) * rules.erode_rate, -dh);
            sediment = sediment + taken;
            splat(p, -taken);
        }
        speed = sqrt(max(0.0, speed * speed - dh * rules.gravity));
        water = water * (1.0 - rules.evaporation);
        p = next;
    }
    // What it still carries settles where it stopped.
    splat(p, sediment);
}
