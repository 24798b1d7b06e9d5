//! The `clouds` kernel's reference (SPEC 3.6), written from the formulas in
//! `crate::clouds`; built in f64 (the oracle) and f32.

use super::geometry::{Camera, V3, add, direction, dot, scale, smoothstep, sub};
use super::noise::{Fbm, Noise};
use super::phase::dual_hg;
use super::{Real, pixel_uv, real, real3, render_cpu};
use crate::ParamSet;
use crate::clouds::{Integrator, Jitter, JitterSteps, Layer, Profile, layer_of};
use crate::noise::pcg3d;
use vista_image::Image;

/// A ray stops once its transmittance falls below this; the remainder is
/// then treated as fully opaque (T = 0), which keeps T monotone in density.
pub const T_CUTOFF: Real = 1e-4;
/// The light march stops once the optical depth toward the sun exceeds this
/// (T_sun < 1.1e-7: no visible contribution left).
pub const TAU_SUN_CUTOFF: Real = 16.0;

/// A sky direction counts as cloudy when its optical depth exceeds this
/// (transmittance below 0.905: visibly cloud, SPEC's oktas calibration).
pub const OKTA_TAU: Real = 0.1;
/// The planet's radius (km) under a shell layer: the atmosphere's ground.
pub const PLANET_RADIUS_KM: Real = super::atmosphere::R_GROUND / 1000.0;
/// 1 / golden ratio, (sqrt 5 - 1) / 2: the golden-ratio step offsets.
const INV_PHI: f64 = 0.618_033_988_749_894_9;
/// Midpoint samples per sky direction in [`Clouds::sky_cover`].
pub const OKTA_SAMPLES: u32 = 96;

/// The coverage a parameter set asks for: `coverage` itself, or with
/// `coverage_oktas` = n >= 0 the preset's calibrated coverage for n oktas
/// (0 for none; `okta_coverage_low` holds 1-4, `okta_coverage_high` 5-8).
/// The WGSL looks the same table up.
pub fn coverage_of(p: &ParamSet) -> Real {
    match p.int("coverage_oktas") {
        n if n < 0 => real(p, "coverage"),
        0 => 0.0,
        n @ 1..=4 => p.vector("okta_coverage_low")[n as usize - 1] as Real,
        n => p.vector("okta_coverage_high")[n as usize - 5] as Real,
    }
}

/// remap(x, a, b, c, d) = c + (x - a)(d - c)/(b - a); with b == a (no
/// interval) it is the step c below and d above a. Clouds only use it with
/// a = 1 - coverage, b = 1, so coverage 0 gives c = 0 for every G <= 1.
pub fn remap(x: Real, a: Real, b: Real, c: Real, d: Real) -> Real {
    if b == a {
        return if x > a { d } else { c };
    }
    c + (x - a) * (d - c) / (b - a)
}

/// Height profile in [0, 1] of the normalised height h in the slab:
/// a plateau smoothstep(0, bottom, h) * smoothstep(0, top, 1 - h), times
/// 1 for stratiform, (1 - 0.5 h) for cumuliform (dense base, thinner top),
/// and 0.45 + 0.55 smoothstep(0.5, 0.7, h) for anvil (a dense band in the
/// upper part, the anvil of a cumulonimbus).
pub fn height_profile(profile: Profile, bottom: Real, top: Real, h: Real) -> Real {
    let h = h.clamp(0.0, 1.0);
    let plateau = smoothstep(0.0, bottom, h) * smoothstep(0.0, top, 1.0 - h);
    plateau
        * match profile {
            Profile::Stratiform => 1.0,
            Profile::Cumuliform => 1.0 - 0.5 * h,
            Profile::Anvil => 0.45 + 0.55 * smoothstep(0.5, 0.7, h),
        }
}

/// Interleaved gradient noise (Jimenez 2014) at pixel (x, y) in [0, 1);
/// the seed shifts the pattern by 5.588238 pixels per step (period 64).
// The published constants; the f32 build rounds them as the WGSL does.
#[allow(clippy::excessive_precision)]
pub fn ign(x: u32, y: u32, seed: u32) -> Real {
    let shift = 5.588238 * (seed % 64) as Real;
    let (px, py) = (x as Real + shift, y as Real + shift);
    let inner = (0.06711056 * px + 0.00583715 * py).fract();
    (52.9829189 * inner).fract()
}

/// White-noise jitter in [0, 1): pcg3d of (x, y, seed), top 24 bits.
pub fn white(x: u32, y: u32, seed: u32) -> Real {
    (pcg3d([x, y, seed])[0] >> 8) as Real / 16_777_216.0
}

/// (1 - exp(-x)) / x, the analytic integrator's weight per unit dt; 1 at 0.
pub fn analytic_weight(x: Real) -> Real {
    if x <= 0.0 { 1.0 } else { -(-x).exp_m1() / x }
}

/// (first step as a fraction of the light path, growth ratio) for `n`
/// light steps whose last step is `spread` times the first.
pub fn light_step_layout(n: u32, spread: Real) -> (Real, Real) {
    if n <= 1 || spread == 1.0 {
        return (1.0 / n as Real, 1.0);
    }
    let log_r = spread.ln() / (n - 1) as Real;
    // (r - 1) / (r^n - 1) via expm1: exact as r -> 1.
    ((log_r).exp_m1() / (n as Real * log_r).exp_m1(), log_r.exp())
}

/// Where the primary steps of a ray end, as fractions of its segment: the
/// first k of n steps growing geometrically (last / first = spread) end at
/// (r^k - 1) / (r^n - 1), r = spread^(1 / (n - 1)); k / n when uniform.
#[derive(Debug, Clone, Copy)]
pub struct StepLayout {
    n: u32,
    log_r: Real,
    total: Real,
}

impl StepLayout {
    /// The layout of `n` steps whose last is `spread` times the first (1: uniform).
    pub fn new(n: u32, spread: Real) -> StepLayout {
        let log_r = spread.ln() / (n.max(2) - 1) as Real;
        StepLayout { n, log_r, total: (n as Real * log_r).exp_m1() }
    }

    /// Fraction of the segment covered by the first `k` steps.
    pub fn end(&self, k: u32) -> Real {
        if self.log_r == 0.0 { k as Real / self.n as Real } else { (k as Real * self.log_r).exp_m1() / self.total }
    }
}

/// The roots t0 <= t1 of t^2 + 2 b t + c = 0, where the unit ray q + t d
/// meets a sphere around the origin (b = q . d, c = |q|^2 - r^2); `None`
/// when it misses. The root of larger magnitude comes first, the other from
/// t0 t1 = c, so neither is a difference of near-equal numbers.
pub fn sphere_roots(b: Real, c: Real) -> Option<(Real, Real)> {
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let far = -b - if b >= 0.0 { disc.sqrt() } else { -disc.sqrt() };
    let near = if far == 0.0 { 0.0 } else { c / far };
    Some((far.min(near), far.max(near)))
}

/// One marched ray.
#[derive(Debug, Clone)]
pub struct RayResult {
    /// In-scattered radiance L_cloud (not including the background).
    pub radiance: V3,
    /// Transmittance T of the whole ray (0 after the cutoff).
    pub transmittance: Real,
    /// Transmittance after each step (filled when asked for).
    pub trace: Vec<Real>,
    /// Density evaluations (primary and light samples): the cost.
    pub density_evals: u32,
}

/// Everything the march needs, resolved from a parameter set in Real.
#[derive(Debug, Clone)]
pub struct Clouds {
    /// Slab or shell geometry.
    pub layer: Layer,
    /// x and z of the shell's centre (the camera's): it lies at
    /// (x, -[`PLANET_RADIUS_KM`], z).
    pub centre_xz: [Real; 2],
    /// Altitude of the layer's bottom (km).
    pub base: Real,
    /// Altitude of the layer's top (km), above `base`.
    pub top: Real,
    /// Coverage in [0, 1]: cloud where G exceeds 1 - coverage (about the cloud
    /// fraction; from `coverage_oktas` when that is set, see [`coverage_of`]).
    pub coverage: Real,
    /// Extinction (1/km) where the remapped noise and the height profile are 1.
    pub density_scale: Real,
    /// sigma_a / sigma_s: sigma_t = (1 + absorption) sigma_s (0: pure scattering).
    pub absorption: Real,
    /// The height profile.
    pub profile: Profile,
    /// Rounding of the profile at the base, as a fraction of the layer's thickness.
    pub profile_bottom: Real,
    /// Rounding of the profile at the top, as a fraction of the layer's thickness.
    pub profile_top: Real,
    /// Noise frequency per axis: noise_scale * noise_stretch.
    pub frequency: V3,
    /// Offset added in noise space, after `frequency` (animate it to move the clouds).
    pub wind: V3,
    /// The density's 3D fBm octaves (no octave rotation).
    pub fbm: Fbm,
    /// The fBm's seeded basis.
    pub noise: Noise,
    /// 1 / A, A the fBm's amplitude sum: scales fbm3 to about [-1, 1].
    pub inv_amplitude: Real,
    /// Position and basis; the aspect is set per image in [`Clouds::ray`].
    pub view: Camera,
    /// Rays and light rays are cut at this distance (km).
    pub max_distance: Real,
    /// Unit direction toward the sun (azimuth from +z toward +x, elevation above the horizon).
    pub sun_dir: V3,
    /// sun_color * sun_intensity.
    pub sun: V3,
    /// Asymmetry g of the first (forward) Henyey-Greenstein lobe, in [-0.99, 0.99].
    pub g1: Real,
    /// Asymmetry g of the second (backward) Henyey-Greenstein lobe, in [-0.99, 0.99].
    pub g2: Real,
    /// Weight of the g2 lobe: P = (1 - blend) HG(g1) + blend HG(g2).
    pub blend: Real,
    /// Powder term strength: sun light times (1 - powder exp(-2 tau_sun)); 0 = off.
    pub powder: Real,
    /// Isotropic sky radiance scattered by the cloud (linear RGB).
    pub ambient: V3,
    /// Ambient factor at the layer's base, rising linearly to 1 at its top.
    pub ambient_bottom: Real,
    /// Background sky radiance straight up (linear RGB).
    pub sky_zenith: V3,
    /// Background sky radiance at and below the horizon (linear RGB).
    pub sky_horizon: V3,
    /// Primary march steps per ray (with `step_km` > 0, the most a ray takes).
    pub steps: u32,
    /// Light march steps toward the sun from each sample that holds cloud.
    pub light_steps: u32,
    /// Last light step / first light step (1 = uniform).
    pub light_spread: Real,
    /// Last primary step / first (1 = uniform).
    pub step_spread: Real,
    /// Primary step length (km); 0 = always `steps` steps.
    pub step_km: Real,
    /// Where in its step each primary sample sits.
    pub jitter_steps: JitterSteps,
    /// How each step's in-scattering is integrated.
    pub integrator: Integrator,
    /// The per-pixel first-sample offset.
    pub jitter: Jitter,
    /// Seed of the jitter hash (white: hashed; ign: shifts the pattern, period 64).
    pub jitter_seed: u32,
}

/// What a kernel gives its clouds besides the `cloud` group's params: the
/// camera, the sun, the sky behind, and the per-pixel jitter.
#[derive(Debug, Clone)]
pub struct CloudFrame {
    /// The camera (its position also centres the shell).
    pub view: Camera,
    /// Unit direction toward the sun.
    pub sun_dir: V3,
    /// Sun radiance (unused by the landscape, which lights through the atmosphere).
    pub sun: V3,
    /// Background sky straight up.
    pub sky_zenith: V3,
    /// Background sky at and below the horizon.
    pub sky_horizon: V3,
    /// The per-pixel first-sample offset.
    pub jitter: Jitter,
    /// Seed of the jitter hash.
    pub jitter_seed: u32,
}

impl Clouds {
    /// Resolves a `clouds` param set (angles in degrees become radians).
    ///
    /// # Panics
    /// If `layer` names no [`Layer`] (`CloudsKernel::check` refuses that).
    pub fn from_params(p: &ParamSet) -> Clouds {
        // pitch is within +-89 deg, so forward is never vertical.
        let forward = direction(real(p, "yaw_deg").to_radians(), real(p, "pitch_deg").to_radians());
        let frame = CloudFrame {
            view: Camera::looking(real3(p, "camera_pos"), forward, real(p, "fov_deg"), 1.0),
            sun_dir: direction(real(p, "sun_azimuth_deg").to_radians(), real(p, "sun_elevation_deg").to_radians()),
            sun: real3(p, "sun_color").map(|c| c * real(p, "sun_intensity")),
            sky_zenith: real3(p, "sky_zenith"),
            sky_horizon: real3(p, "sky_horizon"),
            jitter: p.choice_in("jitter", crate::clouds::JITTERS),
            jitter_seed: p.u32("jitter_seed"),
        };
        // As clouds.wgsl: the group's coverage, unless coverage_oktas picks one.
        Clouds { coverage: coverage_of(p), ..Clouds::from_group(p, frame) }
    }

    /// The layer from the params of the kernel's `cloud` group (the WGSL
    /// `CloudParams` its uniform holds, `[[group]] field = "cloud"` in its
    /// manifest): the one constructor of the clouds and landscape kernels.
    /// Each leaf is read from the param the manifest's group rule names.
    ///
    /// # Panics
    /// If the kernel's manifest has no `cloud` group or the layer is not a
    /// [`Layer`] (the kernels' `check` refuses that).
    pub fn from_group(p: &ParamSet, frame: CloudFrame) -> Clouds {
        let group = crate::clouds::cloud_group(p.kernel());
        let name = |leaf: &str| group.param(leaf, |n| p.value(n).is_some());
        let r = |leaf: &str| real(p, &name(leaf));
        let fbm = Fbm { octaves: p.u32(&name("octaves")), lacunarity: r("lacunarity"), gain: r("gain"), theta: 0.0 };
        let ns = r("noise_scale");
        let camera = frame.view.pos;
        Clouds {
            layer: layer_of(p, &name("layer")).expect("the kernel's check refuses other layers"),
            centre_xz: [camera[0], camera[2]],
            base: r("base_km"),
            top: r("top_km"),
            coverage: r("coverage"),
            density_scale: r("density_scale"),
            absorption: r("absorption"),
            profile: p.choice_in(&name("profile"), crate::clouds::PROFILES),
            profile_bottom: r("profile_bottom"),
            profile_top: r("profile_top"),
            frequency: real3(p, &name("noise_stretch")).map(|s| s * ns),
            wind: real3(p, &name("wind_offset")),
            fbm,
            noise: Noise::new(p.choice_in(&name("basis"), crate::noise::BASES), p.u32(&name("seed"))),
            inv_amplitude: 1.0 / fbm.amplitude_sum(),
            view: frame.view,
            max_distance: r("max_distance_km"),
            sun_dir: frame.sun_dir,
            sun: frame.sun,
            g1: r("forward_g"),
            g2: r("backward_g"),
            blend: r("phase_blend"),
            powder: r("powder"),
            ambient: real3(p, &name("ambient")),
            ambient_bottom: r("ambient_bottom"),
            sky_zenith: frame.sky_zenith,
            sky_horizon: frame.sky_horizon,
            steps: p.u32(&name("steps")),
            light_steps: p.u32(&name("light_steps")),
            light_spread: r("light_spread"),
            step_spread: r("step_spread"),
            step_km: r("step_km"),
            jitter_steps: p.choice_in(&name("jitter_steps"), crate::clouds::JITTER_STEPS),
            integrator: p.choice_in(&name("integrator"), crate::clouds::INTEGRATORS),
            jitter: frame.jitter,
            jitter_seed: frame.jitter_seed,
        }
    }

    /// Normalised height in the layer of the altitude y (unclamped).
    pub fn height01(&self, y: Real) -> Real {
        (y - self.base) / (self.top - self.base)
    }

    /// The altitude that places p in the layer: p.y for the slab; for the
    /// shell |q| - R, q = p - centre, written (|q|^2 - R^2) / (|q| + R) with
    /// |q|^2 - R^2 = x^2 + z^2 + y (y + 2R) so the f32 build does not lose
    /// it to the cancellation of two squares near R^2.
    pub fn altitude(&self, p: V3) -> Real {
        match self.layer {
            Layer::Slab => p[1],
            Layer::Shell => {
                let (x, z) = (p[0] - self.centre_xz[0], p[2] - self.centre_xz[1]);
                let r = PLANET_RADIUS_KM;
                let above = x * x + z * z + p[1] * (p[1] + 2.0 * r);
                above / ((x * x + z * z + (p[1] + r) * (p[1] + r)).sqrt() + r)
            }
        }
    }

    /// Where the ray o + t d (unit d) meets the sphere of altitude h around
    /// the shell's centre (radius R + h), as [`sphere_roots`].
    pub fn sphere_hits(&self, o: V3, d: V3, h: Real) -> Option<(Real, Real)> {
        let r = PLANET_RADIUS_KM;
        let q = sub(o, [self.centre_xz[0], -r, self.centre_xz[1]]);
        // |q|^2 - (R + h)^2 with the large terms factored out.
        let c = q[0] * q[0] + q[2] * q[2] + (o[1] - h) * (o[1] + h + 2.0 * r);
        sphere_roots(dot(q, d), c)
    }

    /// The density d(p) (1/km), i.e. sigma_s.
    pub fn density(&self, p: V3) -> Real {
        let h = self.height01(self.altitude(p));
        if !(0.0..=1.0).contains(&h) {
            return 0.0;
        }
        let profile = height_profile(self.profile, self.profile_bottom, self.profile_top, h);
        if profile <= 0.0 || self.coverage <= 0.0 {
            return 0.0;
        }
        let q = [0, 1, 2].map(|i| p[i] * self.frequency[i] + self.wind[i]);
        let g = 0.5 + 0.5 * self.fbm.eval3(&self.noise, q) * self.inv_amplitude;
        let shape = remap(g, 1.0 - self.coverage, 1.0, 0.0, 1.0).max(0.0);
        self.density_scale * profile * shape
    }

    /// The camera ray through the centre of pixel (x, y).
    pub fn ray(&self, x: u32, y: u32, width: u32, height: u32) -> (V3, V3) {
        let (u, v) = pixel_uv(x, y, width, height);
        let camera = Camera { aspect: width as Real / height as Real, ..self.view };
        (camera.pos, camera.ray(u, v))
    }

    /// Background sky: horizon + (zenith - horizon) * clamp(d.y, 0, 1).
    pub fn background(&self, d: V3) -> V3 {
        let t = d[1].clamp(0.0, 1.0);
        [0, 1, 2].map(|i| self.sky_horizon[i] + (self.sky_zenith[i] - self.sky_horizon[i]) * t)
    }

    /// Part [t0, t1] of the ray o + t d inside the layer and within
    /// max_distance, or None. For the shell, the first such part: a ray
    /// from above the layer that dips into the inner sphere and leaves it
    /// again (past the limb) keeps only its first crossing.
    pub fn layer_segment(&self, o: V3, d: V3) -> Option<(Real, Real)> {
        if self.layer == Layer::Shell {
            let (out0, out1) = self.sphere_hits(o, d, self.top).filter(|&(_, t1)| t1 > 0.0)?;
            let (mut t0, mut t1) = (out0.max(0.0), out1);
            if let Some((in0, in1)) = self.sphere_hits(o, d, self.base).filter(|&(_, t1)| t1 > 0.0) {
                if in0 <= t0 {
                    // Starting inside the inner sphere: the layer begins where the ray leaves it.
                    t0 = t0.max(in1);
                } else {
                    t1 = t1.min(in0);
                }
            }
            let t1 = t1.min(self.max_distance);
            return (t1 > t0).then_some((t0, t1));
        }
        let (t0, t1) = if d[1].abs() < 1e-6 {
            if o[1] < self.base || o[1] > self.top {
                return None;
            }
            (0.0, self.max_distance)
        } else {
            let ta = (self.base - o[1]) / d[1];
            let tb = (self.top - o[1]) / d[1];
            (ta.min(tb).max(0.0), ta.max(tb).min(self.max_distance))
        };
        (t1 > t0).then_some((t0, t1))
    }

    /// Light-march steps grow geometrically so the last is `light_spread`
    /// times the first: ratio r = spread^(1 / (n - 1)), first step a
    /// fraction (r - 1) / (r^n - 1) of the path (1 / n when spread = 1).
    /// Short steps near the sample resolve the self-shadowing that dominates
    /// the look; the far part of the path matters less once light is
    /// attenuated. As n grows every step shrinks, so it converges to the
    /// same integral as uniform steps.
    pub fn light_step_layout(&self) -> (Real, Real) {
        light_step_layout(self.light_steps, self.light_spread)
    }

    /// Optical depth from p toward the sun to the slab's top (midpoint rule
    /// on `light_steps` geometrically growing steps, cut at max_distance
    /// and at TAU_SUN_CUTOFF). A point below the slab (the ground, for a
    /// cloud shadow) starts where its sun ray enters the slab.
    pub fn sun_optical_depth(&self, p: V3) -> Real {
        self.sun_march(p).0
    }

    /// (optical depth toward the sun, density evaluations spent).
    fn sun_march(&self, p: V3) -> (Real, u32) {
        let s = self.sun_dir;
        // From where the sun ray enters the layer (p itself inside it) to its top.
        let (p, len) = match self.layer {
            Layer::Slab => {
                let p = add(p, scale(s, ((self.base - p[1]) / s[1]).max(0.0)));
                (p, (self.top - p[1]) / s[1])
            }
            Layer::Shell => {
                // Below the base p is inside the inner sphere, which the sun ray leaves at its far root.
                let start = match self.sphere_hits(p, s, self.base) {
                    Some((t0, t1)) if t0 <= 0.0 && t1 > 0.0 => t1,
                    _ => 0.0,
                };
                let exit = self.sphere_hits(p, s, self.top).map_or(0.0, |(_, t1)| t1);
                (add(p, scale(s, start)), exit - start)
            }
        };
        let len = len.clamp(0.0, self.max_distance);
        let (first, growth) = self.light_step_layout();
        let mut dt = len * first;
        let mut t = 0.0;
        let mut tau = 0.0;
        let mut evals = 0;
        for _ in 0..self.light_steps {
            let q = add(p, scale(s, t + 0.5 * dt));
            tau += self.density(q) * (1.0 + self.absorption) * dt;
            evals += 1;
            if tau > TAU_SUN_CUTOFF {
                break;
            }
            t += dt;
            dt *= growth;
        }
        (tau, evals)
    }

    /// Dual-lobe HG phase for the cosine mu between view ray and sun.
    pub fn phase(&self, mu: Real) -> Real {
        dual_hg(mu, self.g1, self.g2, self.blend)
    }

    /// Jitter xi in [0, 1) of pixel (x, y); 0.5 (midpoint) without jitter.
    pub fn jitter_offset(&self, x: u32, y: u32) -> Real {
        match self.jitter {
            Jitter::None => 0.5,
            Jitter::White => white(x, y, self.jitter_seed),
            Jitter::Ign => ign(x, y, self.jitter_seed),
        }
    }

    /// Marches the ray o + t d with first-sample offset `xi` (in steps).
    /// With `trace`, records the transmittance after every step.
    pub fn march(&self, o: V3, d: V3, xi: Real, trace: bool) -> RayResult {
        match self.layer_segment(o, d) {
            Some((t0, t1)) => self.march_segment(o, d, t0, t1, xi, self.sun, trace),
            None => RayResult { radiance: [0.0; 3], transmittance: 1.0, trace: Vec::new(), density_evals: 0 },
        }
    }

    /// Primary steps over a segment [t0, t1]: `steps`, or with step_km > 0
    /// ceil((t1 - t0) / step_km) clamped to 1..=steps.
    pub fn primary_steps(&self, t0: Real, t1: Real) -> u32 {
        if self.step_km > 0.0 {
            ((t1 - t0) / self.step_km).ceil().clamp(1.0, self.steps as Real) as u32
        } else {
            self.steps
        }
    }

    /// The mean over the image's pixels of steps x (1 + light_steps) x
    /// octaves per ray (0 for a ray that misses the slab): the manifest's
    /// work estimate evaluated ray by ray, which step_km makes vary.
    pub fn mean_work(&self, width: u32, height: u32) -> Real {
        let mut sum = 0.0;
        for y in 0..height {
            for x in 0..width {
                let (o, d) = self.ray(x, y, width, height);
                if let Some((t0, t1)) = self.layer_segment(o, d) {
                    sum += self.primary_steps(t0, t1) as Real;
                }
            }
        }
        sum * (1 + self.light_steps) as Real * self.fbm.octaves as Real / (width * height) as Real
    }

    /// Marches [t0, t1] of the ray o + t d in `steps` steps, lit by `sun`
    /// (radiance from sun_dir; step_km > 0: [`Self::primary_steps`] steps). The steps are equal, or with step_spread > 1
    /// grow geometrically from t0 so the last is step_spread times the
    /// first; each sample sits `xi` of its step in, or with jitter_steps
    /// golden fract(xi + k / phi) in step k.
    #[allow(clippy::too_many_arguments)]
    pub fn march_segment(&self, o: V3, d: V3, t0: Real, t1: Real, xi: Real, sun: V3, trace: bool) -> RayResult {
        let mut out = RayResult { radiance: [0.0; 3], transmittance: 1.0, trace: Vec::new(), density_evals: 0 };
        let n = self.primary_steps(t0, t1);
        let layout = StepLayout::new(n, self.step_spread);
        let dt_uniform = (t1 - t0) / n as Real;
        let phase = self.phase(dot(d, self.sun_dir));
        let ext = 1.0 + self.absorption;
        let mut t_view = 1.0;
        for k in 0..n {
            let xk = match self.jitter_steps {
                JitterSteps::Shared => xi,
                JitterSteps::Golden => (xi + k as Real * INV_PHI as Real).fract(),
            };
            // Uniform steps at t0 + (k + xk) dt, as before the layout existed
            // (the same rounding, which the f32 build's precision test sees).
            let (t, dt) = if self.step_spread == 1.0 {
                (t0 + (k as Real + xk) * dt_uniform, dt_uniform)
            } else {
                let (a, b) = (layout.end(k), layout.end(k + 1));
                (t0 + (t1 - t0) * (a + xk * (b - a)), (t1 - t0) * (b - a))
            };
            let p = add(o, scale(d, t));
            let sigma_s = self.density(p);
            out.density_evals += 1;
            if sigma_s > 0.0 {
                let (tau_sun, evals) = self.sun_march(p);
                out.density_evals += evals;
                let sun_vis = (-tau_sun).exp() * (1.0 - self.powder * (-2.0 * tau_sun).exp());
                let amb =
                    self.ambient_bottom + (1.0 - self.ambient_bottom) * self.height01(self.altitude(p)).clamp(0.0, 1.0);
                let x = sigma_s * ext * dt;
                // Riemann: S dt; analytic: S (1 - exp(-x)) / sigma_t.
                let w = match self.integrator {
                    Integrator::Riemann => dt,
                    Integrator::Analytic => dt * analytic_weight(x),
                };
                for (c, sun_c) in sun.iter().enumerate() {
                    let l_in = sun_c * phase * sun_vis + self.ambient[c] * amb;
                    out.radiance[c] += t_view * sigma_s * l_in * w;
                }
                t_view *= (-x).exp();
                if t_view < T_CUTOFF {
                    t_view = 0.0;
                }
            }
            if trace {
                out.trace.push(t_view);
            }
            if t_view == 0.0 {
                break;
            }
        }
        out.transmittance = t_view;
        out
    }

    /// Optical depth (extinction) of the ray o + t d through the layer, by
    /// the midpoint rule with `samples` steps over its layer segment.
    pub fn optical_depth(&self, o: V3, d: V3, samples: u32) -> Real {
        let Some((ext, dt, densities)) = self.depth_samples(o, d, samples) else { return 0.0 };
        densities.sum::<Real>() * ext * dt
    }

    /// (1 + absorption, dt, the densities at the `samples` midpoints of the
    /// ray's slab segment in order); `None` off the slab.
    fn depth_samples(&self, o: V3, d: V3, samples: u32) -> Option<(Real, Real, impl Iterator<Item = Real> + '_)> {
        let (t0, t1) = self.layer_segment(o, d)?;
        let dt = (t1 - t0) / samples as Real;
        let densities = (0..samples).map(move |k| self.density(add(o, scale(d, t0 + (k as Real + 0.5) * dt))));
        Some((1.0 + self.absorption, dt, densities))
    }

    /// Whether [`Self::optical_depth`] exceeds `tau`, stopping at the first
    /// sample that settles it. The terms are >= 0 and are added in the same
    /// order, and rounding is monotone, so a partial sum over `tau` implies
    /// the full one is: the answer is the full sum's, at a fraction of the
    /// work under cloud.
    pub fn optical_depth_exceeds(&self, o: V3, d: V3, samples: u32, tau: Real) -> bool {
        let Some((ext, dt, mut densities)) = self.depth_samples(o, d, samples) else { return 0.0 > tau };
        let mut sum = 0.0;
        densities.any(|x| {
            sum += x;
            sum * ext * dt > tau
        })
    }

    /// Cloud amount as an observer at the camera counts it: the fraction of
    /// sky directions whose optical depth exceeds [`OKTA_TAU`]. The sky is
    /// the upper hemisphere in `n` x `n` cells of equal solid angle (azimuth
    /// uniform, sin(elevation) uniform, one ray through each cell's centre),
    /// less the directions that do not reach the layer within
    /// max_distance_km (near the horizon under a high layer): no cloud can
    /// show there in this render, whatever the coverage.
    pub fn sky_cover(&self, n: u32) -> Real {
        use rayon::prelude::*;
        let o = self.view.pos;
        // (directions reaching the layer, cloudy ones) per elevation row, on all cores.
        let (sky, cloudy) = (0..n)
            .into_par_iter()
            .map(|i| {
                let sin_e = (i as Real + 0.5) / n as Real;
                let cos_e = (1.0 - sin_e * sin_e).sqrt();
                let (mut sky, mut cloudy) = (0u32, 0u32);
                for j in 0..n {
                    let az = 2.0 * super::consts::PI * (j as Real + 0.5) / n as Real;
                    let d = [cos_e * az.sin(), sin_e, cos_e * az.cos()];
                    if self.layer_segment(o, d).is_none() {
                        continue;
                    }
                    sky += 1;
                    if self.optical_depth_exceeds(o, d, OKTA_SAMPLES, OKTA_TAU) {
                        cloudy += 1;
                    }
                }
                (sky, cloudy)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        if sky == 0 { 0.0 } else { cloudy as Real / sky as Real }
    }

    /// Final pixel value: (L + T * background, 1 - T).
    pub fn pixel(&self, x: u32, y: u32, width: u32, height: u32) -> [Real; 4] {
        let (o, d) = self.ray(x, y, width, height);
        let r = self.march(o, d, self.jitter_offset(x, y), false);
        let bg = self.background(d);
        let t = r.transmittance;
        [r.radiance[0] + t * bg[0], r.radiance[1] + t * bg[1], r.radiance[2] + t * bg[2], 1.0 - t]
    }

    /// Largest in-scattered radiance per unit sigma_s, for output_bounds.
    pub fn max_l_in(&self) -> Real {
        let p_max = self.phase(1.0).max(self.phase(-1.0));
        let sun = self.sun.iter().cloned().fold(0.0, Real::max);
        let amb = self.ambient.iter().cloned().fold(0.0, Real::max);
        sun * p_max + amb
    }
}

/// The raw output (linear radiance, alpha = 1 - T) of the `clouds` kernel.
pub fn render(p: &ParamSet, width: u32, height: u32) -> Image {
    let c = Clouds::from_params(p);
    render_cpu(width, height, |_, _, x, y| c.pixel(x, y, width, height))
}
