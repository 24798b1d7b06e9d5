//! The golden store: `golden/<kernel>/<case>.png` plus `golden/manifest.toml`
//! recording, per case, how and where each golden was made.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::{Case, GoldenError};

/// The run's side of the provenance, beside the golden's manifest entry.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct RunInfo {
    /// The backend name this run renders on, as reports and manifests name it
    /// (`lavapipe`, `swiftshader`, `gpu`, ...).
    pub backend: String,
    /// The adapter description (`name | driver driver_info | backend | device
    /// type`), compared with the golden's to pick the PSNR threshold.
    pub adapter: String,
    /// Hash of the case's kernel, size and resolved parameters ([`params_hash`](crate::params_hash)).
    pub params_hash: String,
    /// Hash of the WGSL the kernel reaches now (`unavailable: ...` when it
    /// cannot be computed).
    pub shader_hash: String,
}

/// Provenance of one golden at bless time.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ManifestEntry {
    /// The case's kernel name.
    pub kernel: String,
    /// Image size as `<width>x<height>` in pixels.
    pub size: String,
    /// Hash of the case's canonical resolved parameters.
    pub params_hash: String,
    /// Hash of the kernel's WGSL file and the lib modules it reaches
    /// through `#import` (see `ShaderSet::source_hash`).
    pub shader_hash: String,
    /// Hash of each WGSL file the kernel reaches (path relative to
    /// `shaders/`), so that a check names the files that changed.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub shader_files: BTreeMap<String, String>,
    /// Adapter name | driver | backend | device type.
    pub adapter: String,
    /// lavapipe | swiftshader | browser | gpu ("" in entries that predate it).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub backend: String,
    /// When the golden was blessed: UTC, RFC 3339 to the second.
    pub date: String,
    /// Hash of the raw f32 output bits: a later render on the same adapter
    /// and shader must reproduce it exactly (determinism across processes).
    pub raw_hash: String,
    /// PSNR of this golden against the one it replaced ("new" if none).
    pub psnr_vs_previous: String,
    /// Hash of the golden PNG's bytes: the file this entry describes.
    #[serde(default)]
    pub golden_hash: String,
    /// While a bless replaces this golden: the hash of the file being
    /// replaced ("none" for a new golden). Written before the golden and
    /// cleared after it, so the file on disk always matches the entry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replacing: Option<String>,
    /// A pass graph's other golden files (`<case>.<output>.png`, `.exr`,
    /// `.npy`; a first output's `.exr` or `.npy`), by file name, with the
    /// hash of their bytes.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub outputs: BTreeMap<String, String>,
}

impl ManifestEntry {
    /// Whether `run` renders what this entry's bless rendered: the same
    /// adapter, shader and params, so a deterministic kernel must
    /// reproduce `raw_hash` bit for bit.
    pub(crate) fn same_inputs(&self, run: &RunInfo) -> bool {
        (&self.adapter, &self.shader_hash, &self.params_hash) == (&run.adapter, &run.shader_hash, &run.params_hash)
    }

    /// The entry a bless of one render of `case` writes, dated now: this
    /// run's provenance, the hash of each WGSL file the kernel reaches, the
    /// raw output's hash, the PSNR against the golden it replaces and the
    /// hash of the PNG's bytes.
    pub fn of_render(
        case: &Case,
        run: &RunInfo,
        shader_files: BTreeMap<String, String>,
        raw_hash: String,
        psnr_vs_previous: String,
        golden_hash: String,
    ) -> ManifestEntry {
        ManifestEntry {
            kernel: case.kernel.name().to_string(),
            size: format!("{}x{}", case.width, case.height),
            params_hash: run.params_hash.clone(),
            shader_hash: run.shader_hash.clone(),
            shader_files,
            adapter: run.adapter.clone(),
            backend: run.backend.clone(),
            date: crate::now_utc(),
            raw_hash,
            psnr_vs_previous,
            golden_hash,
            replacing: None,
            outputs: BTreeMap::new(),
        }
    }
}

/// `golden/manifest.toml`: the provenance of every golden.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct Manifest {
    /// Entries by case id, or `<case>@<backend>` for a per-backend golden.
    #[serde(default)]
    pub case: BTreeMap<String, ManifestEntry>,
}

/// A golden directory and the kernels its cases may name.
#[derive(Debug, Clone)]
pub struct Store {
    /// The golden directory (`golden/` under the project root).
    pub dir: PathBuf,
    /// The project's kernels, which the case file's kernel names resolve against.
    pub kernels: vista_kernels::Registry,
}

impl Store {
    /// The project's `golden/`; a project without a root has no store, and
    /// the error says what `command` looked for and from where.
    pub fn of_project(project: &vista_project::Project, command: &str) -> Result<Store, GoldenError> {
        let dir = project.require_root(command)?.join("golden");
        let kernels = vista_kernels::Registry::of_project(project).map_err(|e| GoldenError::BadInput(e.to_string()))?;
        Ok(Store { dir, kernels })
    }

    /// `golden/cases.toml`: the case file.
    pub fn cases_path(&self) -> PathBuf {
        self.dir.join("cases.toml")
    }

    /// `golden/manifest.toml`: the manifest.
    pub fn manifest_path(&self) -> PathBuf {
        self.dir.join("manifest.toml")
    }

    /// `golden/<kernel>/<case>.png`: the case's own golden.
    pub fn golden_path(&self, case: &Case) -> PathBuf {
        self.dir.join(case.golden_rel_path())
    }

    /// `golden/<kernel>/<case>@<backend>.png`: a per-backend golden.
    pub fn backend_golden_path(&self, case: &Case, backend: &str) -> PathBuf {
        self.dir.join(case.kernel.name()).join(format!("{}@{backend}.png", case.id))
    }

    /// The golden a run on `backend` is judged against, and the manifest key
    /// of its entry: the per-backend golden `<case>@<backend>.png` where one
    /// exists (key `<case>@<backend>`), else the case's own.
    pub fn golden_for(&self, case: &Case, backend: &str) -> (PathBuf, String) {
        let own = self.backend_golden_path(case, backend);
        match own.is_file() {
            true => (own, format!("{}@{backend}", case.id)),
            false => (self.golden_path(case), case.id.clone()),
        }
    }

    /// Reads and validates `golden/cases.toml` against the store's kernels.
    pub fn load_cases(&self) -> Result<Vec<Case>, GoldenError> {
        crate::load_cases(&self.cases_path(), &self.kernels)
    }

    /// The manifest; empty if the file does not exist yet.
    pub fn manifest(&self) -> Result<Manifest, GoldenError> {
        let path = self.manifest_path();
        let io = |message: String| GoldenError::Io { path: path.display().to_string(), message };
        match vista_project::guard::read_regular(&path, vista_project::guard::MAX_TEXT_BYTES) {
            Ok(Some(bytes)) => {
                let text = String::from_utf8(bytes).map_err(|_| io("is not UTF-8 text".into()))?;
                toml::from_str(&text).map_err(|e| GoldenError::Cases {
                    path: path.display().to_string(),
                    message: format!("malformed manifest: {}", crate::cases::one_line_toml_error(&text, &e)),
                })
            }
            Ok(None) => Ok(Manifest::default()),
            Err(e) => Err(io(e.message)),
        }
    }

    /// Writes the manifest atomically, under a do-not-edit header.
    pub fn write_manifest(&self, m: &Manifest) -> Result<(), GoldenError> {
        let text = format!(
            "# Written by `vista bless`: provenance of every golden. Do not edit by hand.\n\n{}",
            toml::to_string_pretty(m).map_err(|e| GoldenError::BadInput(format!("manifest encode: {e}")))?
        );
        vista_image::atomic_write(&self.manifest_path(), text.as_bytes())?;
        Ok(())
    }

    /// Golden files on disk (PNG, EXR, NumPy) that no case refers to: a
    /// file of `golden/<kernel>/` belongs to a case of that kernel when its
    /// name is the case id up to the first '.' (ids have none), so a pass
    /// graph's `<case>.<output>.npy` belongs to its case.
    pub fn orphans(&self, cases: &[Case]) -> Vec<PathBuf> {
        let known: std::collections::HashSet<(String, String)> =
            cases.iter().map(|c| (c.kernel.name().to_string(), c.id.clone())).collect();
        let mut out = Vec::new();
        let Ok(kernels) = std::fs::read_dir(&self.dir) else {
            return out;
        };
        for k in kernels.flatten().filter(|e| e.path().is_dir()) {
            let Ok(files) = std::fs::read_dir(k.path()) else {
                continue;
            };
            for f in files.flatten() {
                let p = f.path();
                let kernel = k.file_name().to_string_lossy().to_string();
                // `<id>.<output>.npy`, `<id>@<backend>.png`: the id ends at the first '.' or '@'.
                let id = f.file_name().to_string_lossy().split(['.', '@']).next().unwrap_or_default().to_string();
                let golden_kind = p.extension().is_some_and(|e| e == "png" || e == "npy" || e == "exr");
                if golden_kind && !known.contains(&(kernel, id)) {
                    out.push(p);
                }
            }
        }
        out.sort();
        out
    }
}

/// Params hash as recorded in the manifest.
pub fn params_hash(case: &Case) -> String {
    crate::short_hash(&format!("{}|{}x{}|{}", case.kernel.name(), case.width, case.height, case.params.canonical()))
}

/// Whether a run is on the driver that blessed the case's golden (no golden
/// yet counts as the same), and the PSNR threshold that follows: the one
/// place that chooses between a case's same-driver and other-driver
/// thresholds (SPEC 4, 11). Buffers take their cross-driver allowance from
/// the same choice ([`crate::outputs::effective_tolerance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriverThreshold {
    /// The adapter and driver are the bless-time ones.
    pub same_driver: bool,
    /// The case's PSNR threshold for that.
    pub psnr: f64,
}

impl DriverThreshold {
    /// The threshold for `case` run on `adapter`, against its manifest `entry`.
    pub fn of(case: &Case, entry: Option<&ManifestEntry>, adapter: &str) -> DriverThreshold {
        let same_driver = entry.is_none_or(|e| e.adapter == adapter);
        let psnr = if same_driver { case.psnr_same_driver } else { case.psnr_other_driver };
        DriverThreshold { same_driver, psnr }
    }
}
