// Ray geometry shared by the sky, cloud and heightfield kernels.
#define_import_path vista::geometry

// Unit vector at azimuth `az` (from +z toward +x) and elevation `el`, radians.
fn direction(az: f32, el: f32) -> vec3<f32> {
    return vec3(cos(el) * sin(az), sin(el), cos(el) * cos(az));
}

// The SPEC 3.4 pinhole camera: position, basis, tan(fov / 2) and W / H.
struct Pinhole {
    pos: vec3<f32>,
    forward: vec3<f32>,
    right: vec3<f32>,
    up: vec3<f32>,
    tan_half_fov: f32,
    aspect: f32,
}

// Looking along the unit, non-vertical `forward` (the host refuses vertical
// views before any GPU work): r = normalize(cross(f, (0,1,0))), up = cross(r, f).
fn pinhole_looking(pos: vec3<f32>, forward: vec3<f32>, fov_deg: f32, aspect: f32) -> Pinhole {
    let right = normalize(cross(forward, vec3(0.0, 1.0, 0.0)));
    return Pinhole(pos, forward, right, cross(right, forward), tan(0.5 * radians(fov_deg)), aspect);
}

// f = normalize(look_at - pos), then pinhole_looking.
fn pinhole_look_at(pos: vec3<f32>, look_at: vec3<f32>, fov_deg: f32, aspect: f32) -> Pinhole {
    return pinhole_looking(pos, normalize(look_at - pos), fov_deg, aspect);
}

// The unit ray through the pixel-centre coordinates uv (v down).
fn pinhole_ray(c: Pinhole, uv: vec2<f32>) -> vec3<f32> {
    let sx = (2.0 * uv.x - 1.0) * c.tan_half_fov * c.aspect;
    let sy = (1.0 - 2.0 * uv.y) * c.tan_half_fov;
    return normalize(c.forward + sx * c.right + sy * c.up);
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
