// Index formats and primitive restart. No vertex buffer: each vertex's
// position comes from its index, which the draw reads from a uint16 or
// uint32 index buffer. The low byte holds a corner of the 8 x 8 target on a
// grid of whole pixels (x in bits 0-3, y in bits 4-7, y down); the bits
// above it must hold the pass's tag (`tag`, the index's high bits): a
// vertex whose index lost or gained high bits lands at the corner (0, 8)
// and draws triangles the expectation does not have. Strips are cut by
// 0xFFFF / 0xFFFFFFFF (WebGPU always restarts strips at the format's
// largest value). Each covered pixel is written 1.

@group(0) @binding(0) var<uniform> tag: u32;

@vertex
fn corner(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    var x = f32(i & 0xFu);
    var y = f32((i >> 4u) & 0xFu);
    if (i >> 8u) != tag {
        x = 0.0;
        y = 8.0;
    }
    return vec4<f32>(x / 4.0 - 1.0, 1.0 - y / 4.0, 0.5, 1.0);
}

@fragment
fn covered() -> @location(0) vec4<u32> {
    return vec4<u32>(1u, 0u, 0u, 0u);
}
