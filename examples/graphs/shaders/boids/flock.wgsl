// Boids (Reynolds 1987) on a storage buffer of structs, one step per
// dispatch, ping-ponged: every boid reads the whole previous generation
// from `boids_in` and writes itself to `boids_out`.
//
// Two flocks share the sky: a boid keeps its distance from every boid
// but only steers towards and along its own flock. All three rules use a
// smooth weight (1 - d^2 / r^2)^2 that falls to zero at the rule's radius
// and are summed without normalising, so a neighbour drifting across a
// radius changes the steering continuously; the sky's edge is a soft
// spring rather than a wrap-around, for the same reason (a tiny rounding
// difference never teleports a boid to the other side).

struct Boid {
    position: vec2<f32>,
    velocity: vec2<f32>,
    flock: u32,
    _pad0: u32,
}

struct FlockRules {
    separation_radius: f32,
    alignment_radius: f32,
    cohesion_radius: f32,
    separation_weight: f32,
    alignment_weight: f32,
    cohesion_weight: f32,
    min_speed: f32,
    max_speed: f32,
    edge: f32,
    edge_spring: f32,
}

@group(0) @binding(0) var<storage, read> boids_in: array<Boid>;
@group(0) @binding(1) var<storage, read_write> boids_out: array<Boid>;

@group(1) @binding(0) var<uniform> rules: FlockRules;
@group(1) @binding(1) var<uniform> delta_t: f32;

// (1 - d^2 / r^2)^2 inside the radius, 0 outside.
fn falloff(dist_sq: f32, radius: f32) -> f32 {
    let t = max(0.0, 1.0 - dist_sq / (radius * radius));
    return t * t;
}

// Pull back towards the sky when a coordinate is past +-edge.
fn edge_pull(p: f32) -> f32 {
    return rules.edge_spring * (max(0.0, -rules.edge - p) - max(0.0, p - rules.edge));
}

@compute @workgroup_size(64)
fn step_boids(@builtin(global_invocation_id) gid: vec3<u32>) {
    let count = arrayLength(&boids_in);
    let i = gid.x;
    if (i >= count) {
        return;
    }
    let me = boids_in[i];
    var separation = vec2<f32>(0.0);
    var alignment = vec2<f32>(0.0);
    var cohesion = vec2<f32>(0.0);
    for (var j = 0u; j < count; j = j + 1u) {
        if (j == i) {
            continue;
        }
        let other = boids_in[j];
        let offset = other.position - me.position;
        let dist_sq = dot(offset, offset);
        separation = separation - offset * falloff(dist_sq, rules.separation_radius);
        if (other.flock == me.flock) {
            alignment = alignment + (other.velocity - me.velocity) * falloff(dist_sq, rules.alignment_radius);
            cohesion = cohesion + offset * falloff(dist_sq, rules.cohesion_radius);
        }
    }
    let steer = rules.separation_weight * separation
        + rules.alignment_weight * alignment
        + rules.cohesion_weight * cohesion
        + vec2<f32>(edge_pull(me.position.x), edge_pull(me.position.y));
    var velocity = me.velocity + delta_t * steer;
    let speed = length(velocity);
    if (speed > rules.max_speed) {
        velocity = velocity * (rules.max_speed / speed);
    } else if (speed < rules.min_speed && speed > 1e-6) {
        velocity = velocity * (rules.min_speed / speed);
    }
    boids_out[i] = Boid(me.position + delta_t * velocity, velocity, me.flock, 0u);
}
