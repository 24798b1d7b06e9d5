//! Which cases a run checks ([`Pick`], [`select`]), where its report goes
//! by default, and the goldens no case refers to ([`orphans`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use vista_golden::{Case, GoldenError, Manifest, Store};
use vista_project::Project;

/// Which cases a check runs: `glob` (`--case`), then `--changed`,
/// `--failed` and `--partition`, each narrowing the one before.
#[derive(Debug, Clone, Default)]
pub struct Pick {
    /// Only cases whose id matches this glob.
    pub glob: Option<String>,
    /// Only cases whose params, WGSL or golden changed since the last bless.
    pub changed: bool,
    /// Only cases that failed in the last report.
    pub failed: bool,
    /// Only partition K of N (1-based).
    pub partition: Option<(u64, u64)>,
}

/// The cases `pick` selects from `cases`, and when it narrowed by more than
/// the glob, the line saying so (`selected 3 of 77 cases (--changed)`).
/// Needs no device: hashes from the project's WGSL, the last report in
/// `report_dir`.
pub fn select<'c>(
    project: &Project,
    cases: &'c [Case],
    manifest: &Manifest,
    pick: &Pick,
    report_dir: &Path,
) -> Result<(Vec<&'c Case>, Option<String>), GoldenError> {
    let mut picked = vista_golden::select(cases, pick.glob.as_deref())?;
    let all = picked.len();
    // The project's WGSL, read once, where a case's defs or --changed need it.
    let with_defs = picked.iter().any(|c| !c.params.defs().is_empty());
    let shaders = (with_defs || pick.changed).then(|| vista_render::shader_set(project)).transpose()?;
    // A def a case sets that no shader reads is refused before any case runs.
    if let Some(shaders) = shaders.as_ref().filter(|_| with_defs) {
        for c in picked.iter().filter(|c| !c.params.defs().is_empty()) {
            vista_render::check_case_defs(shaders, &c.kernel, &c.params)
                .map_err(|e| GoldenError::BadInput(format!("case {}: {e}", c.id)))?;
        }
    }
    let mut why: Vec<String> = Vec::new();
    if let Some(shaders) = shaders.as_ref().filter(|_| pick.changed) {
        picked.retain(|c| {
            // Every file any pass reaches, as the manifest records them.
            let mut files = BTreeMap::new();
            for f in c.kernel.shader_units() {
                files.extend(shaders.file_hashes(&f).unwrap_or_default());
            }
            vista_golden::selection::change(c, manifest, &files).is_some()
        });
        why.push("--changed".into());
    }
    if pick.failed {
        let failures = vista_golden::selection::last_failures(report_dir)?;
        picked.retain(|c| failures.contains(&c.id));
        why.push("--failed".into());
    }
    if let Some(part) = pick.partition {
        picked.retain(|c| vista_golden::selection::in_partition(&c.id, part));
        why.push(format!("--partition {}/{}", part.0, part.1));
    }
    let line = (!why.is_empty()).then(|| format!("selected {} of {all} cases ({})", picked.len(), why.join(", ")));
    Ok((picked, line))
}

/// Where a run on `backend` writes its report unless told otherwise: the
/// project's `target/vista-report/` on lavapipe, `target/vista-report-<backend>/`
/// on another backend, with `-validation` under the validation layer, so
/// that checking a second backend (or the same one validated) does not
/// overwrite the first's report.
pub fn default_report_dir(project: &Project, backend: &str, validate: bool) -> Option<PathBuf> {
    let root = project.root()?;
    Some(match (backend, validate) {
        ("lavapipe", false) => project.report_dir()?,
        (b, false) => root.join(format!("target/vista-report-{b}")),
        (b, true) => root.join(format!("target/vista-report-{b}-validation")),
    })
}

/// Goldens no case refers to (a renamed or deleted case left them behind).
pub fn orphans(store: &Store, cases: &[Case]) -> Vec<PathBuf> {
    store.orphans(cases)
}
