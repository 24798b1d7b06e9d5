// Draw offsets as WebGPU's draw() and drawIndexed() apply them: points on
// an 8 x 8 target, one per (vertex_index, instance_index) at pixel
// (vertex_index, instance_index). Each records, at that pixel's slot of a
// storage buffer, its vertex and instance index and the per-vertex and
// per-instance attributes fetched for it, so the words show which vertex
// and instance each draw started from and what base_vertex added.

struct Point {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) record: vec4<u32>,
}

@group(0) @binding(0) var<storage, read_write> seen: array<vec4<u32>>;

const SIDE: f32 = 8.0;

@vertex
fn place(@location(0) mark: u32, @location(1) tag: u32, @builtin(vertex_index) v: u32,
         @builtin(instance_index) i: u32) -> Point {
    let ndc = (vec2<f32>(f32(v), f32(i)) + 0.5) / SIDE * 2.0 - 1.0;
    return Point(vec4<f32>(ndc.x, -ndc.y, 0.0, 1.0), vec4<u32>(v, i, mark, tag));
}

@fragment
fn record(p: Point) -> @location(0) vec4<f32> {
    let at = vec2<u32>(p.position.xy);
    seen[at.y * 8u + at.x] = p.record;
    return vec4<f32>(1.0);
}
