// Rayleigh + Mie single scattering (SPEC 3.5): the sky's radiance, the
// in-scattering and transmittance of any part of a view ray (aerial
// perspective), and the sun's transmittance from a point on it. Shared by
// the atmosphere and landscape kernels.
//
// f32 at planetary scale: positions are ~6.4e6 m, where an ulp is ~0.5 m and
// |p|^2 - R^2 loses everything to cancellation. So no absolute position is
// ever formed. Along p = c + t v (c = camera, |c| = R_ground + altitude):
//   k(t) = |p|^2 - R_ground^2 = k_c + t (2 (c . v) + t),  k_c = alt (2 R_ground + alt)
//   h(t) = k / (|p| + R_ground)                             (no cancellation)
//   p . s = |c| s_y + t (v . s)
// and the same expansion again along the ray toward the sun.
#define_import_path vista::sky

#import vista::geometry::ray_sphere_bc
#import vista::phase::{rayleigh_phase, hg_phase}

const R_GROUND: f32 = 6360000.0;
// R_top^2 - R_ground^2 = (6420 km - 6360 km)(6420 km + 6360 km).
const TOP_K: f32 = 7.668e11;
const BETA_R: vec3<f32> = vec3(5.802e-6, 13.558e-6, 33.1e-6);
const H_R: f32 = 8000.0;
const BETA_M: f32 = 3.996e-6;
const BETA_M_EXT: f32 = 4.43556e-6; // 1.11 * BETA_M
const H_M: f32 = 1200.0;

// One sky: the camera sits at (0, R_ground + altitude, 0), y up; lengths in m.
struct Atmosphere {
    // Unit vector toward the sun.
    sun: vec3<f32>,
    camera_altitude_m: f32,
    sun_intensity: f32,
    mie_g: f32,
    view_samples: u32,
    light_samples: u32,
    // Multipliers of the (Rayleigh, Mie) densities: (1, 1) is SPEC 3.5's
    // air, (0, 0) no atmosphere at all.
    density_scale: vec2<f32>,
}

// What a part of a view ray adds and passes: in-scattered radiance and
// transmittance per channel.
struct SkySegment {
    inscatter: vec3<f32>,
    transmittance: vec3<f32>,
}

fn camera_radius(a: Atmosphere) -> f32 {
    return R_GROUND + a.camera_altitude_m;
}

// k_c = |c|^2 - R_ground^2 = alt (2 R_ground + alt): a product, so f32 forms
// it to within one rounding (the difference of squares would cancel).
fn camera_k(a: Atmosphere) -> f32 {
    let alt = a.camera_altitude_m;
    return alt * (2.0 * R_GROUND + alt);
}

// Altitude of the point with |p|^2 - R_ground^2 = k.
fn altitude(k: f32) -> f32 {
    return k / (sqrt(max(R_GROUND * R_GROUND + k, 0.0)) + R_GROUND);
}

// (rho_R, rho_M) at altitude h.
fn densities(a: Atmosphere, h: f32) -> vec2<f32> {
    return exp(-h / vec2(H_R, H_M)) * a.density_scale;
}

fn optical_depth(column: vec2<f32>) -> vec3<f32> {
    return BETA_R * column.x + BETA_M_EXT * column.y;
}

// Transmittance toward the sun from the point with |p|^2 - R_ground^2 = k and
// p . s = bs; 0 when the ground blocks the sun.
fn sun_transmittance(a: Atmosphere, k: f32, bs: f32) -> vec3<f32> {
    // Ground ahead: the ray descends (bs < 0) and meets the sphere.
    if bs < 0.0 && bs * bs - k >= 0.0 {
        return vec3(0.0);
    }
    // min(): a point on the top sphere may round to just outside it.
    let exit = max(ray_sphere_bc(bs, min(k - TOP_K, 0.0)).y, 0.0);
    let du = exit / f32(a.light_samples);
    var column = vec2(0.0);
    for (var j = 0u; j < a.light_samples; j++) {
        let u = (f32(j) + 0.5) * du;
        column += densities(a, altitude(k + u * (2.0 * bs + u)));
    }
    return exp(-optical_depth(column * du));
}

// Transmittance toward the sun from the point at distance t (m) along the
// unit view direction v.
fn sun_transmittance_along(a: Atmosphere, v: vec3<f32>, t: f32) -> vec3<f32> {
    let rc = camera_radius(a);
    let k = camera_k(a) + t * (2.0 * rc * v.y + t);
    return sun_transmittance(a, k, rc * a.sun.y + t * dot(v, a.sun));
}

// The part [t0, t1] (m) of the view ray inside the atmosphere: entry into /
// exit from the top sphere, cut at the ground; t1 <= t0 when it never enters.
fn view_segment(a: Atmosphere, v: vec3<f32>) -> vec2<f32> {
    let kc = camera_k(a);
    let b = camera_radius(a) * v.y; // c . v
    let top = ray_sphere_bc(b, kc - TOP_K);
    if top.y <= 0.0 {
        return vec2(0.0, 0.0); // never enters the atmosphere
    }
    let t0 = max(top.x, 0.0);
    var t1 = top.y;
    // The camera is above the ground: a hit ahead has both roots >= 0.
    let ground = ray_sphere_bc(b, kc);
    if ground.x >= 0.0 && ground.y > 0.0 {
        t1 = min(t1, ground.x);
    }
    return vec2(t0, t1);
}

// Single scattering over [t0, t1] (m) of the view ray along v: the midpoint
// rule with view_samples steps, each lit by the sun's transmittance
// (light_samples steps) and dimmed by the transmittance back to t0.
fn sky_segment(a: Atmosphere, v: vec3<f32>, t0: f32, t1: f32) -> SkySegment {
    let rc = camera_radius(a);
    let kc = camera_k(a);
    let b = rc * v.y; // c . v
    let s = a.sun;
    let mu = dot(v, s);
    let phase = vec2(rayleigh_phase(mu), hg_phase(mu, a.mie_g));
    let bs0 = rc * s.y; // c . s
    let dt = (t1 - t0) / f32(a.view_samples);
    var before = vec2(0.0); // density integrals over the finished steps
    var sum = vec3(0.0);
    for (var i = 0u; i < a.view_samples; i++) {
        let t = t0 + (f32(i) + 0.5) * dt;
        let k = kc + t * (2.0 * b + t);
        let rho = densities(a, altitude(k));
        let to_mid = exp(-optical_depth(before + 0.5 * dt * rho));
        let sun = sun_transmittance(a, k, bs0 + t * mu);
        let scatter = BETA_R * (rho.x * phase.x) + BETA_M * rho.y * phase.y;
        sum += to_mid * scatter * sun;
        before += dt * rho;
    }
    return SkySegment(a.sun_intensity * dt * sum, exp(-optical_depth(before)));
}

// Radiance arriving at the camera along v from the whole atmosphere.
fn sky_radiance(a: Atmosphere, v: vec3<f32>) -> vec3<f32> {
    let seg = view_segment(a, v);
    if seg.y <= seg.x {
        return vec3(0.0);
    }
    return sky_segment(a, v, seg.x, seg.y).inscatter;
}
