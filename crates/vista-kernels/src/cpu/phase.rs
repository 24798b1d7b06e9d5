//! Phase functions (SPEC 3.5, 3.6). `mu` is the cosine between the
//! direction toward the light and the view ray's direction.

use super::Real;
use super::consts::PI;

/// Rayleigh: 3 / (16 pi) (1 + mu^2).
pub fn rayleigh(mu: Real) -> Real {
    3.0 / (16.0 * PI) * (1.0 + mu * mu)
}

/// Henyey-Greenstein: (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5).
pub fn hg(mu: Real, g: Real) -> Real {
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * mu).powf(1.5))
}

/// (1 - blend) HG(g1) + blend HG(g2).
pub fn dual_hg(mu: Real, g1: Real, g2: Real, blend: Real) -> Real {
    (1.0 - blend) * hg(mu, g1) + blend * hg(mu, g2)
}
