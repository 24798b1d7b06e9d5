//! The integer side of the noise bases (SPEC 3.1): Perlin's permutation,
//! seeded shuffles, the pcg3d hash and the basis names. The float side
//! (perlin, value, fBm, ridged) is in `src/cpu/noise.rs` (shared math), built once per
//! precision; its f64 build is re-exported here.

use rand::seq::SliceRandom;

pub use crate::cpu64::noise::*;
use crate::{Kernel, ParamSet, UniformLayout, Value};

/// The read-only table lib/noise.wgsl reads: Perlin's permutation for the
/// kernel's `seed` param (seed 0 without one), its chain values packed
/// ([`chain_words`]), then the plane flag and z and, on a hash plane, its
/// corner hashes ([`plane_hashes`]).
pub fn table(kernel: &Kernel, layout: &UniformLayout, p: &ParamSet) -> Vec<u32> {
    if !layout.uses_table {
        return vec![0; 4];
    }
    let seed = match p.value("seed") {
        Some(Value::Int(s)) => *s as u32,
        _ => 0,
    };
    let perm = permutation(seed);
    // The chain words are built where they end up: appended, they were
    // copied once more (256 KiB per case).
    let mut table = Vec::with_capacity(perm.len() + 512 + 256 * 256 + 2 + 256 * 256);
    table.extend_from_slice(&perm);
    chain_words_into(&perm, &mut table);
    match kernel.hash_plane(p) {
        Some(z) => plane_hashes_into(&perm, &mut table, perm.len() + 512, z),
        None => table.extend([0, 0]),
    }
    table
}

/// Ken Perlin's reference permutation (Improved Noise, 2002).
pub const PERLIN_PERMUTATION: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99, 37, 240,
    21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88,
    237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83,
    111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216,
    80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173, 186,
    3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17,
    182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129,
    22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238,
    210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184,
    84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195,
    78, 66, 215, 61, 156, 180,
];

/// PCG32 stream selector used for seeded permutations (pcg_basic's default).
const PCG_STREAM: u64 = 0xda3e_39cb_94b9_5bdb;

/// The 512-entry permutation table for `seed`: Perlin's own for seed 0,
/// otherwise a Fisher-Yates shuffle of 0..255 driven by PCG32(seed),
/// duplicated so `p[i + 1]` never needs a wrap.
pub fn permutation(seed: u32) -> Vec<u32> {
    let mut base: Vec<u32> = if seed == 0 {
        PERLIN_PERMUTATION.iter().map(|&v| v as u32).collect()
    } else {
        let mut rng = rand_pcg::Pcg32::new(seed as u64, PCG_STREAM);
        let mut p: Vec<u32> = (0..256).collect();
        p.shuffle(&mut rng);
        p
    };
    base.extend_from_within(..);
    base
}

/// The packed chain values the WGSL Perlin reads after the 512-entry
/// permutation `perm` (lib/noise.wgsl): 512 pair words, perm[k] | perm[k + 1]
/// << 8 (k = 511 wraps to perm[0]), then 256 x 256 cell words at 256 x + y,
/// perm[a] | perm[a + 1] << 8 | perm[b] << 16 | perm[b + 1] << 24 with a =
/// perm[x] + y, b = perm[x + 1] + y. Every entry is below 256, so four fit.
pub fn chain_words(perm: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(512 + 256 * 256);
    chain_words_into(perm, &mut out);
    out
}

/// [`chain_words`] appended to `out`.
pub fn chain_words_into(perm: &[u32], out: &mut Vec<u32>) {
    // A fixed-size copy indexed modulo its length: no bounds checks in the
    // 65536-cell loop (every small case builds this table).
    let mut q = [0u32; 512];
    for (k, v) in q.iter_mut().enumerate() {
        *v = perm[k % perm.len()];
    }
    let p = |k: usize| q[k & 511];
    // The pair words first; a cell word is two of them: pair[a] | pair[b] << 16.
    let mut pair = [0u32; 512];
    for (k, v) in pair.iter_mut().enumerate() {
        *v = p(k) | p(k + 1) << 8;
    }
    out.reserve(512 + 256 * 256);
    out.extend_from_slice(&pair);
    for x in 0..256 {
        let (a0, b0) = (p(x) as usize, p(x + 1) as usize);
        out.extend((0..256).map(|y| pair[(a0 + y) & 511] | pair[(b0 + y) & 511] << 16));
    }
}

/// The flag, plane and corner hashes the WGSL Perlin reads after the
/// permutation and its chain words for the integer plane z: [1, z & 255, then
/// at 256 x + y the corner hashes h(x, y), h(x + 1, y), h(x, y + 1), h(x + 1,
/// y + 1) of that cell in bytes 0 to 3, for x, y in 0..256], where h(x, y) =
/// perm[perm[perm[x] + y] + z] and x + 1, y + 1 wrap to 0..255 (as the doubled
/// table does). They are the last step of the chain from the cell words of
/// [`chain_words`] (`cells`, after its 512 pair words): a cell's four hashes
/// are perm[c + z] of its bytes perm[a], perm[b], perm[a + 1], perm[b + 1].
pub fn plane_hashes(perm: &[u32], cells: &[u32], z: i64) -> Vec<u32> {
    let mut out = cells.to_vec();
    plane_hashes_into(perm, &mut out, 0, z);
    out.drain(..cells.len());
    out
}

/// [`plane_hashes`] of the cell words `table[cells_at..cells_at + 65536]`,
/// appended to `table` (a case's table grows in place: no 256 KiB copy).
pub fn plane_hashes_into(perm: &[u32], table: &mut Vec<u32>, cells_at: usize, z: i64) {
    let z = (z & 255) as usize;
    let h = |word: u32, byte: u32| perm[(word >> (8 * byte) & 255) as usize + z];
    let cells = table.len() - cells_at;
    table.reserve(2 + cells);
    table.extend([1, z as u32]);
    for i in cells_at..cells_at + cells {
        let w = table[i];
        table.push(h(w, 0) | h(w, 2) << 8 | h(w, 1) << 16 | h(w, 3) << 24);
    }
}

/// pcg3d (Jarzynski & Olano 2020): a 3D -> 3D integer hash, wrapping u32 math.
pub fn pcg3d(v: [u32; 3]) -> [u32; 3] {
    let mut v = v.map(|c| c.wrapping_mul(1_664_525).wrapping_add(1_013_904_223));
    v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[2]));
    v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
    v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    v = v.map(|c| c ^ (c >> 16));
    v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[2]));
    v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
    v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    v
}

/// Seed mixing for value noise: the seed is folded into z by a Weyl step so
/// that seeds give unrelated lattices while seed 0 is the plain hash.
pub fn value_seed_offset(seed: u32) -> u32 {
    seed.wrapping_mul(0x9E37_79B9)
}

/// Hash of one lattice point, as u32 (component x of pcg3d).
pub fn lattice_hash(seed: u32, i: i32, j: i32, k: i32) -> u32 {
    pcg3d([i as u32, j as u32, (k as u32).wrapping_add(value_seed_offset(seed))])[0]
}

/// The noise basis N of SPEC 3.1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// Ken Perlin's improved gradient noise over a seeded permutation.
    Perlin,
    /// Quintic-faded trilinear interpolation of pcg3d-hashed lattice values in [-1, 1).
    Value,
}

/// The basis names, as the kernels' `basis` enum params spell them.
pub const BASIS_NAMES: &[&str] = &["perlin", "value"];

/// Each basis name's meaning (for [`crate::ParamSet::choice_in`]).
pub const BASES: &[(&str, Basis)] = &[("perlin", Basis::Perlin), ("value", Basis::Value)];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    // 3.14 is SPEC 3.1's reference input, not an approximation of pi.
    #[allow(clippy::approx_constant)]
    fn perlin_reference_value() {
        // SPEC 3.1: the value printed by Perlin's Java reference implementation.
        let p = permutation(0);
        let v = perlin(&p, 3.14, 42.0, 7.0);
        assert!((v - 0.136_919_958_784_000_12).abs() < 1e-15, "perlin(3.14, 42, 7) = {v}");
    }

    #[test]
    fn chain_words_hold_the_chain_values_of_their_cell() {
        for seed in [0, 7] {
            let perm = permutation(seed);
            let words = chain_words(&perm);
            assert_eq!(words.len(), 512 + 65536);
            let bytes = |w: u32| [w & 255, w >> 8 & 255, w >> 16 & 255, w >> 24];
            for k in [0, 200, 510] {
                assert_eq!(bytes(words[k])[..2], [perm[k], perm[k + 1]], "seed {seed} pair {k}");
            }
            for (x, y) in [(0, 0), (17, 200), (255, 3), (9, 255), (255, 255)] {
                let a = perm[x] as usize + y;
                let b = perm[x + 1] as usize + y;
                let want = [perm[a], perm[a + 1], perm[b], perm[b + 1]];
                assert_eq!(bytes(words[512 + 256 * x + y]), want, "seed {seed} cell ({x}, {y})");
            }
        }
    }

    #[test]
    fn plane_words_hold_the_four_corner_hashes_of_their_cell() {
        for (seed, z) in [(0, 0), (7, 255), (12, -3)] {
            let perm = permutation(seed);
            let plane = plane_hashes(&perm, &chain_words(&perm)[512..], z);
            let zw = (z & 255) as usize;
            assert_eq!(plane[..2], [1, zw as u32]);
            let chain = |x: usize, y: usize| perm[perm[perm[x % 256] as usize + y % 256] as usize + zw];
            // Interior cells and the wrapping edges x = 255, y = 255.
            for (x, y) in [(0, 0), (17, 200), (255, 3), (9, 255), (255, 255)] {
                let word = plane[2 + 256 * x + y];
                let bytes = [word & 255, word >> 8 & 255, word >> 16 & 255, word >> 24];
                let want = [chain(x, y), chain(x + 1, y), chain(x, y + 1), chain(x + 1, y + 1)];
                assert_eq!(bytes, want, "seed {seed} z {z} cell ({x}, {y})");
            }
        }
    }

    #[test]
    fn perlin_is_zero_on_the_lattice() {
        for seed in [0, 1, 99] {
            let n = Noise::new(Basis::Perlin, seed);
            for (x, y, z) in [(0, 0, 0), (3, -7, 11), (255, 256, -1000)] {
                assert_eq!(n.eval(x as f64, y as f64, z as f64), 0.0);
            }
        }
    }

    #[test]
    fn seeded_permutation_is_a_permutation_and_differs() {
        for seed in [1, 2, 12345] {
            let p = permutation(seed);
            let mut sorted = p[..256].to_vec();
            sorted.sort();
            assert_eq!(sorted, (0..256).collect::<Vec<_>>());
            assert_eq!(p[..256], p[256..]);
            assert_ne!(p, permutation(0));
        }
        assert_ne!(permutation(1), permutation(2));
    }

    #[test]
    fn value_noise_equals_remapped_hash_on_lattice() {
        for (i, j, k) in [(0, 0, 0), (5, -3, 2), (-100, 77, 9)] {
            let want = ((lattice_hash(7, i, j, k) >> 8) as f64) / 16_777_216.0 * 2.0 - 1.0;
            assert_eq!(value(7, i as f64, j as f64, k as f64), want);
        }
    }

    #[test]
    fn pcg3d_known_vector() {
        // pcg3d(0,0,0): every lane starts at 1013904223; computed by hand-run
        // of the published recurrence in wrapping u32 arithmetic.
        let v = pcg3d([0, 0, 0]);
        let mut w = [1_013_904_223u32; 3];
        w[0] = w[0].wrapping_add(w[1].wrapping_mul(w[2]));
        w[1] = w[1].wrapping_add(w[2].wrapping_mul(w[0]));
        w[2] = w[2].wrapping_add(w[0].wrapping_mul(w[1]));
        let w = w.map(|c| c ^ (c >> 16));
        let mut x = w;
        x[0] = x[0].wrapping_add(x[1].wrapping_mul(x[2]));
        x[1] = x[1].wrapping_add(x[2].wrapping_mul(x[0]));
        x[2] = x[2].wrapping_add(x[0].wrapping_mul(x[1]));
        assert_eq!(v, x);
        assert_ne!(v, [0, 0, 0]);
    }
}
