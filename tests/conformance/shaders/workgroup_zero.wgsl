// Workgroup memory is zero when a workgroup starts (WGSL: variables in
// the workgroup address space are zero-initialized). Eight workgroups of
// 64 invocations each read every workgroup variable before any write,
// then dirty it all (so a backend that reused the memory of an earlier
// workgroup without zeroing it would show that workgroup's values), and
// record what they read: 80 words per workgroup.

struct Cell {
    v: vec3<f32>,
    k: i32,
    m: mat2x2<f32>,
    tags: array<u32, 4>,
}

const LANES: u32 = 64u;
const STRIDE: u32 = 80u;

var<workgroup> words: array<u32, 64>;
var<workgroup> cell: Cell;
var<workgroup> scale: f32;
var<workgroup> count: atomic<u32>;

@group(0) @binding(0) var<storage, read_write> seen: array<u32>;

@compute @workgroup_size(64)
fn read_then_dirty(@builtin(local_invocation_index) lane: u32, @builtin(workgroup_id) group: vec3<u32>) {
    let base = group.x * STRIDE;
    // Every read happens before the barrier; every write after it.
    seen[base + lane] = words[lane];
    if lane == 0u {
        let c = cell;
        seen[base + 64u] = bitcast<u32>(c.v.x);
        seen[base + 65u] = bitcast<u32>(c.v.y);
        seen[base + 66u] = bitcast<u32>(c.v.z);
        seen[base + 67u] = bitcast<u32>(c.k);
        seen[base + 68u] = bitcast<u32>(c.m[0].x);
        seen[base + 69u] = bitcast<u32>(c.m[0].y);
        seen[base + 70u] = bitcast<u32>(c.m[1].x);
        seen[base + 71u] = bitcast<u32>(c.m[1].y);
        for (var t = 0u; t < 4u; t++) {
            seen[base + 72u + t] = c.tags[t];
        }
        seen[base + 76u] = bitcast<u32>(scale);
        seen[base + 77u] = atomicLoad(&count);
    }
    workgroupBarrier();
    words[lane] = 0xDEAD0000u | lane;
    atomicAdd(&count, 1u);
    if lane == 1u {
        cell = Cell(vec3<f32>(-1.0), -1, mat2x2<f32>(-1.0, -1.0, -1.0, -1.0), array<u32, 4>(9u, 9u, 9u, 9u));
        scale = -1.0;
    }
    workgroupBarrier();
    if lane == 0u {
        // Every lane added one to a counter that started at zero.
        seen[base + 78u] = atomicLoad(&count);
        seen[base + 79u] = group.x;
    }
}
