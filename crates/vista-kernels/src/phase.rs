//! Phase functions in f64 (SPEC 3.5, 3.6). `mu` is the cosine between the
//! direction toward the light and the view ray's direction.

use std::f64::consts::PI;

/// Rayleigh: 3 / (16 pi) (1 + mu^2).
pub fn rayleigh(mu: f64) -> f64 {
    3.0 / (16.0 * PI) * (1.0 + mu * mu)
}

/// Henyey-Greenstein: (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5).
pub fn hg(mu: f64, g: f64) -> f64 {
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * mu).powf(1.5))
}

/// (1 - blend) HG(g1) + blend HG(g2).
pub fn dual_hg(mu: f64, g1: f64, g2: f64, blend: f64) -> f64 {
    (1.0 - blend) * hg(mu, g1) + blend * hg(mu, g2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Integral over the sphere of f(mu): 2 pi * int_{-1}^{1} f(mu) dmu (Simpson).
    fn sphere_integral(f: impl Fn(f64) -> f64) -> f64 {
        let n = 20_000;
        let h = 2.0 / n as f64;
        let mut s = f(-1.0) + f(1.0);
        for i in 1..n {
            s += f(-1.0 + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        2.0 * PI * s * h / 3.0
    }

    #[test]
    fn phase_functions_integrate_to_one() {
        assert!((sphere_integral(rayleigh) - 1.0).abs() < 1e-9);
        for g in [-0.5, 0.0, 0.3, 0.7, 0.8] {
            let i = sphere_integral(|mu| hg(mu, g));
            assert!((i - 1.0).abs() < 1e-6, "HG g={g} integrates to {i}");
        }
        let i = sphere_integral(|mu| dual_hg(mu, 0.7, -0.5, 0.5));
        assert!((i - 1.0).abs() < 1e-6, "dual-lobe HG integrates to {i}");
    }

    #[test]
    fn hg_mean_cosine_is_g() {
        for g in [-0.5, 0.2, 0.8] {
            let mean = sphere_integral(|mu| mu * hg(mu, g));
            assert!((mean - g).abs() < 1e-6, "HG g={g} mean cosine {mean}");
        }
    }

    #[test]
    fn rayleigh_forward_to_side_ratio_is_two() {
        assert!((rayleigh(1.0) / rayleigh(0.0) - 2.0).abs() < 1e-15);
    }
}
