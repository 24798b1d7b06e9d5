// Exclusive prefix sum of u32 values in three dispatches: each 256-value
// block is scanned in workgroup memory (Hillis-Steele), the block totals are
// scanned by one workgroup, and each block then adds its offset.

struct ScanInfo {
    count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

const BLOCK: u32 = 256u;

@group(0) @binding(0) var<uniform> info: ScanInfo;
@group(0) @binding(1) var<storage, read> values: array<u32>;
@group(0) @binding(2) var<storage, read_write> prefix: array<u32>;
@group(0) @binding(3) var<storage, read_write> block_sums: array<u32>;

var<workgroup> tile: array<u32, 256>;

// Inclusive scan of tile[] across the workgroup.
fn scan_tile(lane: u32) {
    for (var offset = 1u; offset < BLOCK; offset = offset * 2u) {
        var add = 0u;
        if (lane >= offset) {
            add = tile[lane - offset];
        }
        workgroupBarrier();
        tile[lane] = tile[lane] + add;
        workgroupBarrier();
    }
}

@compute @workgroup_size(256)
fn scan_blocks(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let i = wid.x * BLOCK + lid.x;
    var v = 0u;
    if (i < info.count) {
        v = values[i];
    }
    tile[lid.x] = v;
    workgroupBarrier();
    scan_tile(lid.x);
    if (i < info.count) {
        prefix[i] = tile[lid.x] - v;
    }
    if (lid.x == BLOCK - 1u) {
        block_sums[wid.x] = tile[lid.x];
    }
}

@compute @workgroup_size(256)
fn scan_block_sums(@builtin(local_invocation_id) lid: vec3<u32>) {
    let blocks = (info.count + BLOCK - 1u) / BLOCK;
    var v = 0u;
    if (lid.x < blocks) {
        v = block_sums[lid.x];
    }
    tile[lid.x] = v;
    workgroupBarrier();
    scan_tile(lid.x);
    if (lid.x < blocks) {
        block_sums[lid.x] = tile[lid.x] - v;
    }
}

@compute @workgroup_size(256)
fn add_block_offsets(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    if (gid.x < info.count) {
        prefix[gid.x] = prefix[gid.x] + block_sums[wid.x];
    }
}
