// Phase functions (SPEC 3.5, 3.6). mu = cosine of the angle between the
// direction toward the light and the view ray's direction.
#define_import_path vista::phase

const PI: f32 = 3.141592653589793;

// Rayleigh: 3 / (16 pi) (1 + mu^2).
fn rayleigh_phase(mu: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + mu * mu);
}

// Henyey-Greenstein: (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5).
fn hg_phase(mu: f32, g: f32) -> f32 {
    let denom = max(1.0 + g * g - 2.0 * g * mu, 1e-6);
    return (1.0 - g * g) / (4.0 * PI * denom * sqrt(denom));
}

// Blend of a forward and a backward HG lobe: clouds stay lit with the sun behind the camera.
fn dual_hg_phase(mu: f32, g1: f32, g2: f32, blend: f32) -> f32 {
    return mix(hg_phase(mu, g1), hg_phase(mu, g2), blend);
}
