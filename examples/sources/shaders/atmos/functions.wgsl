#define_import_path atmos::functions

#import atmos::{types::Atmosphere, bindings::atmosphere}

// Distance from radius r, along a ray whose zenith cosine is mu, to the
// top of the atmosphere: the positive root of |p + t d| = top_radius.
fn distance_to_top(r: f32, mu: f32) -> f32 {
    let top = atmosphere.top_radius;
    let disc = r * r * (mu * mu - 1.0) + top * top;
    return max(0.0, -r * mu + sqrt(max(disc, 0.0)));
}

// Rayleigh transmittance exp(-beta * integral of rho) from (r, mu) to the
// top, rho = exp(-h / H), by the midpoint rule with SAMPLE_COUNT samples.
fn transmittance_to_top(r: f32, mu: f32) -> vec3<f32> {
    let samples = f32(#{SAMPLE_COUNT});
    let d = distance_to_top(r, mu);
    let dt = d / samples;
    var depth = 0.0;
    for (var i = 0.0; i < samples; i += 1.0) {
        let t = (i + 0.5) * dt;
        let radius = sqrt(r * r + t * t + 2.0 * r * mu * t);
        depth += exp(-(radius - atmosphere.bottom_radius) / atmosphere.rayleigh_scale_height) * dt;
    }
    return exp(-atmosphere.rayleigh_scattering * depth);
}
