// Unit tests of vista::sky (`vista test`). Expected values from SPEC 3.5,
// computed in f64 (Python's math module) with the planet's spheres as
// vectors (|p| - R_ground for an altitude, the roots of |o + t d| = r for a
// sphere): R_ground = 6360 km, R_top = 6420 km, beta_R = (5.802, 13.558,
// 33.1) 1e-6 / m, H_R = 8000 m, beta_M = 3.996e-6 / m (extinction 1.11
// beta_M), H_M = 1200 m, rho(h) = exp(-h / H), T = exp(-optical depth),
// integrals by the midpoint rule with the given sample counts.
//
// Values well below 1 are compared by their ratio to the expected value,
// so the default tolerance (1e-5) is relative for them too.
#import vista::sky::{Atmosphere, R_GROUND, altitude, densities, optical_depth, sun_transmittance, sun_transmittance_along, view_segment, sky_segment}
#import wgsl_test::{expect, expectNear, expectNearV2f, expectNearV3f}

// Sun (unit), camera altitude (m), sun intensity 20, Mie g 0.8, sample
// counts and density multipliers.
fn sky(sun: vec3<f32>, alt: f32, view_samples: u32, light_samples: u32, scale: vec2<f32>) -> Atmosphere {
    return Atmosphere(sun, alt, 20.0, 0.8, view_samples, light_samples, scale);
}

@test
fn densities_at_ground_and_at_scale_heights() {
    let a = sky(vec3<f32>(0.0, 1.0, 0.0), 0.0, 1u, 1u, vec2<f32>(1.0, 1.0));
    expectNearV2f(densities(a, 0.0), vec2<f32>(1.0, 1.0));
    // h = H_R: (e^-1, e^(-8000 / 1200)) = (0.36787944117144233, 0.0012726338013398079).
    expectNearV2f(densities(a, 8000.0) / vec2<f32>(0.36787944117144233, 0.0012726338013398079), vec2<f32>(1.0));
    // h = H_M: (e^(-1200 / 8000), e^-1) = (0.8607079764250578, 0.36787944117144233).
    expectNearV2f(densities(a, 1200.0) / vec2<f32>(0.8607079764250578, 0.36787944117144233), vec2<f32>(1.0));
    // The multipliers scale each: (2, 0.5) at h = H_M.
    let b = sky(vec3<f32>(0.0, 1.0, 0.0), 0.0, 1u, 1u, vec2<f32>(2.0, 0.5));
    expectNearV2f(densities(b, 1200.0) / vec2<f32>(1.7214159528501156, 0.18393972058572117), vec2<f32>(1.0));
}

@test
fn optical_depth_of_the_scale_height_column() {
    // Columns (H_R, H_M) = (8000, 1200) m, the whole air above the ground:
    // beta_R * 8000 + 1.11 * 3.996e-6 * 1200 per channel.
    let tau = optical_depth(vec2<f32>(8000.0, 1200.0));
    expectNearV3f(tau / vec3<f32>(0.051738672, 0.113786672, 0.270122672), vec3<f32>(1.0));
    // Rayleigh alone and Mie alone (grey).
    expectNearV3f(optical_depth(vec2<f32>(1.0e5, 0.0)), vec3<f32>(0.5802, 1.3558, 3.31));
    expectNearV3f(optical_depth(vec2<f32>(0.0, 1.0e5)) / vec3<f32>(0.443556), vec3<f32>(1.0));
}

@test
fn altitude_from_the_squared_radius_difference() {
    // k = h (2 R_ground + h) is the altitude h's |p|^2 - R_ground^2.
    expectNear(altitude(0.0), 0.0, 0.0);
    expectNear(altitude(1000.0 * (2.0 * R_GROUND + 1000.0)), 1000.0);
    expectNear(altitude(59000.0 * (2.0 * R_GROUND + 59000.0)), 59000.0);
}

@test
fn view_segment_against_the_spheres() {
    // Camera at 1000 m: straight up it leaves the top sphere at
    // R_top - R_ground - 1000 = 59000 m.
    let low = sky(vec3<f32>(0.0, 1.0, 0.0), 1000.0, 1u, 1u, vec2<f32>(1.0, 1.0));
    expectNearV2f(view_segment(low, vec3<f32>(0.0, 1.0, 0.0)), vec2<f32>(0.0, 59000.0));
    // Straight down it meets the ground at 1000 m.
    expectNearV2f(view_segment(low, vec3<f32>(0.0, -1.0, 0.0)), vec2<f32>(0.0, 1000.0));
    // Horizontally: sqrt(R_top^2 - (R_ground + 1000)^2) = 868377.2221793936 m.
    expectNearV2f(view_segment(low, vec3<f32>(0.0, 0.0, 1.0)), vec2<f32>(0.0, 868377.2221793936));
    // 30 degrees up, (0, 0.5, sqrt(3) / 2): the top sphere's far root 116416.62769928109 m.
    expectNearV2f(view_segment(low, vec3<f32>(0.0, 0.5, 0.8660254037844386)), vec2<f32>(0.0, 116416.62769928109));
    // From 100 km looking down: enters at 40 km, meets the ground at 100 km.
    let high = sky(vec3<f32>(0.0, 1.0, 0.0), 100000.0, 1u, 1u, vec2<f32>(1.0, 1.0));
    expectNearV2f(view_segment(high, vec3<f32>(0.0, -1.0, 0.0)), vec2<f32>(40000.0, 100000.0));
    // Looking up from there it never enters: t1 <= t0.
    let up = view_segment(high, vec3<f32>(0.0, 1.0, 0.0));
    expect(up.y <= up.x);
}

@test
fn sun_transmittance_one_step_from_the_ground() {
    // p on the ground (k = 0), sun on the horizon (p . s = 0): the path to the
    // top is sqrt(R_top^2 - R_ground^2) = 875671.17 m; one midpoint sample
    // at altitude 15052.94 m: exp(-(beta_R rho_R + 1.11 beta_M rho_M) L).
    let a = sky(vec3<f32>(0.0, 0.0, 1.0), 0.0, 1u, 1u, vec2<f32>(1.0, 1.0));
    let t1 = sun_transmittance(a, 0.0, 0.0);
    expectNearV3f(t1 / vec3<f32>(0.4611569583578865, 0.16386885487963213, 0.012086742352099005), vec3<f32>(1.0));
    // Four samples: 0.12434177633995627, 0.013866433317650763, 5.516507265892077e-05.
    let b = sky(vec3<f32>(0.0, 0.0, 1.0), 0.0, 1u, 4u, vec2<f32>(1.0, 1.0));
    let t4 = sun_transmittance(b, 0.0, 0.0);
    expectNearV3f(t4 / vec3<f32>(0.12434177633995627, 0.013866433317650763, 5.516507265892077e-05), vec3<f32>(1.0));
}

@test
fn sun_transmittance_along_a_view_ray() {
    // Camera at 1000 m, view straight up, the point at t = 2000 m (3000 m
    // up); sun (0, 0.6, 0.8); four midpoint samples to the top sphere.
    let a = sky(vec3<f32>(0.0, 0.6, 0.8), 1000.0, 1u, 4u, vec2<f32>(1.0, 1.0));
    let t = sun_transmittance_along(a, vec3<f32>(0.0, 1.0, 0.0), 2000.0);
    expectNearV3f(t, vec3<f32>(0.9543767641171932, 0.8966510134183616, 0.7662162912636267));
    // The ground blocks a sun 0.1 below the horizon from the camera (its
    // ray meets the ground sphere at 10079 m): exactly 0.
    let b = sky(vec3<f32>(0.0, -0.1, 0.99498743710662), 1000.0, 1u, 4u, vec2<f32>(1.0, 1.0));
    let blocked = sun_transmittance_along(b, vec3<f32>(0.0, 1.0, 0.0), 0.0);
    expect(all(blocked == vec3<f32>(0.0)));
}

@test
fn sky_segment_one_view_sample() {
    // Camera at 1000 m, view v = (0, 0, 1) over [0, 100 km], sun s = (0, 0.6,
    // 0.8) (mu = 0.8), E = 20, g = 0.8; one view sample at t = 50 km
    // (altitude 1196.5069 m), one light sample toward the sun. SPEC 3.5's
    // integrand there times dt: E dt T(c, mid) (beta_R rho_R P_R(mu) +
    // beta_M rho_M P_HG(mu)) T_sun(mid), with T(c, mid) from the column
    // rho dt / 2; transmittance exp(-optical depth of rho dt).
    let a = sky(vec3<f32>(0.0, 0.6, 0.8), 1000.0, 1u, 1u, vec2<f32>(1.0, 1.0));
    let seg = sky_segment(a, vec3<f32>(0.0, 0.0, 1.0), 0.0, 100000.0);
    expectNearV3f(seg.inscatter, vec3<f32>(0.9706085679885543, 1.3365258052671827, 1.232962407864475));
    expectNearV3f(seg.transmittance / vec3<f32>(0.5151734339957246, 0.2641842982049611, 0.04910283923111496), vec3<f32>(1.0));
    // No air: nothing scattered, everything passed.
    let empty = sky(vec3<f32>(0.0, 0.6, 0.8), 1000.0, 1u, 1u, vec2<f32>(0.0, 0.0));
    let none = sky_segment(empty, vec3<f32>(0.0, 0.0, 1.0), 0.0, 100000.0);
    expect(all(none.inscatter == vec3<f32>(0.0)));
    expect(all(none.transmittance == vec3<f32>(1.0)));
}
