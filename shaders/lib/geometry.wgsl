// Ray geometry shared by the sky, cloud and heightfield kernels.
#define_import_path vista::geometry

// SPEC 3.4 pinhole camera: the unit ray through the pixel-centre coordinates
// uv (v down) for the basis fwd/right/up, tan(fov / 2) and aspect W / H.
// Twin of `Camera::ray` in crates/vista-kernels/src/geometry.rs.
fn pinhole_ray(uv: vec2<f32>, tan_half_fov: f32, aspect: f32, fwd: vec3<f32>, right: vec3<f32>, up: vec3<f32>) -> vec3<f32> {
    let sx = (2.0 * uv.x - 1.0) * tan_half_fov * aspect;
    let sy = (1.0 - 2.0 * uv.y) * tan_half_fov;
    return normalize(fwd + sx * right + sy * up);
}

// Distances (t0, t1), t0 <= t1, where the ray o + t d (d unit) meets the
// sphere of radius r centred at the origin; (-1, -1) when it misses.
fn ray_sphere(o: vec3<f32>, d: vec3<f32>, r: f32) -> vec2<f32> {
    return ray_sphere_bc(dot(o, d), dot(o, o) - r * r);
}

// ray_sphere from b = dot(o, d) and c = |o|^2 - r^2 given by the caller.
// At planetary radii dot(o, o) - r * r cancels catastrophically in f32 (an
// ulp of 6.4e6^2 is 4e6 m^2); callers that know c exactly (from an altitude
// h: c = h (2 r + h)) pass it here instead.
fn ray_sphere_bc(b: f32, c: f32) -> vec2<f32> {
    let disc = b * b - c;
    if disc < 0.0 {
        return vec2(-1.0, -1.0);
    }
    let s = sqrt(disc);
    // Stable form: avoids cancellation for the near root when |b| >> s.
    let sb = select(-1.0, 1.0, b >= 0.0);
    let q = -b - sb * s;
    let tb = select(c / q, 0.0, q == 0.0);
    return vec2(min(q, tb), max(q, tb));
}

// Direction on the upper hemisphere for the latlong projection:
// azimuth phi = 2 pi u, elevation e = (pi / 2)(1 - v).
fn latlong_direction(u: f32, v: f32) -> vec3<f32> {
    let phi = 2.0 * 3.141592653589793 * u;
    let e = 0.5 * 3.141592653589793 * (1.0 - v);
    return vec3(cos(e) * sin(phi), sin(e), cos(e) * cos(phi));
}
