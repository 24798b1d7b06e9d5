// Every leaf of one struct, read by the shader and written out in
// declaration order as raw bits: a uniform fed from params
// (`from_uniform`) and the same struct in a storage buffer fed from inline
// data (`from_storage`). The host packs the bytes by WGSL's layout rules
// (mat3x3 columns padded to 16 bytes, vec3 + f32 sharing 16, a nested
// struct aligned to 16); expected.py lists the values the shader must see.

struct Inner {
    dir: vec3<f32>,
    s: f32,
}

struct Block {
    a: f32,
    m3: mat3x3<f32>,
    v3: vec3<f32>,
    w: f32,
    v2: vec2<f32>,
    arr: array<vec4<f32>, 2>,
    m2: mat2x2<f32>,
    m42: mat4x2<f32>,
    inner: Inner,
    k: u32,
    i: i32,
    u2: vec2<u32>,
    m4: mat4x4<f32>,
    v4i: vec4<i32>,
}

@group(0) @binding(0) var<uniform> blk: Block;
@group(0) @binding(1) var<storage, read> sblk: Block;
@group(0) @binding(2) var<storage, read_write> leaves: array<u32>;

var<private> next: u32 = 0u;

fn put(x: f32) {
    leaves[next] = bitcast<u32>(x);
    next += 1u;
}

fn put_u(x: u32) {
    leaves[next] = x;
    next += 1u;
}

fn put_all(b: Block) {
    put(b.a);
    for (var c = 0; c < 3; c++) { for (var r = 0; r < 3; r++) { put(b.m3[c][r]); } }
    put(b.v3.x); put(b.v3.y); put(b.v3.z);
    put(b.w);
    put(b.v2.x); put(b.v2.y);
    for (var e = 0; e < 2; e++) { for (var r = 0; r < 4; r++) { put(b.arr[e][r]); } }
    for (var c = 0; c < 2; c++) { for (var r = 0; r < 2; r++) { put(b.m2[c][r]); } }
    for (var c = 0; c < 4; c++) { for (var r = 0; r < 2; r++) { put(b.m42[c][r]); } }
    put(b.inner.dir.x); put(b.inner.dir.y); put(b.inner.dir.z);
    put(b.inner.s);
    put_u(b.k);
    put_u(bitcast<u32>(b.i));
    put_u(b.u2.x); put_u(b.u2.y);
    for (var c = 0; c < 4; c++) { for (var r = 0; r < 4; r++) { put(b.m4[c][r]); } }
    for (var r = 0; r < 4; r++) { put_u(bitcast<u32>(b.v4i[r])); }
}

@compute @workgroup_size(1)
fn from_uniform() {
    put_all(blk);
}

@compute @workgroup_size(1)
fn from_storage() {
    put_all(sblk);
}
