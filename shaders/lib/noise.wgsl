// Noise bases (SPEC 3.1): Perlin's Improved Noise and pcg3d value noise.
#define_import_path vista::noise

#import vista::hash::{pcg3d, unit_from_hash}

// 512-entry permutation (Perlin's table for seed 0, a PCG32 shuffle otherwise),
// built on the CPU so the WGSL and the reference share one definition of it.
// After it the host puts the same chain's values packed for fewer loads (each
// hash is a permutation entry, below 256, so four fit in a word), all with
// wraps as the doubled table wraps:
// - at PERLIN_PAIRS + k, k < 511: perm[k] | perm[k + 1] << 8, a corner's hash
//   and the one above it (z + 1);
// - at PERLIN_CELLS + 256 x + y: perm[a], perm[a + 1], perm[b], perm[b + 1] in
//   bytes 0 to 3, with a = perm[x] + y, b = perm[x + 1] + y (the chain's
//   second level for cell (x, y));
// - perm[PLANE_FLAG] = 1 and perm[PLANE_Z] = z & 255 and, for a kernel that
//   samples one integer plane z (its manifest's hash_plane), at PLANE_HASHES
//   + 256 x + y the hashes perm[perm[perm[x] + y] + z] of the cell's corners
//   (x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1) in bytes 0 to 3.
// So a 3D cell takes 5 loads instead of the chain's 14, and a cell on the
// plane 1, with the same values (tests/noise.rs checks the bits).
@group(0) @binding(2) var<storage, read> perm: array<u32>;
const PERLIN_PAIRS: u32 = 512u;
const PERLIN_CELLS: u32 = 1024u;
const PLANE_FLAG: u32 = 66560u;
const PLANE_Z: u32 = 66561u;
const PLANE_HASHES: u32 = 66562u;

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

// The cell of p: its lattice corner wrapped to 0..255, the offset inside
// it and the quintic weights of that offset.
struct PerlinCell {
    i: vec3<u32>,
    f: vec3<f32>,
    w: vec3<f32>,
}

fn perlin_cell(p: vec3<f32>) -> PerlinCell {
    let cell = floor(p);
    let f = p - cell;
    return PerlinCell(vec3<u32>(vec3<i32>(cell) & vec3<i32>(255)), f, quintic(f));
}

// One z face of a cell: the gradients of its corners (hashes h00, h10, h01,
// h11 at x, y offsets 0/1 from f) blended by w.x, then w.y.
fn perlin_face(h00: u32, h10: u32, h01: u32, h11: u32, f: vec3<f32>, w: vec3<f32>) -> f32 {
    let x0 = mix(perlin_grad(h00, f), perlin_grad(h10, f - vec3(1.0, 0.0, 0.0)), w.x);
    let x1 = mix(perlin_grad(h01, f - vec3(0.0, 1.0, 0.0)), perlin_grad(h11, f - vec3(1.0, 1.0, 0.0)), w.x);
    return mix(x0, x1, w.y);
}

// perlin(p) for p.z on the table's hash plane: the lower face only (w.z = 0
// there), its four corner hashes one load; the same face as perlin's, so the
// same bits. On the plane perlin_cell's z offset p.z - floor(p.z) is +0
// exactly, so the cell is found in 2D with f.z = 0 (w.z is not read by the
// face). perlin_grad reads the low 4 bits of each shifted byte.
fn perlin_on_plane(p: vec3<f32>) -> f32 {
    let cell = floor(p.xy);
    let f = vec3(p.xy - cell, 0.0);
    let i = vec2<u32>(vec2<i32>(cell) & vec2<i32>(255));
    let q = perm[PLANE_HASHES + (i.x << 8u) + i.y];
    return perlin_face(q, q >> 8u, q >> 16u, q >> 24u, f, quintic(f));
}

// The hashes of cell i's lower corners (x, y), (x + 1, y), (x, y + 1),
// (x + 1, y + 1) at z in byte 0 of each component and of the corners above
// them (z + 1) in byte 1.
fn perlin_hashes(i: vec3<u32>) -> vec4<u32> {
#ifdef VISTA_PERLIN_CHAIN
    // Perlin's own chain through the doubled table, three loads per corner:
    // the reference the packed tables are checked against (tests/noise.rs).
    let a = perm[i.x] + i.y;
    let b = perm[i.x + 1u] + i.y;
    let k = vec4(perm[a], perm[b], perm[a + 1u], perm[b + 1u]) + i.z;
    return vec4(perm[k.x] | perm[k.x + 1u] << 8u, perm[k.y] | perm[k.y + 1u] << 8u,
                perm[k.z] | perm[k.z + 1u] << 8u, perm[k.w] | perm[k.w + 1u] << 8u);
#else
    let q = perm[PERLIN_CELLS + (i.x << 8u) + i.y];
    let k = (vec4(q, q >> 16u, q >> 8u, q >> 24u) & vec4(255u)) + i.z;
    return vec4(perm[PERLIN_PAIRS + k.x], perm[PERLIN_PAIRS + k.y], perm[PERLIN_PAIRS + k.z], perm[PERLIN_PAIRS + k.w]);
#endif
}

fn perlin(p: vec3<f32>) -> f32 {
    let c = perlin_cell(p);
    let h = perlin_hashes(c.i);
    let lower = perlin_face(h.x, h.y, h.z, h.w, c.f, c.w);
    // On an integer z plane (the 2D kernels' z_slice 0: fbm, ridged, the
    // terrains) w.z = 0, so the upper face weighs exactly 0 and
    // mix(lower, upper, 0) = lower: its four corners are skipped, with the
    // same result (tests/noise.rs checks the bits against the full formula).
    let f = c.f;
    if f.z == 0.0 {
        return lower;
    }
    // f - (0, 0, 1) - (1, 0, 0) is f - (1, 0, 1) exactly: the same offsets.
    let upper = perlin_face(h.x >> 8u, h.y >> 8u, h.z >> 8u, h.w >> 8u, f - vec3(0.0, 0.0, 1.0), c.w);
    return mix(lower, upper, c.w.z);
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

// The basis N of fbm2 and ridged2, and how it is chosen. Composed rather
// than branched on where the kernel allows it: llvmpipe runs both sides of a
// branch its lanes could disagree on, masked, so run-time tests keep their
// full cost there (measured in the README).
// - BASIS_IS_PERLIN / BASIS_IS_VALUE: the kernel's manifest lists `basis` under
//   `specialize`, so its value is a shader def and the other basis is not
//   compiled in; without either def, the run-time branch on `basis`.
// - VISTA_HASH_PLANE: the manifest names a hash_plane param and its value is
//   an integer, so the table carries that plane's corner hashes and Perlin
//   reads one word per cell.
// Either way the same functions compute the same values (tests/noise.rs
// checks the bits of every combination against the run-time branch).
fn slice_noise(basis: u32, seed: u32, p: vec3<f32>) -> f32 {
#ifdef BASIS_IS_VALUE
    return value_noise(p, seed);
#else ifdef BASIS_IS_PERLIN
    return slice_perlin(p);
#else
    if basis == BASIS_VALUE {
        return value_noise(p, seed);
    }
    return slice_perlin(p);
#endif
}

fn slice_perlin(p: vec3<f32>) -> f32 {
#ifdef VISTA_HASH_PLANE
    return perlin_on_plane(p);
#else
    return perlin(p);
#endif
}

fn basis_noise(basis: u32, seed: u32, p: vec3<f32>) -> f32 {
    if basis == BASIS_VALUE {
        return value_noise(p, seed);
    }
    return perlin(p);
}
