// Shared pieces of the sky LUT chain (after Hillaire 2020, "A Scalable and
// Production Ready Sky and Atmosphere Rendering Technique"): the
// atmosphere's layers, ray-sphere distances and the transmittance LUT's
// parametrisation. Lengths in km, coefficients per km.
#define_import_path sky_luts::common

struct Atmosphere {
    bottom_radius: f32,
    top_radius: f32,
    rayleigh_scale_height: f32,
    mie_scale_height: f32,
    rayleigh_scattering: vec3<f32>,
    mie_scattering: f32,
    ozone_absorption: vec3<f32>,
    mie_absorption: f32,
    ground_albedo: vec3<f32>,
    ozone_center: f32,
    ozone_width: f32,
    mie_g: f32,
    _pad_x: f32,
    _pad_y: f32,
}

const PI: f32 = 3.14159265358979;

// Scattering and extinction at altitude h above the ground.
struct Medium {
    rayleigh: vec3<f32>,
    mie: f32,
    extinction: vec3<f32>,
}

fn medium_at(atm: Atmosphere, h: f32) -> Medium {
    let rayleigh = atm.rayleigh_scattering * exp(-h / atm.rayleigh_scale_height);
    let mie_density = exp(-h / atm.mie_scale_height);
    let mie = atm.mie_scattering * mie_density;
    // Ozone: a tent of density 1 at its centre, 0 at half its width away.
    let ozone = atm.ozone_absorption * max(0.0, 1.0 - abs(h - atm.ozone_center) / (0.5 * atm.ozone_width));
    return Medium(rayleigh, mie, rayleigh + vec3<f32>(mie + atm.mie_absorption * mie_density) + ozone);
}

// Distance from radius r along cos-zenith mu to the sphere of radius big
// (r <= big): the far root of |p + t d| = big.
fn distance_to_sphere(r: f32, mu: f32, big: f32) -> f32 {
    let disc = r * r * (mu * mu - 1.0) + big * big;
    return max(0.0, -r * mu + sqrt(max(disc, 0.0)));
}

// Distance to the ground along mu, or -1 when the ray misses it.
fn distance_to_ground(r: f32, mu: f32, ground: f32) -> f32 {
    let disc = r * r * (mu * mu - 1.0) + ground * ground;
    if (mu >= 0.0 || disc < 0.0) {
        return -1.0;
    }
    return max(0.0, -r * mu - sqrt(disc));
}

// Radius and cos-zenith after t along a ray from radius r at cos-zenith mu.
fn radius_after(r: f32, mu: f32, t: f32) -> f32 {
    return sqrt(max(r * r + t * t + 2.0 * r * mu * t, 0.0));
}

// The transmittance LUT's coordinates: u = (mu + 1) / 2 across, the
// altitude's share of the atmosphere's thickness down.
fn transmittance_uv(atm: Atmosphere, r: f32, mu: f32) -> vec2<f32> {
    let v = (r - atm.bottom_radius) / (atm.top_radius - atm.bottom_radius);
    return vec2<f32>(0.5 * (mu + 1.0), clamp(v, 0.0, 1.0));
}

fn lut_radius(atm: Atmosphere, v: f32) -> f32 {
    return atm.bottom_radius + v * (atm.top_radius - atm.bottom_radius);
}
