// Compressed-row offsets from per-row counts, as engines build them for
// sparse grids and particle bins: offsets[i] is the exclusive prefix sum of
// counts[0..i], and offsets[n] (one past the rows) holds the total. Every
// length comes from arrayLength, as such kernels take it from the host's
// buffers: no uniform says how many rows there are.

const BLOCK: u32 = 256u;

@group(0) @binding(0) var<storage, read> counts: array<u32>;
@group(0) @binding(1) var<storage, read_write> offsets: array<u32>;
@group(0) @binding(2) var<storage, read_write> block_totals: array<u32>;

var<workgroup> lanes: array<u32, 256>;

// Inclusive Hillis-Steele scan of lanes[] across the workgroup.
fn scan_lanes(lane: u32) {
    for (var step = 1u; step < BLOCK; step = step * 2u) {
        var carried = 0u;
        if (lane >= step) {
            carried = lanes[lane - step];
        }
        workgroupBarrier();
        lanes[lane] = lanes[lane] + carried;
        workgroupBarrier();
    }
}

// Each block of 256 rows: its exclusive scan, and its total.
@compute @workgroup_size(256)
fn scan_rows(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let rows = arrayLength(&counts);
    let row = wid.x * BLOCK + lid.x;
    var count = 0u;
    if (row < rows) {
        count = counts[row];
    }
    lanes[lid.x] = count;
    workgroupBarrier();
    scan_lanes(lid.x);
    if (row < rows) {
        offsets[row] = lanes[lid.x] - count;
    }
    if (lid.x == BLOCK - 1u) {
        block_totals[wid.x] = lanes[lid.x];
    }
}

// The block totals' exclusive scan in place (one workgroup, at most 256
// blocks), the grand total in the slot after the last block.
@compute @workgroup_size(256)
fn scan_block_totals(@builtin(local_invocation_id) lid: vec3<u32>) {
    let blocks = arrayLength(&block_totals) - 1u;
    var total = 0u;
    if (lid.x < blocks) {
        total = block_totals[lid.x];
    }
    lanes[lid.x] = total;
    workgroupBarrier();
    scan_lanes(lid.x);
    if (lid.x < blocks) {
        block_totals[lid.x] = lanes[lid.x] - total;
    }
    if (lid.x == BLOCK - 1u) {
        block_totals[blocks] = lanes[lid.x];
    }
}

// Each row adds its block's offset; the slot after the last row takes the total.
@compute @workgroup_size(256)
fn add_block_offsets(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let rows = arrayLength(&offsets) - 1u;
    if (gid.x < rows) {
        offsets[gid.x] = offsets[gid.x] + block_totals[wid.x];
    } else if (gid.x == rows) {
        offsets[rows] = block_totals[arrayLength(&block_totals) - 1u];
    }
}
