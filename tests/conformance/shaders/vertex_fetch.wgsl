// Vertex fetch as WebGPU converts each vertex format: every attribute of
// one per-vertex buffer (8- and 16-bit integers and normalized values,
// float16, float32x3, unorm10-10-10-2) and one per-instance attribute,
// passed flat to the fragment stage, which writes them with the vertex and
// instance index into a storage buffer (40 words per point), then the
// length of the instance buffer seen as storage. Each point
// covers exactly one pixel of an 8 x 1 target.

struct Attributes {
    @location(0) u8: vec2<u32>,
    @location(1) i8: vec2<i32>,
    @location(2) un8: vec4<f32>,
    @location(3) sn8: vec4<f32>,
    @location(4) u16: vec2<u32>,
    @location(5) i16: vec2<i32>,
    @location(6) un16: vec2<f32>,
    @location(7) h4: vec4<f32>,
    @location(8) f3: vec3<f32>,
    @location(9) packed: vec4<f32>,
    @location(10) per_instance: vec2<u32>,
}

struct Point {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) u8: vec2<u32>,
    @location(1) @interpolate(flat) i8: vec2<i32>,
    @location(2) @interpolate(flat) un8: vec4<f32>,
    @location(3) @interpolate(flat) sn8: vec4<f32>,
    @location(4) @interpolate(flat) u16: vec2<u32>,
    @location(5) @interpolate(flat) i16: vec2<i32>,
    @location(6) @interpolate(flat) un16: vec2<f32>,
    @location(7) @interpolate(flat) h4: vec4<f32>,
    @location(8) @interpolate(flat) f3: vec3<f32>,
    @location(9) @interpolate(flat) packed: vec4<f32>,
    @location(10) @interpolate(flat) per_instance: vec2<u32>,
    @location(11) @interpolate(flat) ids: vec2<u32>,
}

@group(0) @binding(0) var<storage, read_write> fetched: array<u32>;
// The instance buffer again, as storage in the same pass: a buffer with
// vertex usage must still show its declared length (wgpu pads such a
// buffer; the binding must not cover the padding).
@group(0) @binding(1) var<storage, read> instance_words: array<u32>;

const VERTICES_PER_INSTANCE: u32 = 3u;
const WIDTH: f32 = 8.0;

@vertex
fn fetch_vertex(a: Attributes, @builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> Point {
    let slot = i * VERTICES_PER_INSTANCE + v;
    let x = (f32(slot) + 0.5) / WIDTH * 2.0 - 1.0;
    return Point(vec4<f32>(x, 0.0, 0.0, 1.0), a.u8, a.i8, a.un8, a.sn8, a.u16, a.i16, a.un16, a.h4, a.f3,
                 a.packed, a.per_instance, vec2<u32>(v, i));
}

var<private> at: u32;

fn put(x: u32) {
    fetched[at] = x;
    at += 1u;
}

fn put_f(x: f32) {
    put(bitcast<u32>(x));
}

@fragment
fn record(p: Point) -> @location(0) vec4<f32> {
    at = (p.ids.y * VERTICES_PER_INSTANCE + p.ids.x) * 40u;
    put(p.ids.x); put(p.ids.y);
    put(p.u8.x); put(p.u8.y);
    put(bitcast<u32>(p.i8.x)); put(bitcast<u32>(p.i8.y));
    put_f(p.un8.x); put_f(p.un8.y); put_f(p.un8.z); put_f(p.un8.w);
    put_f(p.sn8.x); put_f(p.sn8.y); put_f(p.sn8.z); put_f(p.sn8.w);
    put(p.u16.x); put(p.u16.y);
    put(bitcast<u32>(p.i16.x)); put(bitcast<u32>(p.i16.y));
    put_f(p.un16.x); put_f(p.un16.y);
    put_f(p.h4.x); put_f(p.h4.y); put_f(p.h4.z); put_f(p.h4.w);
    put_f(p.f3.x); put_f(p.f3.y); put_f(p.f3.z);
    put_f(p.packed.x); put_f(p.packed.y); put_f(p.packed.z); put_f(p.packed.w);
    put(p.per_instance.x); put(p.per_instance.y);
    put(arrayLength(&instance_words));
    return vec4<f32>(1.0);
}
