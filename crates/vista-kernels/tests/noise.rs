//! CPU invariants of the noise bases, fBm and ridged (SPEC 3.1-3.3, 8, 9).
//! Every sampled test uses fixed-seed generators, so results are repeatable.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use vista_kernels::noise::{
    Basis, Fbm, Noise, PERLIN_MAX_ABS, PERLIN_PERMUTATION, Ridged, lattice_hash, lattice_value, pcg3d, perlin,
    permutation, value,
};
use vista_kernels::ridged::ridged_max;
use vista_kernels::{Kernel, ParamError, ParamSet, find};

const SEEDS: [u32; 5] = [0, 1, 7, 12345, u32::MAX];
const BASES: [Basis; 2] = [Basis::Perlin, Basis::Value];
/// Largest |d fade / dt| = 30 t^2 (1 - t)^2 at t = 1/2.
const FADE_SLOPE: f64 = 1.875;

fn rng(tag: u64) -> Pcg64 {
    Pcg64::seed_from_u64(0x5eed_0000 + tag)
}

/// `n` points uniform in [lo, hi)^2 (2D sample positions).
fn points2(tag: u64, n: usize, lo: f64, hi: f64) -> Vec<[f64; 2]> {
    let mut r = rng(tag);
    (0..n).map(|_| [r.random_range(lo..hi), r.random_range(lo..hi)]).collect()
}

fn points3(tag: u64, n: usize, lo: f64, hi: f64) -> Vec<[f64; 3]> {
    let mut r = rng(tag);
    (0..n).map(|_| [r.random_range(lo..hi), r.random_range(lo..hi), r.random_range(lo..hi)]).collect()
}

fn with(kernel: &Kernel, set: &[(&str, &str)]) -> Result<ParamSet, ParamError> {
    let overrides: Vec<(String, String)> = set.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    kernel.resolve(None, &overrides)
}

// ---------------------------------------------------------------- perlin

#[test]
// 3.14 is SPEC 3.1's reference input, not an approximation of pi.
#[allow(clippy::approx_constant)]
fn perlin_reference_value() {
    let v = perlin(&permutation(0), 3.14, 42.0, 7.0);
    assert!((v - 0.136_919_958_784_000_12).abs() < 1e-15, "perlin(3.14, 42, 7) = {v}");
}

#[test]
fn perlin_hand_computed_cell_centre() {
    // Seed 0, cell (0,0,0): corner hashes p[p[p[x]+y]+z] & 15 are 4 (000),
    // 6 (100), 12 (010), 0 (110), gradients (1,0,1), (1,0,-1), (1,1,0),
    // (1,1,0). At (0.5, 0.5, 0) the offsets are (+-0.5, +-0.5, 0) and the dots
    // 0.5, -0.5, 0, -1; fade(0.5) = 0.5 so the result is their mean, -0.25.
    assert_eq!(perlin(&permutation(0), 0.5, 0.5, 0.0), -0.25);
}

/// Perlin's 16 gradients as vectors (Improved Noise, 2002): the 12 cube edges
/// plus (1,1,0), (0,-1,1), (-1,1,0), (0,-1,-1) padding to 16.
const GRADIENTS: [[f64; 3]; 16] = [
    [1., 1., 0.],
    [-1., 1., 0.],
    [1., -1., 0.],
    [-1., -1., 0.],
    [1., 0., 1.],
    [-1., 0., 1.],
    [1., 0., -1.],
    [-1., 0., -1.],
    [0., 1., 1.],
    [0., -1., 1.],
    [0., 1., -1.],
    [0., -1., -1.],
    [1., 1., 0.],
    [0., -1., 1.],
    [-1., 1., 0.],
    [0., -1., -1.],
];

fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Independent formulation: sum over the 8 corners of weight * (g . d), with
/// the corner hash p[p[p[X] + Y] + Z].
fn perlin_by_corners(p: &[u32], x: f64, y: f64, z: f64) -> f64 {
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    let (tx, ty, tz) = (x - fx, y - fy, z - fz);
    let mut sum = 0.0;
    for c in 0..8 {
        let (cx, cy, cz) = ((c & 1) as i64, ((c >> 1) & 1) as i64, ((c >> 2) & 1) as i64);
        let xi = ((fx as i64 + cx) & 255) as usize;
        let yi = ((fy as i64 + cy) & 255) as usize;
        let zi = ((fz as i64 + cz) & 255) as usize;
        let g = GRADIENTS[(p[p[p[xi] as usize + yi] as usize + zi] & 15) as usize];
        let d = [tx - cx as f64, ty - cy as f64, tz - cz as f64];
        let w = |t: f64, on: i64| if on == 1 { fade(t) } else { 1.0 - fade(t) };
        sum += w(tx, cx) * w(ty, cy) * w(tz, cz) * (g[0] * d[0] + g[1] * d[1] + g[2] * d[2]);
    }
    sum
}

#[test]
fn perlin_matches_corner_sum_formulation() {
    for seed in SEEDS {
        let p = permutation(seed);
        for [x, y, z] in points3(seed as u64, 2000, -300.0, 300.0) {
            let (a, b) = (perlin(&p, x, y, z), perlin_by_corners(&p, x, y, z));
            assert!((a - b).abs() < 1e-14, "seed {seed} at ({x}, {y}, {z}): {a} vs {b}");
        }
    }
}

#[test]
fn perlin_is_zero_on_the_lattice() {
    let mut r = rng(1);
    for seed in SEEDS {
        let n = Noise::new(Basis::Perlin, seed);
        for _ in 0..2000 {
            let [x, y, z] = [0; 3].map(|_| r.random_range(-100_000i64..100_000) as f64);
            assert_eq!(n.eval(x, y, z), 0.0, "seed {seed} at ({x}, {y}, {z})");
        }
    }
}

#[test]
fn perlin_changes_with_seed_off_the_lattice() {
    let pts = points3(2, 1000, -50.0, 50.0);
    for (s0, s1) in [(0, 1), (1, 2), (7, 12345), (0, u32::MAX)] {
        let (a, b) = (Noise::new(Basis::Perlin, s0), Noise::new(Basis::Perlin, s1));
        let diffs: Vec<f64> = pts.iter().map(|&[x, y, z]| (a.eval(x, y, z) - b.eval(x, y, z)).abs()).collect();
        let differing = diffs.iter().filter(|&&d| d > 1e-9).count() as f64 / diffs.len() as f64;
        let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
        assert!(differing > 0.95, "seeds {s0}/{s1}: only {differing} of points differ");
        assert!(mean > 0.1, "seeds {s0}/{s1}: mean |difference| {mean}");
    }
}

#[test]
fn perlin_has_period_256() {
    // Dyadic fractions keep x - floor(x) exact after the shift.
    for seed in [0, 7] {
        let n = Noise::new(Basis::Perlin, seed);
        for (x, y, z) in [(0.25, 0.75, 0.5), (3.125, -7.5, 11.375), (-100.0625, 42.5, 0.0)] {
            let v = n.eval(x, y, z);
            assert_ne!(v, 0.0);
            assert_eq!(n.eval(x + 256.0, y, z), v);
            assert_eq!(n.eval(x, y - 512.0, z), v);
            assert_eq!(n.eval(x, y, z + 256.0), v);
        }
    }
}

#[test]
fn perlin_magnitude_bound() {
    // On an integer-z slice |N| <= 1; in 3D it reaches ~1.036, which
    // Noise::max_abs must cover.
    for seed in SEEDS {
        let n = Noise::new(Basis::Perlin, seed);
        let m = points2(seed as u64 + 10, 20_000, -200.0, 200.0)
            .iter()
            .map(|&[x, y]| n.eval(x, y, 0.0).abs())
            .fold(0.0, f64::max);
        assert!(m <= 1.0 && m > 0.7, "seed {seed}: max |N| on z = 0 is {m}");
    }
    let n = Noise::new(Basis::Perlin, 0);
    let peak = n.eval(223.35, 61.525, 233.5);
    assert!(peak > 1.036, "seed 0 peak {peak}");
    // Climb to the local maximum of that cell: still below the bound.
    let (mut q, mut best, mut step) = ([223.35, 61.525, 233.5], peak, 0.01);
    while step > 1e-7 {
        let mut moved = false;
        for axis in 0..3 {
            for sign in [-1.0, 1.0] {
                let mut t = q;
                t[axis] += sign * step;
                let v = n.eval(t[0], t[1], t[2]);
                if v > best {
                    (q, best, moved) = (t, v, true);
                }
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    eprintln!("perlin seed 0 local peak {best:.6} at {q:?}; PERLIN_MAX_ABS = {PERLIN_MAX_ABS}");
    assert!(best > 1.0363 && best <= PERLIN_MAX_ABS, "peak {best}");
    assert_eq!(n.max_abs(), PERLIN_MAX_ABS);
}

// ---------------------------------------------------------------- value

#[test]
fn value_noise_equals_remapped_hash_on_lattice() {
    let mut r = rng(3);
    for seed in SEEDS {
        let n = Noise::new(Basis::Value, seed);
        for _ in 0..2000 {
            let [i, j, k] = [0; 3].map(|_| r.random_range(-100_000i32..100_000));
            let h = lattice_hash(seed, i, j, k);
            let want = (h >> 8) as f64 * 2f64.powi(-24) * 2.0 - 1.0;
            let (x, y, z) = (i as f64, j as f64, k as f64);
            assert_eq!(value(seed, x, y, z), want, "seed {seed} at ({i}, {j}, {k})");
            assert_eq!(n.eval(x, y, z), want);
            assert_eq!(lattice_value(seed, i, j, k), want);
        }
    }
}

#[test]
fn value_noise_lies_in_minus_one_one() {
    for seed in SEEDS {
        let n = Noise::new(Basis::Value, seed);
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for [x, y, z] in points3(seed as u64 + 20, 20_000, -1000.0, 1000.0) {
            let v = n.eval(x, y, z);
            assert!((-1.0..1.0).contains(&v), "seed {seed}: value({x}, {y}, {z}) = {v}");
            (lo, hi) = (lo.min(v), hi.max(v));
        }
        // The range is really used (a [0, 1) or halved mapping would fail).
        assert!(lo < -0.8 && hi > 0.8, "seed {seed}: range [{lo}, {hi}]");
    }
}

// ---------------------------------------------------------------- pcg3d

#[test]
fn pcg3d_known_vectors() {
    // From the published recurrence (Jarzynski & Olano 2020, pcg3d) run in
    // Python with & 0xffffffff after every step:
    //   v = [(c*1664525 + 1013904223) & M for c in v]
    //   v0 += v1*v2; v1 += v2*v0; v2 += v0*v1; v = [c ^ (c >> 16) ...]
    //   v0 += v1*v2; v1 += v2*v0; v2 += v0*v1
    assert_eq!(pcg3d([0, 0, 0]), [0x9baf_d7c6, 0xa8e8_8a6b, 0x3f15_482c]);
    assert_eq!(pcg3d([1, 2, 3]), [0xfa9f_79a6, 0x48f2_f44c, 0x596f_5ab1]);
    assert_eq!(pcg3d([0xffff_ffff, 12345, 0x8000_0000]), [0x8f4b_6039, 0x2641_1dd5, 0xcf68_f4ee]);
    // Seed 0 is the plain hash of the lattice coordinates.
    assert_eq!(lattice_hash(0, 1, 2, 3), 0xfa9f_79a6);
}

const GRID: i32 = 1024;

fn grid_hashes(seed: u32) -> Vec<u32> {
    (0..GRID * GRID).map(|c| lattice_hash(seed, c % GRID, c / GRID, 0)).collect()
}

fn chi_square(values: impl Iterator<Item = u32>) -> f64 {
    let mut bins = [0u64; 256];
    let mut n = 0u64;
    for v in values {
        bins[v as usize] += 1;
        n += 1;
    }
    let expected = n as f64 / 256.0;
    bins.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum()
}

#[test]
fn lattice_hash_chi_square() {
    // df = 255: P(chi2 > 330.5) = 0.001, P(chi2 < 180) < 1e-4. Too small a
    // statistic means suspiciously even bins (e.g. a counter, not a hash).
    for seed in [0, 1, 12345] {
        let h = grid_hashes(seed);
        let top = chi_square(h.iter().map(|&v| v >> 24));
        // Bits 8..15: the lowest bits the lattice value (h >> 8) uses.
        let low = chi_square(h.iter().map(|&v| (v >> 8) & 255));
        eprintln!("seed {seed}: chi-square top byte {top:.1}, bits 8..15 {low:.1} (df 255)");
        for chi in [top, low] {
            assert!(chi > 180.0 && chi < 330.5, "seed {seed}: chi-square {chi}");
        }
    }
}

/// pcg (Jarzynski & Olano 2020): the 1D, 32-bit-state hash, a bijection.
fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

fn distinct_fraction(mut v: Vec<u32>) -> f64 {
    let n = v.len() as f64;
    v.sort_unstable();
    v.dedup();
    v.len() as f64 / n
}

#[test]
fn pcg3d_cells_are_distinct_where_xor_combining_collides() {
    // SPEC 8 pitfall: x * 127 ^ y * 311 (the constants of the classic
    // dot(p, vec2(127.1, 311.7)) hash) folds 2D cells into one u32 before
    // a 1D hash, and collisions made there cannot be undone.
    let full = distinct_fraction(grid_hashes(0));
    let keys: Vec<u32> = (0..GRID * GRID)
        .map(|c| ((c % GRID) as u32).wrapping_mul(127) ^ ((c / GRID) as u32).wrapping_mul(311))
        .collect();
    let naive = distinct_fraction(keys.iter().map(|&k| pcg(k)).collect());
    eprintln!("distinct cell hashes on 1024 x 1024: pcg3d {full:.6}, pcg(x*127 ^ y*311) {naive:.6}");
    // Birthday bound for 2^20 draws of 32 bits: ~128 colliding pairs.
    assert!(full >= 0.999, "pcg3d distinct fraction {full}");
    assert!(naive < 0.4, "naive distinct fraction {naive}");
    // pcg is a bijection: every collision comes from the XOR combining.
    assert_eq!(naive, distinct_fraction(keys));
}

#[test]
fn pcg3d_avalanche() {
    // Component x (the lattice hash). Bits 0..15 of each input coordinate,
    // where lattice coordinates live, flip ~16 of 32 output bits. The
    // published pcg3d is weaker for input bits 16..31: multiply-add only
    // carries a change upward and the single v ^= v >> 16 moves it down by
    // 16 only, so bit 31 flips ~7-8 bits and the 96-bit mean is ~14.1.
    let mut r = rng(4);
    let inputs = 2000;
    let mut per_bit = [0u64; 96];
    for _ in 0..inputs {
        let v: [u32; 3] = [r.random(), r.random(), r.random()];
        let h = pcg3d(v)[0];
        for (bit, count) in per_bit.iter_mut().enumerate() {
            let mut w = v;
            w[bit / 32] ^= 1 << (bit % 32);
            *count += (pcg3d(w)[0] ^ h).count_ones() as u64;
        }
    }
    let per: Vec<f64> = per_bit.iter().map(|&c| c as f64 / inputs as f64).collect();
    let low: Vec<f64> = per.iter().enumerate().filter(|(b, _)| b % 32 < 16).map(|(_, &m)| m).collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (all, low_mean) = (mean(&per), mean(&low));
    let low_min = low.iter().cloned().fold(f64::MAX, f64::min);
    let all_min = per.iter().cloned().fold(f64::MAX, f64::min);
    eprintln!(
        "pcg3d avalanche (component x): input bits 0..15 mean {low_mean:.3} (min {low_min:.2}); \
         all 96 bits mean {all:.3} (min {all_min:.2})"
    );
    assert!((15.0..=17.0).contains(&low_mean), "low-bit avalanche mean {low_mean}");
    assert!(low_min > 15.0, "a low input bit flips only {low_min} output bits");
    // Pin the documented weakness so a change of hash shows up here.
    assert!((13.5..=15.0).contains(&all), "96-bit avalanche mean {all}");
    assert!(all_min > 6.0, "an input bit flips only {all_min} output bits");
}

// ---------------------------------------------------------------- fBm

fn fbm(octaves: u32, lacunarity: f64, gain: f64) -> Fbm {
    Fbm { octaves, lacunarity, gain, theta: 0.0 }
}

/// (octaves, lacunarity, gain) combinations exercised below.
const FBM_CASES: [(u32, f64, f64); 4] = [(8, 2.0, 0.5), (5, 2.7, 0.8), (12, 1.5, 0.65), (3, 4.0, 1.0)];

#[test]
fn fbm_amplitude_bound() {
    for basis in BASES {
        for seed in SEEDS {
            let n = Noise::new(basis, seed);
            for (oct, lac, gain) in FBM_CASES {
                for theta in [0.0, 0.6435] {
                    let f = Fbm { theta, ..fbm(oct, lac, gain) };
                    let bound = n.max_abs() * f.amplitude_sum();
                    for (i, [x, y]) in points2(seed as u64 + 30, 300, -64.0, 64.0).into_iter().enumerate() {
                        let z = if i % 2 == 0 { 0.0 } else { 0.37 };
                        let v = f.eval(&n, [x, y], z);
                        assert!(v.abs() <= bound, "{basis:?} seed {seed} {f:?}: |f({x}, {y}, {z})| = {v} > {bound}");
                    }
                }
            }
        }
    }
}

#[test]
fn fbm_self_similarity() {
    // f_{n+1}(p) = N(p) + gain * f_n(lacunarity * p) without rotation: the
    // sample positions are identical, only the summation order differs.
    for basis in BASES {
        for seed in SEEDS {
            let n = Noise::new(basis, seed);
            for (oct, lac, gain) in FBM_CASES {
                let (big, small) = (fbm(oct + 1, lac, gain), fbm(oct, lac, gain));
                for [x, y] in points2(seed as u64 + 40, 200, -30.0, 30.0) {
                    let z = 0.25;
                    let lhs = big.eval(&n, [x, y], z);
                    let rhs = n.eval(x, y, z) + gain * small.eval(&n, [lac * x, lac * y], z);
                    assert!((lhs - rhs).abs() < 1e-12, "{basis:?} seed {seed} {big:?} at ({x}, {y}): {lhs} vs {rhs}");
                }
            }
        }
    }
}

#[test]
fn fbm_octave_increment_bound() {
    for basis in BASES {
        for seed in [0, 7] {
            let noise = Noise::new(basis, seed);
            for (_, lac, gain) in FBM_CASES {
                for [x, y] in points2(seed as u64 + 50, 100, -20.0, 20.0) {
                    let mut prev = 0.0;
                    for n in 0..10 {
                        let cur = fbm(n + 1, lac, gain).eval(&noise, [x, y], 0.5);
                        let step = (cur - prev).abs();
                        let bound = gain.powi(n as i32) * noise.max_abs();
                        assert!(step <= bound + 1e-12, "{basis:?} octave {n}: change {step} > {bound}");
                        prev = cur;
                    }
                }
            }
        }
    }
}

#[test]
fn fbm_one_octave_is_the_basis() {
    for basis in BASES {
        for seed in SEEDS {
            let n = Noise::new(basis, seed);
            for theta in [0.0, 1.0] {
                let f = Fbm { octaves: 1, lacunarity: 2.3, gain: 0.7, theta };
                for [x, y, z] in points3(seed as u64 + 60, 300, -100.0, 100.0) {
                    assert_eq!(f.eval(&n, [x, y], z), n.eval(x, y, z));
                    assert_eq!(f.eval3(&n, [x, y, z]), n.eval(x, y, z));
                }
            }
        }
    }
}

#[test]
fn fbm_seed_changes_the_field() {
    let f = fbm(8, 2.0, 0.5);
    let pts = points2(70, 500, -10.0, 10.0);
    for basis in BASES {
        for (s0, s1) in [(0, 1), (7, 12345), (1, u32::MAX)] {
            let (a, b) = (Noise::new(basis, s0), Noise::new(basis, s1));
            let diffs: Vec<f64> = pts.iter().map(|&p| (f.eval(&a, p, 0.0) - f.eval(&b, p, 0.0)).abs()).collect();
            let differing = diffs.iter().filter(|&&d| d > 1e-9).count();
            let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
            assert_eq!(differing, pts.len(), "{basis:?} seeds {s0}/{s1}");
            assert!(mean > 0.1, "{basis:?} seeds {s0}/{s1}: mean |difference| {mean}");
        }
    }
}

#[test]
fn fbm_mean_is_near_zero() {
    // E[N(p)] = 0 at every p: Perlin's 16 gradients sum to zero and each
    // corner's is equally likely; value-noise lattice values are uniform on
    // [-1, 1) (mean -2^-24). The 100 x 100 region covers ~10^4 independent
    // cells of octave 0 (more for higher ones), so the spatial mean has a
    // standard deviation of about 0.58 / 100 ~ 0.006 (value noise, lattice
    // std 1/sqrt(3); less for perlin): even a 3-sigma mean is below 0.02 A.
    let f = fbm(8, 2.0, 0.5);
    let a = f.amplitude_sum();
    for basis in BASES {
        for seed in [0, 1, 12345] {
            let n = Noise::new(basis, seed);
            let (mut sum, mut sum2) = (0.0, 0.0);
            let k = 200;
            for j in 0..k {
                for i in 0..k {
                    let p = [0.137 + 100.0 * i as f64 / k as f64, -49.71 + 100.0 * j as f64 / k as f64];
                    let v = f.eval(&n, p, 0.0);
                    (sum, sum2) = (sum + v, sum2 + v * v);
                }
            }
            let count = (k * k) as f64;
            let (mean, std) = (sum / count, (sum2 / count - (sum / count).powi(2)).sqrt());
            eprintln!("fbm {basis:?} seed {seed}: mean {mean:+.5} std {std:.4} (A = {a:.4})");
            assert!(mean.abs() < 0.02 * a, "{basis:?} seed {seed}: mean {mean}");
            // A flat field would pass trivially; make sure it varies.
            assert!(std > 0.1, "{basis:?} seed {seed}: std {std}");
        }
    }
}

/// Per-axis Lipschitz bound L of the basis on a slice of fixed z:
/// |N(p + h e_x) - N(p)| <= L |h| (same for e_y).
///
/// Perlin: N = sum_c W_c (g_c . d_c), W_c = X(fx) Y(fy) Z(fz) >= 0, sum W_c = 1.
/// dN/dx = sum_c W_c g_c.x + s'(fx) sum_{cy,cz} Y Z (g_1 . d_1 - g_0 . d_0),
/// pairing the corners cx = 0, 1 (d_0.x = fx, d_1.x = fx - 1, same dy, dz).
/// The first sum is at most max |g.x| = 1. In each pair the x parts give at
/// most |fx| + |fx - 1| = 1 and the y, z parts |g_1y - g_0y| |dy| + (same z)
/// <= 2 |dy| + 2 |dz|. sum_cy Y |dy| = (1 - s(t)) t + s(t) (1 - t) =: a(t);
/// s is convex on [0, 1/2] with s(1/2) = 1/2, so s(t) <= t there and
/// a(t) <= 2t - 2t^2 <= 1/2 (symmetric for t > 1/2). Hence
/// |dN/dx| <= 1 + 1.875 (1 + 2 a(fy) + 2 a(fz)) <= 1 + 1.875 * 3 = 6.625;
/// on an integer z slice only dz = 0 corners carry weight: 1 + 1.875 * 2 = 4.75.
/// Value: dN/dx = s'(fx) sum Y Z (v_1 - v_0), |v_1 - v_0| < 2: 2 * 1.875.
/// N is C^1 across cell faces, so the derivative bound is a Lipschitz bound.
fn basis_lipschitz(basis: Basis, integer_z: bool) -> f64 {
    match (basis, integer_z) {
        (Basis::Perlin, true) => 1.0 + FADE_SLOPE * 2.0,
        (Basis::Perlin, false) => 1.0 + FADE_SLOPE * 3.0,
        (Basis::Value, _) => 2.0 * FADE_SLOPE,
    }
}

#[test]
fn fbm_is_lipschitz() {
    // f = sum gain^i N(lacunarity^i p) (no rotation): per axis
    // L_f = L_N * sum_i (gain * lacunarity)^i.
    let h = 1e-3;
    for basis in BASES {
        for seed in [0, 7, 12345] {
            let n = Noise::new(basis, seed);
            for (oct, lac, gain) in [(6, 2.0, 0.5), (4, 2.5, 0.7)] {
                let f = fbm(oct, lac, gain);
                for z in [0.0, 0.37] {
                    let l_f =
                        basis_lipschitz(basis, z == 0.0) * (0..oct).map(|i| (gain * lac).powi(i as i32)).sum::<f64>();
                    let mut worst = 0.0f64;
                    for (line, [x0, y0]) in points2(seed as u64 + 80, 4, -20.0, 20.0).into_iter().enumerate() {
                        let axis = line % 2;
                        let at = |k: usize| {
                            let mut p = [x0, y0];
                            p[axis] += k as f64 * h;
                            f.eval(&n, p, z)
                        };
                        let mut prev = at(0);
                        for k in 1..2500 {
                            let cur = at(k);
                            worst = worst.max((cur - prev).abs() / (l_f * h));
                            prev = cur;
                        }
                    }
                    eprintln!("fbm {basis:?} seed {seed} {oct}/{lac}/{gain} z {z}: max |df| / (L_f h) = {worst:.3}");
                    assert!(worst <= 1.0 + 1e-9, "{basis:?} seed {seed} z {z}: ratio {worst}");
                    assert!(worst > 0.05, "{basis:?} seed {seed}: field barely moves ({worst})");
                }
            }
        }
    }
}

#[test]
fn fbm_kernel_reference() -> Result<(), ParamError> {
    let kernel = find("fbm")?;
    let p = kernel.resolve(None, &[])?;
    let img = kernel.reference(&p, 32, 32);
    assert_eq!((img.width, img.height), (32, 32));
    for px in &img.data {
        assert!((0.0..=1.0).contains(&px[0]), "{px:?}");
        assert_eq!((px[0], px[1], px[2], px[3]), (px[0], px[0], px[0], 1.0));
    }
    // Pixel (5, 9) is 0.5 + 0.5 f / A at frequency 4 * pixel centre.
    let f = fbm(8, 2.0, 0.5);
    let n = Noise::new(Basis::Perlin, 0);
    let want = 0.5 + 0.5 * f.eval(&n, [4.0 * 5.5 / 32.0, 4.0 * 9.5 / 32.0], 0.0) / f.amplitude_sum();
    assert_eq!(img.get(5, 9)[0], want as f32);
    let spread =
        img.data.iter().map(|p| p[0]).fold(0.0f32, f32::max) - img.data.iter().map(|p| p[0]).fold(1.0, f32::min);
    assert!(spread > 0.2, "image is nearly flat: spread {spread}");
    Ok(())
}

#[test]
fn fbm_kernel_bounds_cover_the_3d_perlin_peak() -> Result<(), ParamError> {
    // One octave at Perlin's 3D peak (seed 0): f / A = 1.036, so the raw
    // output passes 1 and output_bounds must say so.
    let kernel = find("fbm")?;
    let p = with(
        kernel,
        &[("octaves", "1"), ("frequency", "0.001"), ("offset", "223.3495,61.5245"), ("z_slice", "233.5")],
    )?;
    let v = kernel.reference(&p, 1, 1).get(0, 0)[0];
    let (lo, hi) = kernel.output_bounds(&p);
    assert!(v > 1.0 && v <= hi && lo < 0.0, "value {v}, bounds [{lo}, {hi}]");
    let value = with(kernel, &[("basis", "value")])?;
    assert_eq!(kernel.output_bounds(&value), (0.0, 1.0));
    Ok(())
}

// ---------------------------------------------------------------- ridged

/// (octaves, lacunarity, H, gain) combinations; offsets are chosen per test.
const RIDGED_CASES: [(u32, f64, f64, f64); 4] =
    [(8, 2.0, 1.0, 2.0), (6, 2.5, 0.5, 1.0), (10, 1.7, 0.0, 8.0), (4, 3.0, 2.0, 0.3)];

fn ridged(octaves: u32, lacunarity: f64, h: f64, offset: f64, gain: f64) -> Ridged {
    Ridged { octaves, lacunarity, h, offset, gain }
}

#[test]
fn ridged_bounds_for_offset_at_least_one() {
    for basis in BASES {
        for seed in [0, 1, 12345] {
            let n = Noise::new(basis, seed);
            for (oct, lac, h, gain) in RIDGED_CASES {
                for offset in [1.0, 1.2, 2.0] {
                    let r = ridged(oct, lac, h, offset, gain);
                    let (top, sum_w) = (r.max_value(), (0..oct).map(|i| r.weight(i)).sum::<f64>());
                    assert!((top - offset * offset * sum_w).abs() < 1e-12);
                    assert_eq!(ridged_max(&r), top, "offset >= 1: the normaliser is offset^2 sum w_i");
                    let mut hi = 0.0f64;
                    for [x, y, z] in points3(seed as u64 + 90, 300, -50.0, 50.0) {
                        let v = r.eval(&n, [x, y], z);
                        assert!(v >= 0.0 && v <= top, "{basis:?} seed {seed} {r:?}: {v} outside [0, {top}]");
                        hi = hi.max(v / top);
                    }
                    assert!(hi > 0.2, "{basis:?} {r:?}: largest value only {hi} of the maximum");
                }
            }
        }
    }
}

#[test]
fn ridged_never_decreases_when_an_octave_is_added() {
    for basis in BASES {
        for seed in [0, 7] {
            let n = Noise::new(basis, seed);
            for (_, lac, h, gain) in RIDGED_CASES {
                for offset in [0.0, 0.5, 1.0, 1.5] {
                    for [x, y, z] in points3(seed as u64 + 100, 100, -20.0, 20.0) {
                        let mut prev = 0.0;
                        for oct in 1..=10 {
                            let v = ridged(oct, lac, h, offset, gain).eval(&n, [x, y], z);
                            assert!(v >= prev, "{basis:?} octave {oct}: {v} < {prev}");
                            prev = v;
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn ridged_one_octave_is_offset_minus_abs_n_squared() {
    for basis in BASES {
        for seed in SEEDS {
            let n = Noise::new(basis, seed);
            for offset in [0.0, 0.7, 1.0, 1.3] {
                let r = ridged(1, 2.0, 1.0, offset, 2.0);
                for [x, y, z] in points3(seed as u64 + 110, 200, -100.0, 100.0) {
                    let s = offset - n.eval(x, y, z).abs();
                    assert_eq!(r.eval(&n, [x, y], z), s * s);
                }
            }
        }
    }
}

#[test]
fn ridged_at_perlin_lattice_points() {
    // N = 0 at integer points; with integer lacunarity every octave stays on
    // the lattice, so signal_i = offset^2 * clamp(signal_{i-1} gain, 0, 1).
    for seed in [0, 7] {
        let n = Noise::new(Basis::Perlin, seed);
        for offset in [0.5, 1.0, 1.25] {
            for (i, j, k) in [(0, 0, 0), (3, -7, 11), (-120, 45, 2)] {
                let (x, y, z) = (i as f64, j as f64, k as f64);
                let first = ridged(1, 2.0, 1.0, offset, 2.0).eval(&n, [x, y], z);
                assert_eq!(first, offset * offset);
                let r = ridged(6, 2.0, 0.8, offset, 2.0);
                let (mut signal, mut want) = (offset * offset, offset * offset);
                for o in 1..6 {
                    signal = offset * offset * (signal * 2.0).clamp(0.0, 1.0);
                    want += signal * r.weight(o);
                }
                let got = r.eval(&n, [x, y], z);
                assert!((got - want).abs() < 1e-12, "offset {offset} at ({i}, {j}, {k}): {got} vs {want}");
                if offset >= 1.0 {
                    // Every weight saturates: the analytic maximum is reached.
                    assert!((got - r.max_value()).abs() < 1e-12);
                }
            }
        }
    }
}

#[test]
fn ridged_kernel_reference_in_unit_range() -> Result<(), ParamError> {
    let kernel = find("ridged")?;
    let sets: [&[(&str, &str)]; 6] = [
        &[],
        &[("basis", "value")],
        &[("offset", "0.3"), ("gain", "4.0")],
        &[("offset", "0.0"), ("z_slice", "0.5"), ("seed", "7")],
        &[("offset", "2.0"), ("h", "0.0"), ("octaves", "12")],
        &[("basis", "value"), ("offset", "0.6"), ("lacunarity", "3.0"), ("seed", "12345")],
    ];
    for set in sets {
        let p = with(kernel, set)?;
        let img = kernel.reference(&p, 32, 32);
        let (mut lo, mut hi) = (f32::MAX, f32::MIN);
        for px in &img.data {
            assert!((0.0..=1.0).contains(&px[0]) && px[3] == 1.0, "{set:?}: {px:?}");
            (lo, hi) = (lo.min(px[0]), hi.max(px[0]));
        }
        assert!(hi - lo > 0.05, "{set:?}: flat image [{lo}, {hi}]");
    }
    Ok(())
}

#[test]
fn ridged_max_covers_the_3d_perlin_peak() {
    // offset 0: signal = N^2, and |N| reaches 1.036 off integer z.
    let n = Noise::new(Basis::Perlin, 0);
    let r = ridged(1, 2.0, 1.0, 0.0, 2.0);
    let v = r.eval(&n, [223.35, 61.525], 233.5);
    assert!(v > 1.0 && v <= ridged_max(&r), "raw {v}, max {}", ridged_max(&r));
}

// ---------------------------------------------------------------- permutation

#[test]
fn seeded_permutation() {
    assert_eq!(permutation(0)[..256], PERLIN_PERMUTATION.map(u32::from));
    let mut tables = Vec::new();
    for seed in SEEDS {
        let p = permutation(seed);
        assert_eq!(p, permutation(seed), "seed {seed} is not deterministic");
        assert_eq!(p.len(), 512);
        assert_eq!(p[..256], p[256..], "seed {seed}: second half is not a copy");
        let mut sorted = p[..256].to_vec();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..256).collect::<Vec<u32>>(), "seed {seed}: not a permutation of 0..255");
        tables.push(p);
    }
    for a in 0..tables.len() {
        for b in a + 1..tables.len() {
            let same = (0..256).filter(|&i| tables[a][i] == tables[b][i]).count();
            // Two random permutations share ~1 fixed position.
            assert!(same < 16, "seeds {} and {}: {same} equal entries", SEEDS[a], SEEDS[b]);
        }
    }
}
