// Runtime-sized storage arrays of structs, read back leaf by leaf: one
// fed from inline data (one number per scalar, element after element),
// one from a raw .bin file that expected.py lays out by WGSL's rules
// (padding filled with 0xEE bytes), and one behind a fixed header (a struct
// whose last member is the runtime array: the elements start at the
// array's alignment, 16 bytes in; the header, which nothing feeds, is zero).
// Item: vec3 + u32 sharing 16 bytes, vec2, i32 then 4 bytes of padding
// before a mat2x2, array<u32, 3>, then vec4<i32> at 64: 80 bytes.

struct Item {
    p: vec3<f32>,
    id: u32,
    uv: vec2<f32>,
    k: i32,
    m: mat2x2<f32>,
    tags: array<u32, 3>,
    q: vec4<i32>,
}

struct Tail {
    count: u32,
    items: array<Item>,
}

@group(0) @binding(0) var<storage, read> from_data: array<Item>;
@group(0) @binding(1) var<storage, read> from_file: array<Item>;
@group(0) @binding(2) var<storage, read> tail: Tail;
@group(0) @binding(3) var<storage, read_write> leaves: array<u32>;

var<private> next: u32 = 0u;

fn put(x: u32) {
    leaves[next] = x;
    next += 1u;
}

fn put_f(x: f32) {
    put(bitcast<u32>(x));
}

fn put_item(it: Item) {
    put_f(it.p.x); put_f(it.p.y); put_f(it.p.z);
    put(it.id);
    put_f(it.uv.x); put_f(it.uv.y);
    put(bitcast<u32>(it.k));
    put_f(it.m[0].x); put_f(it.m[0].y); put_f(it.m[1].x); put_f(it.m[1].y);
    put(it.tags[0]); put(it.tags[1]); put(it.tags[2]);
    put(bitcast<u32>(it.q.x)); put(bitcast<u32>(it.q.y)); put(bitcast<u32>(it.q.z)); put(bitcast<u32>(it.q.w));
}

@compute @workgroup_size(1)
fn read_items() {
    for (var i = 0u; i < arrayLength(&from_data); i++) { put_item(from_data[i]); }
    for (var i = 0u; i < arrayLength(&from_file); i++) { put_item(from_file[i]); }
    for (var i = 0u; i < arrayLength(&tail.items); i++) { put_item(tail.items[i]); }
    put(arrayLength(&from_data));
    put(arrayLength(&from_file));
    put(arrayLength(&tail.items));
    put(tail.count);
    put(0x57ACu);
}
