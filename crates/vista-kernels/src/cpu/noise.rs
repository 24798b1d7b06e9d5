//! The noise bases (SPEC 3.1) and the fBm / ridged sums built on them
//! (SPEC 3.2, 3.3), written from the published algorithms, not from the
//! WGSL: the GPU side is checked against the f64 build of these. The
//! integer parts (permutation, pcg3d) live in `crate::noise`.

use super::Real;
use crate::noise::{Basis, lattice_hash, permutation};

fn fade(t: Real) -> Real {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn lerp(t: Real, a: Real, b: Real) -> Real {
    a + t * (b - a)
}

/// Dot product with one of the 12 cube-edge gradients chosen by `hash & 15`.
fn grad(hash: u32, x: Real, y: Real, z: Real) -> Real {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

/// Improved Perlin noise at (x, y, z) with permutation table `p` (512 entries).
pub fn perlin(p: &[u32], x: Real, y: Real, z: Real) -> Real {
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    let xi = (fx as i64 & 255) as usize;
    let yi = (fy as i64 & 255) as usize;
    let zi = (fz as i64 & 255) as usize;
    let (x, y, z) = (x - fx, y - fy, z - fz);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let a = p[xi] as usize + yi;
    let aa = p[a] as usize + zi;
    let ab = p[a + 1] as usize + zi;
    let b = p[xi + 1] as usize + yi;
    let ba = p[b] as usize + zi;
    let bb = p[b + 1] as usize + zi;
    lerp(
        w,
        lerp(
            v,
            lerp(u, grad(p[aa], x, y, z), grad(p[ba], x - 1.0, y, z)),
            lerp(u, grad(p[ab], x, y - 1.0, z), grad(p[bb], x - 1.0, y - 1.0, z)),
        ),
        lerp(
            v,
            lerp(u, grad(p[aa + 1], x, y, z - 1.0), grad(p[ba + 1], x - 1.0, y, z - 1.0)),
            lerp(u, grad(p[ab + 1], x, y - 1.0, z - 1.0), grad(p[bb + 1], x - 1.0, y - 1.0, z - 1.0)),
        ),
    )
}

/// Upper bound of |perlin| in 3D: the maximum over the unit cell of
/// sum_c W_c * max_g (g . d_c) (each corner's best edge gradient, W_c >= 0),
/// found numerically as 1.036354 near (0.645, 0.519, 0.5). It is reached:
/// Perlin's own table gives 1.03615 at (223.35, 61.525, 233.5), so 1 is not a
/// bound off integer z. On an integer-z slice the same maximum is exactly 1.
pub const PERLIN_MAX_ABS: Real = 1.0364;

/// Lattice value in [-1, 1): (h >> 8) * 2^-24 mapped from [0, 1).
pub fn lattice_value(seed: u32, i: i32, j: i32, k: i32) -> Real {
    let unit = (lattice_hash(seed, i, j, k) >> 8) as Real * (1.0 / 16_777_216.0);
    2.0 * unit - 1.0
}

/// Value noise: quintic-faded trilinear interpolation of lattice values.
pub fn value(seed: u32, x: Real, y: Real, z: Real) -> Real {
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    let (i, j, k) = (fx as i32, fy as i32, fz as i32);
    let (u, v, w) = (fade(x - fx), fade(y - fy), fade(z - fz));
    let c = |di: i32, dj: i32, dk: i32| lattice_value(seed, i.wrapping_add(di), j.wrapping_add(dj), k.wrapping_add(dk));
    lerp(
        w,
        lerp(v, lerp(u, c(0, 0, 0), c(1, 0, 0)), lerp(u, c(0, 1, 0), c(1, 1, 0))),
        lerp(v, lerp(u, c(0, 0, 1), c(1, 0, 1)), lerp(u, c(0, 1, 1), c(1, 1, 1))),
    )
}

/// A seeded basis ready to evaluate: owns its permutation table.
#[derive(Debug, Clone)]
pub struct Noise {
    /// Which basis it evaluates.
    pub basis: Basis,
    /// The seed: it picks Perlin's permutation (0: Perlin's own) and offsets
    /// value noise's lattice hash.
    pub seed: u32,
    perm: Vec<u32>,
}

impl Noise {
    /// The basis seeded with `seed`, with its permutation built.
    pub fn new(basis: Basis, seed: u32) -> Noise {
        Noise { basis, seed, perm: permutation(seed) }
    }

    /// N(x, y, z): the basis at a point, in lattice units.
    pub fn eval(&self, x: Real, y: Real, z: Real) -> Real {
        match self.basis {
            Basis::Perlin => perlin(&self.perm, x, y, z),
            Basis::Value => value(self.seed, x, y, z),
        }
    }

    /// Upper bound of |N| used for amplitude invariants and normalisation:
    /// `PERLIN_MAX_ABS` for perlin; value noise interpolates values in [-1, 1).
    pub fn max_abs(&self) -> Real {
        match self.basis {
            Basis::Perlin => PERLIN_MAX_ABS,
            Basis::Value => 1.0,
        }
    }
}

/// fBm octave parameters (SPEC 3.2).
#[derive(Debug, Clone, Copy)]
pub struct Fbm {
    /// The number of octaves summed.
    pub octaves: u32,
    /// The frequency factor from one octave to the next.
    pub lacunarity: Real,
    /// The amplitude factor from one octave to the next.
    pub gain: Real,
    /// Octave rotation angle in radians.
    pub theta: Real,
}

impl Fbm {
    /// A = sum_{i < octaves} gain^i.
    pub fn amplitude_sum(&self) -> Real {
        (0..self.octaves).map(|i| self.gain.powi(i as i32)).sum()
    }

    /// f(p) = sum gain^i N(p_i), p_{i+1} = lacunarity R(theta) p_i, at height z.
    pub fn eval(&self, n: &Noise, p: [Real; 2], z: Real) -> Real {
        let (s, c) = self.theta.sin_cos();
        let (mut x, mut y) = (p[0], p[1]);
        let mut amp = 1.0;
        let mut sum = 0.0;
        for _ in 0..self.octaves {
            sum += amp * n.eval(x, y, z);
            amp *= self.gain;
            (x, y) = (self.lacunarity * (c * x - s * y), self.lacunarity * (s * x + c * y));
        }
        sum
    }

    /// Three-dimensional fBm (clouds): p_{i+1} = lacunarity * p_i.
    pub fn eval3(&self, n: &Noise, p: [Real; 3]) -> Real {
        let mut q = p;
        let mut amp = 1.0;
        let mut sum = 0.0;
        for _ in 0..self.octaves {
            sum += amp * n.eval(q[0], q[1], q[2]);
            amp *= self.gain;
            q = q.map(|c| c * self.lacunarity);
        }
        sum
    }
}

/// Musgrave's ridged multifractal parameters (SPEC 3.3).
#[derive(Debug, Clone, Copy)]
pub struct Ridged {
    /// The number of octaves summed.
    pub octaves: u32,
    /// The frequency factor from one octave to the next.
    pub lacunarity: Real,
    /// The fractal increment H: octave i is weighted lacunarity^(-i H).
    pub h: Real,
    /// Subtracted from |N| before squaring: an octave's signal is (offset - |N|)^2.
    pub offset: Real,
    /// Scales an octave's signal into the next octave's weight (clamped to [0, 1]).
    pub gain: Real,
}

impl Ridged {
    /// w_i = lacunarity^(-i H).
    pub fn weight(&self, i: u32) -> Real {
        self.lacunarity.powf(-(i as Real) * self.h)
    }

    /// Analytic maximum offset^2 * sum w_i: each term's signal is at most
    /// offset^2 (N = 0) and its weight at most 1.
    pub fn max_value(&self) -> Real {
        self.offset * self.offset * (0..self.octaves).map(|i| self.weight(i)).sum::<Real>()
    }

    /// Raw ridged value (not normalised).
    pub fn eval(&self, n: &Noise, p: [Real; 2], z: Real) -> Real {
        let (mut x, mut y) = (p[0], p[1]);
        let mut signal = self.offset - n.eval(x, y, z).abs();
        signal *= signal;
        let mut result = signal;
        for i in 1..self.octaves {
            x *= self.lacunarity;
            y *= self.lacunarity;
            let weight = (signal * self.gain).clamp(0.0, 1.0);
            let s = self.offset - n.eval(x, y, z).abs();
            signal = s * s * weight;
            result += signal * self.weight(i);
        }
        result
    }
}

