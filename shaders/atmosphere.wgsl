// atmosphere kernel (SPEC 3.5): single-scattering Rayleigh + Mie sky.
// Writes linear radiance L (RGB), alpha 1.
//
// f32 at planetary scale: positions are ~6.4e6 m, where an ulp is ~0.5 m and
// |p|^2 - R^2 loses everything to cancellation. So no absolute position is
// ever formed. Along p = c + t v (c = camera, |c| = R_ground + altitude):
//   k(t) = |p|^2 - R_ground^2 = k_c + t (2 (c . v) + t),  k_c = alt (2 R_ground + alt)
//   h(t) = k / (|p| + R_ground)                             (no cancellation)
//   p . s = |c| s_y + t (v . s)
// and the same expansion again along the ray toward the sun.
#import vista::geometry::{ray_sphere_bc, latlong_direction}
#import vista::phase::{rayleigh_phase, hg_phase}

// Packed by name from kernels/atmosphere.toml (exposure is the host's tone map).
struct Params {
    width: u32,
    height: u32,
    projection: u32,
    view_samples: u32,
    light_samples: u32,
    sun_elevation_deg: f32,
    camera_altitude_m: f32,
    sun_intensity: f32,
    mie_g: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

const R_GROUND: f32 = 6360000.0;
// R_top^2 - R_ground^2 = (6420 km - 6360 km)(6420 km + 6360 km).
const TOP_K: f32 = 7.668e11;
const BETA_R: vec3<f32> = vec3(5.802e-6, 13.558e-6, 33.1e-6);
const H_R: f32 = 8000.0;
const BETA_M: f32 = 3.996e-6;
const BETA_M_EXT: f32 = 4.43556e-6; // 1.11 * BETA_M
const H_M: f32 = 1200.0;
const PI: f32 = 3.141592653589793;

// The camera sits at (0, R_ground + altitude, 0); the sun at azimuth 0.
fn camera_radius() -> f32 {
    return R_GROUND + params.camera_altitude_m;
}

// k_c = |c|^2 - R_ground^2 = alt (2 R_ground + alt): a product, so f32 forms
// it to within one rounding (the difference of squares would cancel).
fn camera_k() -> f32 {
    let alt = params.camera_altitude_m;
    return alt * (2.0 * R_GROUND + alt);
}

fn sun_direction() -> vec3<f32> {
    let e = radians(params.sun_elevation_deg);
    return vec3(0.0, sin(e), cos(e));
}

// Altitude of the point with |p|^2 - R_ground^2 = k.
fn altitude(k: f32) -> f32 {
    return k / (sqrt(max(R_GROUND * R_GROUND + k, 0.0)) + R_GROUND);
}

// (rho_R, rho_M) at altitude h.
fn densities(h: f32) -> vec2<f32> {
    return exp(-h / vec2(H_R, H_M));
}

fn optical_depth(column: vec2<f32>) -> vec3<f32> {
    return BETA_R * column.x + BETA_M_EXT * column.y;
}

// Transmittance toward the sun from the point with |p|^2 - R_ground^2 = k and
// p . s = bs; 0 when the ground blocks the sun.
fn sun_transmittance(k: f32, bs: f32) -> vec3<f32> {
    // Ground ahead: the ray descends (bs < 0) and meets the sphere.
    if bs < 0.0 && bs * bs - k >= 0.0 {
        return vec3(0.0);
    }
    // min(): a point on the top sphere may round to just outside it.
    let exit = max(ray_sphere_bc(bs, min(k - TOP_K, 0.0)).y, 0.0);
    let du = exit / f32(params.light_samples);
    var column = vec2(0.0);
    for (var j = 0u; j < params.light_samples; j++) {
        let u = (f32(j) + 0.5) * du;
        column += densities(altitude(k + u * (2.0 * bs + u)));
    }
    return exp(-optical_depth(column * du));
}

fn radiance(v: vec3<f32>) -> vec3<f32> {
    let rc = camera_radius();
    let kc = camera_k();
    let b = rc * v.y; // c . v
    let top = ray_sphere_bc(b, kc - TOP_K);
    if top.y <= 0.0 {
        return vec3(0.0); // never enters the atmosphere
    }
    let t0 = max(top.x, 0.0);
    var t1 = top.y;
    // The camera is above the ground: a hit ahead has both roots >= 0.
    let ground = ray_sphere_bc(b, kc);
    if ground.x >= 0.0 && ground.y > 0.0 {
        t1 = min(t1, ground.x);
    }
    let s = sun_direction();
    let mu = dot(v, s);
    let phase = vec2(rayleigh_phase(mu), hg_phase(mu, params.mie_g));
    let bs0 = rc * s.y; // c . s
    let dt = (t1 - t0) / f32(params.view_samples);
    var before = vec2(0.0); // density integrals over the finished steps
    var sum = vec3(0.0);
    for (var i = 0u; i < params.view_samples; i++) {
        let t = t0 + (f32(i) + 0.5) * dt;
        let k = kc + t * (2.0 * b + t);
        let rho = densities(altitude(k));
        let to_mid = exp(-optical_depth(before + 0.5 * dt * rho));
        let sun = sun_transmittance(k, bs0 + t * mu);
        let scatter = BETA_R * (rho.x * phase.x) + BETA_M * rho.y * phase.y;
        sum += to_mid * scatter * sun;
        before += dt * rho;
    }
    return params.sun_intensity * dt * sum;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size;
    var l = vec3(0.0);
    if params.projection == 0u {
        l = radiance(latlong_direction(uv.x, uv.y));
    } else {
        // Equidistant fisheye: zenith at the centre, horizon on the inscribed
        // circle, azimuth 0 (the sun) up.
        let xy = vec2(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y) * size / min(size.x, size.y);
        let r = length(xy);
        if r <= 1.0 {
            let phi = atan2(xy.x, xy.y);
            let e = 0.5 * PI * (1.0 - r);
            l = radiance(vec3(cos(e) * sin(phi), sin(e), cos(e) * cos(phi)));
        }
    }
    textureStore(output, id.xy, vec4(l, 1.0));
}
