// Integer hashes. Integer-only on purpose: sin-based hashes differ between drivers.
#define_import_path vista::hash

// pcg3d, Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020.
fn pcg3d(input: vec3<u32>) -> vec3<u32> {
    var v = input * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> vec3<u32>(16u);
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return v;
}

// Uniform float in [0, 1) from the top 24 bits of a hash.
fn unit_from_hash(h: u32) -> f32 {
    return f32(h >> 8u) * (1.0 / 16777216.0);
}
