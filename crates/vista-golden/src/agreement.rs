//! The one GPU-vs-CPU comparison: the settings compared, the bound each
//! holds (`agreement.toml`, data), and how a setting's GPU render is set
//! beside the f64 reference (the heightfield compared where both found the
//! same surface, the landscape's reference shading the GPU's own terrain
//! hits). Used by `tests/agreement.rs` and by `vista mutate`'s reference
//! check, so both judge alike.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use serde::Deserialize;
use vista_image::Image;
use vista_kernels::{Kernel, Output, ParamSet};
use vista_render::Renderer;

/// Agreement of two raw images over all four channels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Agreement {
    /// PSNR with peak 1 (display kernels) or the reference's largest RGB
    /// value (HDR kernels, SPEC 5's rule); +inf when identical.
    pub psnr: f64,
    /// Largest absolute difference (+inf when either side is NaN).
    pub max_abs: f64,
}

/// `gpu` against `reference` (the CPU's raw output) for `kernel`.
pub fn agreement(kernel: &Kernel, gpu: &Image, reference: &Image) -> Agreement {
    let peak = match kernel.output() {
        Output::Display => 1.0,
        // The reference's own peak: HDR radiance, or a normalised view's max.
        Output::Hdr | Output::Normalize => {
            reference.data.iter().flat_map(|p| p[..3].iter()).fold(0.0f64, |m, v| m.max(*v as f64))
        }
    };
    let (mut se, mut max_abs) = (0.0f64, 0.0f64);
    for (g, c) in gpu.data.iter().zip(&reference.data) {
        for k in 0..4 {
            let d = (g[k] as f64 - c[k] as f64).abs();
            se += d * d;
            max_abs = if d.is_nan() { f64::INFINITY } else { max_abs.max(d) };
        }
    }
    let mse = se / (gpu.data.len() * 4) as f64;
    Agreement { psnr: if mse == 0.0 { f64::INFINITY } else { 10.0 * (peak * peak / mse).log10() }, max_abs }
}

/// One compared setting: a built-in kernel, a preset, overrides, a size.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Setting {
    /// Name of the built-in kernel rendered.
    pub kernel: String,
    /// The kernel preset the setting starts from.
    pub preset: String,
    /// Parameter overrides on top of the preset, by name (values as text).
    #[serde(default)]
    pub set: std::collections::BTreeMap<String, String>,
    /// Render size `[width, height]` in pixels.
    pub size: [u32; 2],
}

impl Setting {
    /// "kernel preset {overrides}", for messages.
    pub fn label(&self) -> String {
        format!("{} {} {:?}", self.kernel, self.preset, self.set)
    }

    fn params(&self, k: &Kernel, extra: &[(&str, &str)]) -> Result<ParamSet, String> {
        let mut set: Vec<(String, String)> = self
            .set
            .iter()
            .filter(|(n, _)| !extra.iter().any(|e| e.0 == *n))
            .map(|(n, v)| (n.clone(), v.clone()))
            .collect();
        set.extend(extra.iter().map(|(n, v)| (n.to_string(), v.to_string())));
        k.resolve(Some(&self.preset), &set).map_err(|e| format!("{}: {e}", self.label()))
    }
}

/// The least agreement a setting must reach.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct Bound {
    /// Least PSNR (dB) of the GPU render against the f64 reference.
    pub min_psnr: f64,
    /// Largest absolute difference allowed between GPU and reference values.
    pub max_abs: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct BoundRow {
    kernel: String,
    preset: Option<String>,
    backend: Option<String>,
    /// Overrides a setting must have (all of them) for the row to apply.
    #[serde(default)]
    set: std::collections::BTreeMap<String, String>,
    min_psnr: f64,
    max_abs: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Table {
    setting: Vec<Setting>,
    bound: Vec<BoundRow>,
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let text = include_str!("agreement.toml");
        toml::from_str(text)
            .unwrap_or_else(|e| panic!("agreement.toml: {}", vista_project::one_line_toml_error(text, &e)))
    })
}

/// Every compared setting, in file order.
pub fn settings() -> &'static [Setting] {
    &table().setting
}

/// The bound of a kernel's preset on a backend, without overrides: the
/// first row that matches.
pub fn bound(kernel: &str, preset: &str, backend: &str) -> Option<Bound> {
    bound_with(kernel, preset, &Default::default(), backend)
}

/// The bound of setting `s` on a backend: the first row whose kernel,
/// preset, backend and `set` overrides (all of them) match.
pub fn bound_of(s: &Setting, backend: &str) -> Option<Bound> {
    bound_with(&s.kernel, &s.preset, &s.set, backend)
}

fn bound_with(
    kernel: &str,
    preset: &str,
    set: &std::collections::BTreeMap<String, String>,
    backend: &str,
) -> Option<Bound> {
    table()
        .bound
        .iter()
        .find(|b| {
            b.kernel == kernel
                && b.preset.as_deref().is_none_or(|p| p == preset)
                && b.backend.as_deref().is_none_or(|x| x == backend)
                && b.set.iter().all(|(k, v)| set.get(k) == Some(v))
        })
        .map(|b| Bound { min_psnr: b.min_psnr, max_abs: b.max_abs })
}

/// A hit agrees with the oracle's when the depths (t / t_max) are within
/// 2e-5: 0.4 m at t_max = 20 km.
pub const DEPTH_TOL: f32 = 2e-5;

/// Share of pixels whose landscape terrain hit must agree with the oracle's
/// (within LANDSCAPE_DEPTH_TOL t); measured at 48 x 27 on lavapipe: seed,
/// dawn and overcast 96.5%, flythrough 93.7%.
pub const LANDSCAPE_HIT_PCT: f64 = 90.0;
const LANDSCAPE_DEPTH_TOL: f32 = 1e-3;

/// f64 references by what determines them, computed once per process: a
/// shader change alters only the GPU side, so fault loops and mutants
/// reuse them.
pub fn cpu_cached(key: String, make: impl FnOnce() -> Image) -> Image {
    static CACHE: OnceLock<Mutex<HashMap<String, Image>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(img) = cache.lock().expect("reference cache").get(&key) {
        return img.clone();
    }
    let img = make();
    cache.lock().expect("reference cache").insert(key, img.clone());
    img
}

/// The f64 reference of `p` at `w` x `h`, computed once per process.
pub fn reference(k: &Kernel, p: &ParamSet, w: u32, h: u32) -> Image {
    cpu_cached(format!("{} {} {w}x{h}", k.name(), p.canonical()), || k.reference(p, w, h))
}

/// One setting judged: its agreement, its bound, and why it breaks it.
#[derive(Debug, Clone)]
pub struct Judged {
    /// The GPU render's agreement with the f64 reference.
    pub agreement: Agreement,
    /// The bound from `agreement.toml` it is held to on this backend.
    pub bound: Bound,
    /// The figures, when the agreement is outside the bound.
    pub broken: Option<String>,
    /// Content hash of the GPU's raw render of the setting.
    pub gpu_hash: String,
}

/// Why a setting could not be judged.
#[derive(Debug, thiserror::Error)]
pub enum SettingError {
    /// A render failed (a GPU timeout among them).
    #[error("{setting}: {source}")]
    Render {
        /// The setting's label ([`Setting::label`]; with ` depth` appended for
        /// its depth-view render).
        setting: String,
        /// Why the render failed.
        source: vista_render::RenderError,
    },
    /// The setting is not judgeable: no bound, bad params, or terrain hits
    /// too far from the oracle's for shading to be compared.
    #[error("{0}")]
    Unjudgeable(String),
}

/// Renders a setting on `gpu`, sets it beside the f64 reference as the
/// agreement tests do, and judges it against its bound on `gpu`'s backend.
/// An error: the setting cannot be rendered, has no bound, or its terrain
/// hits disagree with the oracle's beyond what shading can be judged over.
pub fn judge_setting(gpu: &Renderer, s: &Setting) -> Result<Judged, SettingError> {
    let k = vista_kernels::find(&s.kernel).map_err(|e| SettingError::Unjudgeable(e.to_string()))?;
    let p = s.params(k, &[]).map_err(SettingError::Unjudgeable)?;
    let [w, h] = s.size;
    let mut g = vista_render::render(gpu, k, &p, w, h)
        .map_err(|source| SettingError::Render { setting: s.label(), source })?
        .into_raw();
    let gpu_hash = g.content_hash();
    let c = match s.kernel.as_str() {
        "landscape" => with_gpu_hits(gpu, k, s, &p)?,
        "heightfield" => {
            let mut c = reference(k, &p, w, h);
            masked_by_hits(gpu, k, s, &mut g, &mut c)?;
            c
        }
        _ => reference(k, &p, w, h),
    };
    let a = agreement(k, &g, &c);
    let bound = bound_of(s, gpu.backend()).ok_or_else(|| {
        SettingError::Unjudgeable(format!("agreement.toml has no bound for {} on {}", s.label(), gpu.backend()))
    })?;
    let broken = (a.psnr < bound.min_psnr || a.max_abs > bound.max_abs)
        .then(|| format!("{}: {:.1} dB, max abs {:.2e}", s.label(), a.psnr, a.max_abs));
    Ok(Judged { agreement: a, bound, broken, gpu_hash })
}

/// The GPU's and the oracle's depth views of a setting.
fn depths(gpu: &Renderer, k: &Kernel, s: &Setting) -> Result<(Image, Image), SettingError> {
    let p = s.params(k, &[("view", "depth")]).map_err(SettingError::Unjudgeable)?;
    let [w, h] = s.size;
    let gd = vista_render::render(gpu, k, &p, w, h)
        .map_err(|source| SettingError::Render { setting: format!("{} depth", s.label()), source })?
        .into_raw();
    Ok((gd, reference(k, &p, w, h)))
}

/// The landscape's f64 reference shading the GPU's own terrain hits
/// (decoded from its depth view), after checking that those hits agree with
/// the brute-force oracle's at LANDSCAPE_HIT_PCT of the pixels. So the
/// radiance bound judges shading and composition apart from the hit
/// search: 20 m ridges seen from 20 km alias, and a hit a few metres along
/// the ray can flip a soft shadow.
fn with_gpu_hits(gpu: &Renderer, k: &Kernel, s: &Setting, p: &ParamSet) -> Result<Image, SettingError> {
    let [w, h] = s.size;
    let (gd, cd) = depths(gpu, k, s)?;
    let same = gd
        .data
        .iter()
        .zip(&cd.data)
        .filter(|(a, b)| (a[0] < 1.0) == (b[0] < 1.0) && (a[0] - b[0]).abs() <= LANDSCAPE_DEPTH_TOL * b[0])
        .count();
    let pct = 100.0 * same as f64 / gd.data.len() as f64;
    if pct < LANDSCAPE_HIT_PCT {
        return Err(SettingError::Unjudgeable(format!(
            "{}: terrain hits agree at {pct:.1}% < {LANDSCAPE_HIT_PCT}%",
            s.label()
        )));
    }
    let hits: Vec<u32> = gd.data.iter().map(|px| px[0].to_bits()).collect();
    let hit_bytes: Vec<u8> = hits.iter().flat_map(|w| w.to_le_bytes()).collect();
    let key = format!("landscape at GPU hits {} {w}x{h} {}", p.canonical(), blake3::hash(&hit_bytes).to_hex());
    Ok(cpu_cached(key, || {
        let scene = vista_kernels::landscape::Landscape::from_params(p);
        let t_max = p.f64("t_max");
        vista_kernels::render_cpu(w, h, |_, _, x, y| {
            let z = gd.get(x, y)[0] as f64;
            scene.pixel_with_hit(x, y, w, h, (z < 1.0).then_some(z * t_max))
        })
    }))
}

/// Heightfield shading is compared where both sides found the same surface:
/// pixels whose hit differs from the brute-force oracle's (a crest taken on
/// its near or far side; the depth tests bound how many, at most 10% here)
/// are set equal.
fn masked_by_hits(gpu: &Renderer, k: &Kernel, s: &Setting, g: &mut Image, c: &mut Image) -> Result<(), SettingError> {
    let (gd, cd) = depths(gpu, k, s)?;
    let mut differ = 0;
    for i in 0..g.data.len() {
        let (a, b) = (gd.data[i][0], cd.data[i][0]);
        if (a < 1.0) != (b < 1.0) || (a - b).abs() > DEPTH_TOL {
            g.data[i] = c.data[i];
            differ += 1;
        }
    }
    if differ * 100 > g.data.len() * 10 {
        return Err(SettingError::Unjudgeable(format!("{}: {differ} pixels hit elsewhere than the oracle", s.label())));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_resolves_and_has_a_bound_on_every_backend() {
        assert!(settings().len() >= 20);
        for s in settings() {
            let k = vista_kernels::find(&s.kernel).unwrap();
            s.params(k, &[]).unwrap();
            for b in ["lavapipe", "swiftshader", "browser", "gpu"] {
                assert!(bound_of(s, b).is_some(), "{} on {b}", s.label());
            }
        }
        // First match wins: the flythrough's own row off lavapipe only.
        assert_eq!(bound("clouds", "flythrough", "lavapipe").unwrap().min_psnr, 110.0);
        assert_eq!(bound("clouds", "flythrough", "swiftshader").unwrap().min_psnr, 65.0);
        assert_eq!(bound("clouds", "cumulus", "swiftshader").unwrap().min_psnr, 75.0);
        // A row's overrides must all be the setting's.
        let low = settings().iter().find(|s| s.set.get("pitch_deg").is_some_and(|p| p == "5")).expect("a low view");
        assert_eq!(bound_of(low, "swiftshader").unwrap().min_psnr, 65.0);
        assert_eq!(bound_of(low, "lavapipe").unwrap().min_psnr, 110.0);
    }
}
