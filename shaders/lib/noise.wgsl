// Noise bases (SPEC 3.1): Perlin's Improved Noise and pcg3d value noise.
#define_import_path vista::noise

#import vista::hash::{pcg3d, unit_from_hash}

// 512-entry permutation (Perlin's table for seed 0, a PCG32 shuffle otherwise),
// built on the CPU so the WGSL and the reference share one definition of it.
@group(0) @binding(2) var<storage, read> perm: array<u32>;

const BASIS_PERLIN: u32 = 0u;
const BASIS_VALUE: u32 = 1u;

// Upper bound of |N| for both bases: value noise stays in [-1, 1); 3D Perlin
// reaches 1.03615 off integer z (numerical max 1.036354 over the cell).
const PERLIN_MAX_ABS: f32 = 1.0364;

fn quintic(t: vec3<f32>) -> vec3<f32> {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

// Gradient = one of the 12 cube edges (h & 15 picks, 4 repeated), dotted with (x, y, z).
fn perlin_grad(hash: u32, p: vec3<f32>) -> f32 {
    let h = hash & 15u;
    let u = select(p.y, p.x, h < 8u);
    let v = select(select(p.z, p.x, h == 12u || h == 14u), p.y, h < 4u);
    return select(-u, u, (h & 1u) == 0u) + select(-v, v, (h & 2u) == 0u);
}

fn perlin(p: vec3<f32>) -> f32 {
    let cell = floor(p);
    let i = vec3<u32>(vec3<i32>(cell) & vec3<i32>(255));
    let f = p - cell;
    let w = quintic(f);
    // Corner hashes through the doubled permutation table.
    let a = perm[i.x] + i.y;
    let b = perm[i.x + 1u] + i.y;
    let aa = perm[a] + i.z;
    let ab = perm[a + 1u] + i.z;
    let ba = perm[b] + i.z;
    let bb = perm[b + 1u] + i.z;
    let x0 = mix(perlin_grad(perm[aa], f), perlin_grad(perm[ba], f - vec3(1.0, 0.0, 0.0)), w.x);
    let x1 = mix(perlin_grad(perm[ab], f - vec3(0.0, 1.0, 0.0)), perlin_grad(perm[bb], f - vec3(1.0, 1.0, 0.0)), w.x);
    let lower = mix(x0, x1, w.y);
    // On an integer z plane (the 2D kernels' z_slice 0: fbm, ridged, the
    // terrains) w.z = 0, so the upper face weighs exactly 0 and
    // mix(lower, upper, 0) = lower: its four corners are skipped, with the
    // same result (tests/noise.rs checks the bits against the full formula).
    if f.z == 0.0 {
        return lower;
    }
    let x2 = mix(perlin_grad(perm[aa + 1u], f - vec3(0.0, 0.0, 1.0)), perlin_grad(perm[ba + 1u], f - vec3(1.0, 0.0, 1.0)), w.x);
    let x3 = mix(perlin_grad(perm[ab + 1u], f - vec3(0.0, 1.0, 1.0)), perlin_grad(perm[bb + 1u], f - vec3(1.0, 1.0, 1.0)), w.x);
    return mix(lower, mix(x2, x3, w.y), w.z);
}

// Lattice value in [-1, 1): pcg3d of the signed cell, seed folded into z by a Weyl step.
fn lattice_value(cell: vec3<i32>, seed: u32) -> f32 {
    let h = pcg3d(bitcast<vec3<u32>>(cell) + vec3<u32>(0u, 0u, seed * 0x9E3779B9u));
    return unit_from_hash(h.x) * 2.0 - 1.0;
}

fn value_noise(p: vec3<f32>, seed: u32) -> f32 {
    let cell = floor(p);
    let c = vec3<i32>(cell);
    let w = quintic(p - cell);
    let x0 = mix(lattice_value(c, seed), lattice_value(c + vec3(1, 0, 0), seed), w.x);
    let x1 = mix(lattice_value(c + vec3(0, 1, 0), seed), lattice_value(c + vec3(1, 1, 0), seed), w.x);
    let x2 = mix(lattice_value(c + vec3(0, 0, 1), seed), lattice_value(c + vec3(1, 0, 1), seed), w.x);
    let x3 = mix(lattice_value(c + vec3(0, 1, 1), seed), lattice_value(c + vec3(1, 1, 1), seed), w.x);
    return mix(mix(x0, x1, w.y), mix(x2, x3, w.y), w.z);
}

// The basis N selected at run time.
fn basis_noise(basis: u32, seed: u32, p: vec3<f32>) -> f32 {
    if basis == BASIS_VALUE {
        return value_noise(p, seed);
    }
    return perlin(p);
}
