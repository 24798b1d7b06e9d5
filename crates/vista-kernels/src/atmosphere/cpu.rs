//! The `atmosphere` kernel's reference (SPEC 3.5): the midpoint-rule
//! single-scattering integral with explicit 3D positions (|p| - R_ground for
//! altitudes). See `crate::atmosphere` for the scheme; the WGSL works from
//! camera-relative scalars instead, so the two meet only through the math.
//! Built in f64 (the oracle) and f32.

use super::consts::PI;
use super::phase::{hg, rayleigh};
use super::{Real, Vec3, real, render_cpu};
use crate::ParamSet;
use vista_image::Image;

/// Ground radius (m).
pub const R_GROUND: Real = 6_360_000.0;
/// Top-of-atmosphere radius (m).
pub const R_TOP: Real = 6_420_000.0;
/// Rayleigh scattering = extinction (no absorption), per m, RGB.
pub const BETA_R: [Real; 3] = [5.802e-6, 13.558e-6, 33.1e-6];
/// Rayleigh scale height (m).
pub const H_R: Real = 8000.0;
/// Mie scattering coefficient (per m).
pub const BETA_M: Real = 3.996e-6;
/// Mie extinction = 1.11 * scattering (per m).
pub const BETA_M_EXT: Real = 1.11 * BETA_M;
/// Mie scale height (m).
pub const H_M: Real = 1200.0;


/// Altitude above the ground of a point (m).
pub fn altitude(p: Vec3) -> Real {
    p.length() - R_GROUND
}

/// Densities (rho_R, rho_M) = (exp(-h / H_R), exp(-h / H_M)).
pub fn densities(h: Real) -> [Real; 2] {
    [(-h / H_R).exp(), (-h / H_M).exp()]
}

/// Optical depth per RGB channel of the density integrals (Rayleigh, Mie) in m.
pub fn optical_depth_of(column: [Real; 2]) -> [Real; 3] {
    BETA_R.map(|b| b * column[0] + BETA_M_EXT * column[1])
}

/// Extinction per RGB channel at altitude h (per m).
pub fn extinction(h: Real) -> [Real; 3] {
    let [r, m] = densities(h);
    optical_depth_of([r, m])
}

/// Distances (t0, t1), t0 <= t1, where o + t d (d unit) meets the sphere of
/// radius r centred at the origin, or None when it misses.
pub fn ray_sphere(o: Vec3, d: Vec3, r: Real) -> Option<(Real, Real)> {
    let b = o.dot(d);
    let c = o.length_squared() - r * r;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    // The stable pair of roots: q avoids cancellation, c / q is the other one.
    let q = -b - b.signum() * s;
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    let (a, e) = (q, c / q);
    Some((a.min(e), a.max(e)))
}

/// Density integrals (int rho_R, int rho_M) in m over o + t d, t in [0, length],
/// by the midpoint rule with `samples` steps.
pub fn column(o: Vec3, d: Vec3, length: Real, samples: u32) -> [Real; 2] {
    let dt = length / samples as Real;
    let mut sum = [0.0; 2];
    for i in 0..samples {
        let [r, m] = densities(altitude(o + (i as Real + 0.5) * dt * d));
        sum[0] += r;
        sum[1] += m;
    }
    sum.map(|s| s * dt)
}

/// Optical depth per RGB channel of the segment o + t d, t in [0, length].
pub fn optical_depth(o: Vec3, d: Vec3, length: Real, samples: u32) -> [Real; 3] {
    optical_depth_of(column(o, d, length, samples))
}

/// Transmittance exp(-optical depth) per RGB channel of a segment.
pub fn transmittance(o: Vec3, d: Vec3, length: Real, samples: u32) -> [Real; 3] {
    optical_depth(o, d, length, samples).map(|t| (-t).exp())
}

/// Exact density integrals (Rayleigh, Mie) straight up from altitude `alt` to
/// the top: int_0^{top - alt} exp(-(alt + t) / H) dt
/// = H exp(-alt / H) (1 - exp(-(R_top - R_ground - alt) / H)).
/// At alt = 0 this is SPEC 3.5's beta * H * (1 - exp(-(R_top - R_ground - alt) / H))
/// divided by beta; above the ground SPEC's form lacks the exp(-alt / H) factor
/// (it measures the density from the camera instead of from the ground).
pub fn zenith_column_closed_form(alt: Real) -> [Real; 2] {
    let len = R_TOP - R_GROUND - alt;
    [H_R, H_M].map(|h| h * (-alt / h).exp() * -(-len / h).exp_m1())
}

/// Latlong projection (SPEC 3.5): azimuth 2 pi u, elevation (pi / 2)(1 - v).
pub fn latlong_direction(u: Real, v: Real) -> Vec3 {
    let (phi, e) = (2.0 * PI * u, 0.5 * PI * (1.0 - v));
    Vec3::new(e.cos() * phi.sin(), e.sin(), e.cos() * phi.cos())
}

/// Equidistant fisheye of the upper hemisphere: zenith at the image centre,
/// the horizon on the circle inscribed in the shorter side, azimuth 0 (the
/// sun) at the top. None outside the circle.
pub fn fisheye_direction(u: Real, v: Real, width: u32, height: u32) -> Option<Vec3> {
    let m = width.min(height) as Real;
    let x = (2.0 * u - 1.0) * width as Real / m;
    let y = (1.0 - 2.0 * v) * height as Real / m;
    let r = (x * x + y * y).sqrt();
    if r > 1.0 {
        return None;
    }
    let (phi, e) = (x.atan2(y), 0.5 * PI * (1.0 - r));
    Some(Vec3::new(
        e.cos() * phi.sin(),
        e.sin(),
        e.cos() * phi.cos(),
    ))
}

/// One sky configuration: everything the radiance integral needs.
#[derive(Debug, Clone, Copy)]
pub struct Sky {
    /// Unit vector toward the sun, (0, sin e_s, cos e_s).
    pub sun: Vec3,
    /// Camera height above the ground (m).
    pub camera_altitude: Real,
    /// E_sun: the sun's irradiance, which scales all in-scattered radiance.
    pub sun_intensity: Real,
    /// Henyey-Greenstein asymmetry g of the Mie phase, in [-0.99, 0.99].
    pub mie_g: Real,
    /// Midpoint steps along the view ray's segment inside the atmosphere.
    pub view_samples: u32,
    /// Midpoint steps toward the sun from each view sample.
    pub light_samples: u32,
    /// Multipliers of the (Rayleigh, Mie) densities: (1, 1) for SPEC 3.5's
    /// air (the atmosphere kernel), (0, 0) for none.
    pub density_scale: [Real; 2],
}

impl Sky {
    /// Resolves an `atmosphere` param set: the sun at azimuth 0, SPEC 3.5's air.
    pub fn from_params(p: &ParamSet) -> Sky {
        Sky {
            sun: sun_direction(real(p, "sun_elevation_deg")),
            camera_altitude: real(p, "camera_altitude_m"),
            sun_intensity: real(p, "sun_intensity"),
            mie_g: real(p, "mie_g"),
            view_samples: p.u32("view_samples"),
            light_samples: p.u32("light_samples"),
            density_scale: [1.0, 1.0],
        }
    }

    /// Densities (rho_R, rho_M) of this sky at altitude h.
    pub fn densities(&self, h: Real) -> [Real; 2] {
        let [r, m] = densities(h);
        [r * self.density_scale[0], m * self.density_scale[1]]
    }

    /// The camera's position (m), straight above the planet's centre at the
    /// origin: (0, R_GROUND + camera_altitude, 0).
    pub fn camera(&self) -> Vec3 {
        Vec3::new(0.0, R_GROUND + self.camera_altitude, 0.0)
    }

    /// Transmittance from p to the top of the atmosphere toward the sun
    /// (`light_samples` midpoint steps); 0 when the planet blocks the sun.
    pub fn sun_transmittance(&self, p: Vec3) -> [Real; 3] {
        if ray_sphere(p, self.sun, R_GROUND).is_some_and(|(_, t1)| t1 > 0.0) {
            return [0.0; 3];
        }
        let exit = ray_sphere(p, self.sun, R_TOP).map_or(0.0, |(_, t1)| t1.max(0.0));
        let [r, m] = column(p, self.sun, exit, self.light_samples);
        optical_depth_of([r * self.density_scale[0], m * self.density_scale[1]]).map(|t| (-t).exp())
    }

    /// The view segment [t_start, t_end] inside the atmosphere, None when the
    /// ray never enters it: entry into / exit from the top sphere, cut at the
    /// ground hit.
    pub fn view_segment(&self, dir: Vec3) -> Option<(Real, Real)> {
        let c = self.camera();
        let (a, b) = ray_sphere(c, dir, R_TOP)?;
        if b <= 0.0 {
            return None;
        }
        let mut end = b;
        // Camera above the ground: a hit ahead has both roots >= 0.
        let ground_ahead = ray_sphere(c, dir, R_GROUND).filter(|&(g0, g1)| g0 >= 0.0 && g1 > 0.0);
        if let Some((g0, _)) = ground_ahead {
            end = end.min(g0);
        }
        Some((a.max(0.0), end))
    }

    /// Radiance (RGB) arriving at the camera along the unit direction `dir`.
    pub fn radiance(&self, dir: Vec3) -> [Real; 3] {
        match self.view_segment(dir) {
            Some((t0, t1)) => self.segment(dir, t0, t1).0,
            None => [0.0; 3],
        }
    }

    /// (in-scattered radiance, transmittance) per channel of the part
    /// [t0, t1] (m) of the view ray along `dir`: the midpoint rule with
    /// `view_samples` steps, each step's light dimmed back to t0.
    pub fn segment(&self, dir: Vec3, t0: Real, t1: Real) -> ([Real; 3], [Real; 3]) {
        let c = self.camera();
        let mu = dir.dot(self.sun);
        let (pr, pm) = (rayleigh(mu), hg(mu, self.mie_g));
        let n = self.view_samples;
        let dt = (t1 - t0) / n as Real;
        let mut before = [0.0; 2]; // density integrals over the finished steps
        let mut sum = [0.0; 3];
        for i in 0..n {
            let p = c + (t0 + (i as Real + 0.5) * dt) * dir;
            let rho = self.densities(altitude(p));
            let to_mid =
                optical_depth_of([before[0] + 0.5 * dt * rho[0], before[1] + 0.5 * dt * rho[1]]);
            let sun = self.sun_transmittance(p);
            for k in 0..3 {
                let scatter = BETA_R[k] * rho[0] * pr + BETA_M * rho[1] * pm;
                sum[k] += (-to_mid[k]).exp() * scatter * sun[k];
            }
            before[0] += dt * rho[0];
            before[1] += dt * rho[1];
        }
        (sum.map(|s| self.sun_intensity * s * dt), optical_depth_of(before).map(|t| (-t).exp()))
    }
}

/// Unit vector toward the sun at azimuth 0: (0, sin e_s, cos e_s).
pub fn sun_direction(elevation_deg: Real) -> Vec3 {
    let (s, c) = elevation_deg.to_radians().sin_cos();
    Vec3::new(0.0, s, c)
}

/// Largest value of the phase functions in use: Rayleigh peaks at 3 / (8 pi),
/// HG at (1 + |g|) / (4 pi (1 - |g|)^2).
pub fn max_phase(g: Real) -> Real {
    let g = g.abs();
    (3.0 / (8.0 * PI)).max((1.0 + g) / (4.0 * PI * (1.0 - g) * (1.0 - g)))
}

/// The raw output (linear radiance) of the `atmosphere` kernel.
pub fn render(p: &ParamSet, width: u32, height: u32) -> Image {
    let sky = Sky::from_params(p);
    let fisheye = p.choice_in("projection", &[("latlong", false), ("fisheye", true)]);
    render_cpu(width, height, |u, v, _, _| {
        let dir = if fisheye { fisheye_direction(u, v, width, height) } else { Some(latlong_direction(u, v)) };
        let [r, g, b] = dir.map_or([0.0; 3], |d| sky.radiance(d));
        [r, g, b, 1.0]
    })
}
