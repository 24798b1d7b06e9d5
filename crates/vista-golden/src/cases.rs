//! `golden/cases.toml`: the list of golden cases, one `[[case]]` table each.
//!
//! ```toml
//! [[case]]
//! id = "fbm-perlin-default"      # unique; becomes the test name
//! kernel = "fbm"
//! preset = "default"             # optional
//! set = { octaves = 4 }          # optional overrides (numbers, strings or vectors)
//! size = "256x256"               # optional, default 256x256
//! psnr_same_driver = 60.0        # optional thresholds (dB)
//! psnr_other_driver = 35.0
//! min_ssim = 0.99                # optional
//! max_flip = 0.01                # optional: mean LDR-FLIP error, in [0, 1]
//! max_bad_pixels = 25            # optional: pixels a channel of which differs by > 1/255
//! max_bad_ratio = 0.001          # optional: the same as a share of the pixels, in [0, 1]
//! ignore = [[0, 0, 16, 8]]       # optional: rectangles [x, y, w, h] the comparison leaves out
//! inputs = { photo = "inputs/other.png" }  # optional: a pass graph's resource files replaced
//! defs = { TONEMAP_METHOD_AGX = true }  # optional: shader defs over the kernel's, every pass
//! ```

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;
use vista_kernels::ParamSet;

use crate::GoldenError;

/// Image size (width, height) in pixels of a case without `size`.
pub const DEFAULT_SIZE: (u32, u32) = (256, 256);
/// `psnr_same_driver` (dB) of a case that does not set it.
pub const DEFAULT_PSNR_SAME_DRIVER: f64 = 60.0;
/// `psnr_other_driver` (dB) of a case that does not set it.
pub const DEFAULT_PSNR_OTHER_DRIVER: f64 = 35.0;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
    #[serde(default)]
    case: Vec<RawCase>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCase {
    id: String,
    kernel: String,
    preset: Option<String>,
    #[serde(default)]
    set: BTreeMap<String, toml::Value>,
    size: Option<String>,
    psnr_same_driver: Option<f64>,
    psnr_other_driver: Option<f64>,
    min_ssim: Option<f64>,
    max_flip: Option<f64>,
    max_bad_pixels: Option<u64>,
    max_bad_ratio: Option<f64>,
    #[serde(default)]
    ignore: Vec<[u32; 4]>,
    #[serde(default)]
    expect_fail: Vec<Expectation>,
    #[serde(default)]
    inputs: BTreeMap<String, toml::Value>,
    #[serde(default)]
    tolerances: BTreeMap<String, toml::Value>,
    #[serde(default)]
    defs: toml::Table,
    #[serde(default)]
    doc: String,
}

/// A case expected to fail on one implementation (SPEC 11), as data:
/// `expect_fail = [{ backend = "swiftshader", driver = "SwiftShader", reason = "why" }]`.
/// It matches when the backend is equal and the adapter description
/// contains `driver` (empty: any). An expected failure that passes fails.
/// With `unsupported = "feature"` it holds only where the case is reported
/// unsupported for lack of that feature (SPEC 14), not for any failure.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expectation {
    /// The backend it fails on: one of `EXPECTATION_BACKENDS`.
    pub backend: String,
    /// Substring of the adapter description it fails on; empty matches any.
    #[serde(default)]
    pub driver: String,
    /// Why it fails there (required, non-empty).
    pub reason: String,
    /// A feature whose lack is the expected failure; empty for any failure.
    #[serde(default)]
    pub unsupported: String,
}

impl Expectation {
    /// Whether this expectation applies to a run on `backend` whose adapter
    /// description is `adapter`.
    pub fn matches(&self, backend: &str, adapter: &str) -> bool {
        self.backend == backend && adapter.contains(&self.driver)
    }
}

/// The backends an expectation may name.
pub const EXPECTATION_BACKENDS: &[&str] = &["lavapipe", "swiftshader", "browser", "gpu"];

/// One validated golden case.
#[derive(Debug, Clone)]
pub struct Case {
    /// Unique id: the test name and the golden's file stem.
    pub id: String,
    /// The kernel the case renders.
    pub kernel: std::sync::Arc<vista_kernels::Kernel>,
    /// The kernel preset the case names, if any.
    pub preset: Option<String>,
    /// The case's `set` overrides as (name, value text), in name order.
    pub overrides: Vec<(String, String)>,
    /// The resolved parameters: kernel defaults, then the preset, then the overrides.
    pub params: ParamSet,
    /// Image width in pixels (256 unless `size` says otherwise).
    pub width: u32,
    /// Image height in pixels (256 unless `size` says otherwise).
    pub height: u32,
    /// Least PSNR (dB) against the golden when this run's adapter is the one it
    /// was blessed on.
    pub psnr_same_driver: f64,
    /// Least PSNR (dB) against the golden on any other adapter.
    pub psnr_other_driver: f64,
    /// Least SSIM against the golden, if any.
    pub min_ssim: Option<f64>,
    /// Largest mean LDR-FLIP error allowed (display values), if any.
    pub max_flip: Option<f64>,
    /// Most bad pixels allowed (a channel differs by more than 1/255), as a
    /// count and as a share of the pixels, if any; a case with either is
    /// judged by them instead of its PSNR threshold.
    pub max_bad_pixels: Option<u64>,
    /// Most bad pixels allowed as a share of the image's pixels, in [0, 1], if any.
    pub max_bad_ratio: Option<f64>,
    /// Rectangles `[x, y, w, h]` of the image the golden comparison leaves
    /// out (a watermark, a frame counter, a crest that flips across drivers).
    pub ignore: Vec<[u32; 4]>,
    /// Where this case is expected to fail, and why.
    pub expect_fail: Vec<Expectation>,
    /// A pass graph's resource files this case replaces: (resource, file
    /// under the project root).
    pub inputs: Vec<(String, String)>,
    /// Tolerances this case gives some outputs instead of their manifest's
    /// (`tolerances = { heights = { rmse = 0.002 } }`), by output name.
    pub tolerances: Vec<(String, vista_manifest::graph::Tolerance)>,
    /// What the case covers, in a few words (`doc` in cases.toml).
    pub doc: String,
}

impl Case {
    /// Golden PNG path relative to the golden dir: `<kernel>/<id>.png`.
    pub fn golden_rel_path(&self) -> String {
        format!("{}/{}.png", self.kernel.name(), self.id)
    }

    /// The `vista bless` command that (re)writes this case's golden: the
    /// same form as the one-for-all-failures command, valid in any project.
    pub fn bless_command(&self) -> String {
        bless_all_command(&[self.id.as_str()]).expect("one case")
    }
}

/// Parses and validates a case file. Errors name the file, the line (for
/// TOML syntax) or the case id and the bad value.
pub fn parse_cases(path: &Path, text: &str, kernels: &vista_kernels::Registry) -> Result<Vec<Case>, GoldenError> {
    let file: CaseFile = toml::from_str(text)
        .map_err(|e| GoldenError::Cases { path: path.display().to_string(), message: one_line_toml_error(text, &e) })?;
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    for raw in file.case {
        let bad = |message: String| GoldenError::Cases {
            path: path.display().to_string(),
            // Escaped: an id is not yet known to be printable.
            message: format!("case '{}': {message}", raw.id.escape_debug()),
        };
        if raw.id.is_empty() || !raw.id.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
            return Err(bad("id must be non-empty and use only letters, digits, '-' and '_'".into()));
        }
        if !seen.insert(raw.id.clone()) {
            return Err(bad("duplicate id".into()));
        }
        let kernel = kernels.find(&raw.kernel).map_err(|e| bad(e.to_string()))?;
        // A list for a scalar would be joined into one number: refused.
        for (k, v) in &raw.set {
            let scalar = kernel.params().iter().find(|p| &p.name == k).is_some_and(|p| {
                use vista_kernels::ParamType as T;
                matches!(p.ty, T::U32 | T::I32 | T::F32 | T::Bool | T::Enum)
            });
            if scalar && v.is_array() {
                return Err(bad(format!("set: {k} = {v} is a list, but {k} takes one value")));
            }
        }
        let overrides: Vec<(String, String)> =
            raw.set.iter().map(|(k, v)| (k.clone(), vista_manifest::values::value_text(v))).collect();
        let defs = vista_manifest::values::parse_defs(&raw.defs).map_err(bad)?;
        let params = kernel.resolve(raw.preset.as_deref(), &overrides).map_err(|e| bad(e.to_string()))?.with_defs(defs);
        let (width, height) = match &raw.size {
            Some(s) => vista_kernels::parse_size(s).map_err(|e| bad(e.to_string()))?,
            None => DEFAULT_SIZE,
        };
        let psnr_same_driver = raw.psnr_same_driver.unwrap_or(DEFAULT_PSNR_SAME_DRIVER);
        let psnr_other_driver = raw.psnr_other_driver.unwrap_or(DEFAULT_PSNR_OTHER_DRIVER);
        for (name, v) in [("psnr_same_driver", psnr_same_driver), ("psnr_other_driver", psnr_other_driver)] {
            if !(0.0..=200.0).contains(&v) {
                return Err(bad(format!("{name}={v} is out of range; allowed: [0, 200] dB")));
            }
        }
        if let Some(s) = raw.min_ssim
            && !(-1.0..=1.0).contains(&s)
        {
            return Err(bad(format!("min_ssim={s} is out of range; allowed: [-1, 1]")));
        }
        if let Some(f) = raw.max_flip
            && !(0.0..=1.0).contains(&f)
        {
            return Err(bad(format!("max_flip={f} is out of range; allowed: [0, 1] (mean FLIP error)")));
        }
        if let Some(r) = raw.max_bad_ratio
            && !(0.0..=1.0).contains(&r)
        {
            return Err(bad(format!("max_bad_ratio={r} is out of range; allowed: [0, 1] (a share of the pixels)")));
        }
        for r in &raw.ignore {
            let [x, y, w, h] = *r;
            let (iw, ih) = (width, height);
            if w == 0 || h == 0 || x.saturating_add(w) > iw || y.saturating_add(h) > ih {
                return Err(bad(format!(
                    "ignore = [{x}, {y}, {w}, {h}] is not valid; expected [x, y, w, h] with w, h >= 1 inside the \
                     {iw}x{ih} image (x + w <= {iw}, y + h <= {ih})"
                )));
            }
        }
        let inputs = case_inputs(kernel, &raw.inputs).map_err(bad)?;
        let mut tolerances = Vec::new();
        for (name, v) in &raw.tolerances {
            let outputs: Vec<&str> = kernel.graph().outputs.iter().filter_map(|o| o.resource.as_deref()).collect();
            if outputs.is_empty() {
                return Err(bad(format!(
                    "tolerances: kernel {} has no [[output]] tables; a case's tolerance overrides one of theirs",
                    kernel.name()
                )));
            }
            if !outputs.contains(&name.as_str()) {
                return Err(bad(format!("tolerances: {name} names no output; outputs: {}", outputs.join(", "))));
            }
            let t = vista_manifest::graph::parse_tolerance(v).map_err(|e| bad(format!("tolerances: {name}: {e}")))?;
            tolerances.push((name.clone(), t));
        }
        for x in &raw.expect_fail {
            if !EXPECTATION_BACKENDS.contains(&x.backend.as_str()) {
                return Err(bad(format!(
                    "expect_fail backend '{}' is not valid; expected one of {}",
                    x.backend,
                    EXPECTATION_BACKENDS.join("|")
                )));
            }
            if x.reason.trim().is_empty() {
                return Err(bad("expect_fail needs a reason that names the difference".into()));
            }
        }
        out.push(Case {
            id: raw.id,
            kernel: kernel.clone(),
            preset: raw.preset,
            overrides,
            params,
            width,
            height,
            psnr_same_driver,
            psnr_other_driver,
            min_ssim: raw.min_ssim,
            max_flip: raw.max_flip,
            max_bad_pixels: raw.max_bad_pixels,
            max_bad_ratio: raw.max_bad_ratio,
            ignore: raw.ignore,
            expect_fail: raw.expect_fail,
            inputs,
            tolerances,
            doc: raw.doc,
        });
    }
    Ok(out)
}

/// The one bless command for every failing case (globset alternation).
pub fn bless_all_command(failed: &[&str]) -> Option<String> {
    match failed {
        [] => None,
        [one] => Some(format!("vista bless --case '{one}'")),
        many => Some(format!("vista bless --case '{{{}}}'", many.join(","))),
    }
}

pub use vista_project::one_line_toml_error;

/// Reads the case file at `path` and validates it (see [`parse_cases`]).
pub fn load_cases(path: &Path, kernels: &vista_kernels::Registry) -> Result<Vec<Case>, GoldenError> {
    // golden/cases.toml: the project root is two folders up.
    let root = path.parent().and_then(Path::parent).unwrap_or(Path::new("."));
    let text = vista_project::guard::read_text(root, path)
        .map_err(|e| GoldenError::Cases { path: path.display().to_string(), message: e.message })?;
    parse_cases(path, &text, kernels)
}

/// Cases whose id matches the glob (all when `None`).
pub fn select<'a>(cases: &'a [Case], glob: Option<&str>) -> Result<Vec<&'a Case>, GoldenError> {
    let Some(pattern) = glob else {
        return Ok(cases.iter().collect());
    };
    let matcher = globset::Glob::new(pattern)
        .map_err(|e| GoldenError::BadInput(format!("--case '{pattern}' is not a valid glob: {e}")))?
        .compile_matcher();
    let picked: Vec<&Case> = cases.iter().filter(|c| matcher.is_match(&c.id)).collect();
    if picked.is_empty() {
        return Err(GoldenError::BadInput(format!(
            "--case '{pattern}' matches no case; valid ids: {}",
            cases.iter().map(|c| c.id.as_str()).collect::<Vec<_>>().join(", ")
        )));
    }
    Ok(picked)
}

/// A case's `inputs`: resource files replaced (`(name, path)`), and a
/// buffer's inline leaf values carried as [`vista_render::leaf_values::INLINE`]
/// JSON; the error says what is allowed.
fn case_inputs(
    kernel: &vista_kernels::Kernel,
    raw: &BTreeMap<String, toml::Value>,
) -> Result<Vec<(String, String)>, String> {
    let mut inline: Vec<(String, String)> = Vec::new();
    if !raw.is_empty() {
        let g = kernel.graph();
        if g.resources.is_empty() {
            return Err(format!(
                "inputs: kernel {} has no [[resource]] files to replace (a pass graph's inputs)",
                kernel.name()
            ));
        }
        for (name, value) in raw {
            let Some(r) = g.resources.iter().find(|r| &r.name == name) else {
                let names: Vec<&str> = g.resources.iter().map(|r| r.name.as_str()).collect();
                return Err(format!("inputs: {name} names no resource; resources: {}", names.join(", ")));
            };
            // A buffer's leaf values inline: carried as JSON among the files.
            let file = match value {
                toml::Value::String(f) => f.clone(),
                toml::Value::Table(t) if r.kind_name() == "buffer" => {
                    let json = serde_json::to_string(t).map_err(|e| format!("inputs: {name}: {e}"))?;
                    inline.push((name.clone(), format!("{}{json}", vista_render::leaf_values::INLINE)));
                    continue;
                }
                other => {
                    return Err(format!(
                        "inputs: {name} = {other} is not valid; expected a file path (or, for a buffer, a table \
                         of leaf values {{ \"view.exposure\" = 2.0 }})"
                    ));
                }
            };
            let file = &file;
            let want: &[&str] = match r.kind_name() {
                "texture" => &[".png", ".exr"],
                "depth" => &[".npy", ".exr"],
                "buffer" => &[".npy", ".bin", ".toml", ".json"],
                _ => &[],
            };
            if file.starts_with('/') || file.split(['/', '\\']).any(|c| c == "..") {
                return Err(format!("inputs: {name} = \"{file}\" must be a path under the project root"));
            }
            if !want.iter().any(|e| file.ends_with(e)) {
                return Err(format!(
                    "inputs: {name} = \"{file}\" is not valid for a {}; expected a {} file",
                    r.kind_name(),
                    if want.is_empty() { "(none: a sampler has no file)".to_string() } else { want.join(" or ") }
                ));
            }
        }
    }
    Ok(raw.iter().filter_map(|(n, v)| v.as_str().map(|f| (n.clone(), f.to_string()))).chain(inline).collect())
}
