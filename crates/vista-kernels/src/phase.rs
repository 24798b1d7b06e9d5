//! Phase functions: the f64 build of `src/cpu/phase.rs`, and their tests.

pub use crate::cpu64::phase::*;

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

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
