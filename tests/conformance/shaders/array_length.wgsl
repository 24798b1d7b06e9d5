// arrayLength of six runtime-sized arrays whose element strides are 4, 8,
// 12, 16, 32 and 48 bytes (WGSL's alignment and size rules give each: see
// expected.py), and of the output itself. Each is bound by vista with its
// declared element count; the spec says the shader sees exactly that.

struct Three {          // align 4, size 12: stride 12
    a: f32,
    b: u32,
    c: f32,
}

struct Padded {         // vec3 (align 16) + f32 + vec2: size 24, align 16: stride 32
    dir: vec3<f32>,
    len: f32,
    uv: vec2<f32>,
}

struct Basis {          // mat3x3<f32>: three columns of 16 bytes: stride 48
    m: mat3x3<f32>,
}

@group(0) @binding(0) var<storage, read> a4: array<u32>;
@group(0) @binding(1) var<storage, read> a8: array<vec2<f32>>;
@group(0) @binding(2) var<storage, read> a12: array<Three>;
@group(0) @binding(3) var<storage, read> a16: array<vec3<f32>>;
@group(0) @binding(4) var<storage, read> a32: array<Padded>;
@group(0) @binding(5) var<storage, read> a48: array<Basis>;
@group(1) @binding(0) var<storage, read_write> seen: array<u32>;

@compute @workgroup_size(1)
fn probe_lengths() {
    seen[0] = arrayLength(&a4);
    seen[1] = arrayLength(&a8);
    seen[2] = arrayLength(&a12);
    seen[3] = arrayLength(&a16);
    seen[4] = arrayLength(&a32);
    seen[5] = arrayLength(&a48);
    seen[6] = arrayLength(&seen);
    seen[7] = 0xA11u;
}
