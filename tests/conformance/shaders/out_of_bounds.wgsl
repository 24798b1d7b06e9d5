// Out-of-bounds access as WGSL allows it: a load past the end of an array
// may return the zero value or a value made of bytes from any memory
// location of the bound buffer (or of the variable, for private and
// workgroup memory), and for a vector also (0, 0, 0, x) with x 0, 1 or
// the largest integer; an out-of-bounds store may be dropped or land
// anywhere in the bound buffer (the variable), never outside it. Each
// array holds words of repeated bytes from its own alphabet, so the
// shader can flag (1) "this value is one the spec allows" exactly; the
// expectation is all 1. A buffer bound next to the stored-to one
// (`guard`) must keep its words. Indices come from a buffer, so nothing
// is known at compile time. For textures: textureLoad out of bounds
// returns some texel of the texture, (0, 0, 0, 0) or (0, 0, 0, 1); an
// out-of-bounds textureStore is dropped or lands on some texel.

@group(0) @binding(0) var<storage, read> data: array<u32>;
@group(0) @binding(1) var<storage, read> idx: array<u32>;
@group(0) @binding(2) var<storage, read_write> victim: array<u32>;
@group(0) @binding(3) var<storage, read_write> guard: array<u32>;
@group(0) @binding(4) var<storage, read_write> flags: array<u32>;
@group(0) @binding(5) var<uniform> rows: array<vec4<u32>, 2>;

var<private> table: array<u32, 4> = array<u32, 4>(0x66666666u, 0x77777777u, 0x88888888u, 0x99999999u);
var<private> scratch: array<u32, 4> = array<u32, 4>(0x01010101u, 0x02020202u, 0x03030303u, 0x04040404u);
var<workgroup> shared_words: array<u32, 4>;
var<private> next: u32 = 0u;

fn put(ok: bool) {
    flags[next] = select(0u, 1u, ok);
    next += 1u;
}

fn put_word(w: u32) {
    flags[next] = w;
    next += 1u;
}

// Every byte of v is first + k * step for some k < count.
fn bytes_from(v: u32, first: u32, step: u32, count: u32) -> bool {
    for (var s = 0u; s < 32u; s += 8u) {
        let b = (v >> s) & 0xFFu;
        if b < first || (b - first) % step != 0u || (b - first) / step >= count {
            return false;
        }
    }
    return true;
}

// After the stores: every byte of v is its own original byte or a byte of
// one of the `count` stored words (first, first + 1, ...: repeated bytes).
fn kept_or_stored(v: u32, original: u32, first: u32, count: u32) -> bool {
    for (var s = 0u; s < 32u; s += 8u) {
        let b = (v >> s) & 0xFFu;
        if b != ((original >> s) & 0xFFu) && (b < first || b >= first + count) {
            return false;
        }
    }
    return true;
}

fn row_allowed(v: vec4<u32>) -> bool {
    if all(v.xyz == vec3<u32>(0u)) && (v.w == 0u || v.w == 1u || v.w == 0xFFFFFFFFu) {
        return true;
    }
    return bytes_from(v.x, 0x21u, 1u, 8u) && bytes_from(v.y, 0x21u, 1u, 8u) && bytes_from(v.z, 0x21u, 1u, 8u)
        && bytes_from(v.w, 0x21u, 1u, 8u);
}

@compute @workgroup_size(4)
fn oob_buffers(@builtin(local_invocation_index) lane: u32) {
    shared_words[lane] = 0xC1C1C1C1u + lane * 0x01010101u;
    workgroupBarrier();
    if lane != 0u {
        return;
    }
    let n = arrayLength(&idx);
    for (var k = 0u; k < n; k++) {
        let i = idx[k];
        let v = data[i];
        put(v == 0u || bytes_from(v, 0x11u, 0x11u, 5u));
        let s = data[bitcast<i32>(i)];
        put(s == 0u || bytes_from(s, 0x11u, 0x11u, 5u));
        let t = table[i];
        put(t == 0u || bytes_from(t, 0x66u, 0x11u, 4u));
        let w = shared_words[i];
        put(w == 0u || bytes_from(w, 0xC1u, 1u, 4u));
        put(row_allowed(rows[i]));
    }
    for (var k = 0u; k < n; k++) {
        victim[idx[k]] = 0xE1E1E1E1u + k * 0x01010101u;
        scratch[idx[k]] = 0xF1F1F1F1u + k * 0x01010101u;
    }
    for (var e = 0u; e < 4u; e++) {
        put(kept_or_stored(victim[e], (e + 1u) * 0x01010101u, 0xE1u, n));
        put(kept_or_stored(scratch[e], (e + 1u) * 0x01010101u, 0xF1u, n));
    }
    for (var e = 0u; e < 4u; e++) {
        put_word(guard[e]);
    }
    put_word(arrayLength(&data));
    put_word(arrayLength(&victim));
}

@group(0) @binding(0) var tex_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(1) var<storage, read> coords: array<vec2<i32>>;

fn texel(x: i32, y: i32) -> vec4<f32> {
    return vec4<f32>(f32(x + 1), f32(y + 1), 3.0, 4.0);
}

@compute @workgroup_size(1)
fn tex_write() {
    for (var y = 0; y < 2; y++) {
        for (var x = 0; x < 2; x++) {
            textureStore(tex_out, vec2<i32>(x, y), texel(x, y));
        }
    }
    for (var k = 0u; k < arrayLength(&coords); k++) {
        textureStore(tex_out, coords[k], vec4<f32>(9.0));
    }
}

@group(0) @binding(0) var tex: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> levels: array<i32>;
@group(0) @binding(3) var<storage, read_write> tex_flags: array<u32>;

const TEX_FLAGS_AT: u32 = 49u;

@compute @workgroup_size(1)
fn tex_read() {
    var seen: array<vec4<f32>, 4>;
    var at = TEX_FLAGS_AT;
    for (var y = 0; y < 2; y++) {
        for (var x = 0; x < 2; x++) {
            let v = textureLoad(tex, vec2<i32>(x, y), 0);
            seen[y * 2 + x] = v;
            tex_flags[at] = select(0u, 1u, all(v == texel(x, y)) || all(v == vec4<f32>(9.0)));
            at += 1u;
        }
    }
    let n = arrayLength(&coords) + arrayLength(&levels);
    for (var k = 0u; k < n; k++) {
        var v: vec4<f32>;
        if k < arrayLength(&coords) {
            v = textureLoad(tex, coords[k], 0);
        } else {
            v = textureLoad(tex, vec2<i32>(0, 0), levels[k - arrayLength(&coords)]);
        }
        var ok = all(v == vec4<f32>(0.0)) || all(v == vec4<f32>(0.0, 0.0, 0.0, 1.0));
        for (var t = 0; t < 4; t++) {
            ok = ok || all(v == seen[t]);
        }
        tex_flags[at] = select(0u, 1u, ok);
        at += 1u;
    }
    tex_flags[at] = 0x00B5u;
}
