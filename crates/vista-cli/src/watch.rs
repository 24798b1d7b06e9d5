//! `vista watch`: checks the cases once, then, each time a saved file
//! changes, re-checks the cases it reaches and rewrites the report, until
//! interrupted (or `--timeout`). A WGSL file reaches the cases whose
//! kernel imports it (or includes, prepends, appends it: the folders and
//! files a `[source]` names outside `shaders/` are watched too); a kernel
//! manifest its kernel's cases; `golden/` files
//! (cases, goldens) every case. Changes are found by polling the files'
//! hashes, so it needs no file-notification service and sees edits made by
//! any editor (atomic renames included).

use std::collections::BTreeMap;
use std::path::Path;
use std::time::{Duration, Instant};

use vista_check::{Checker, Filed, Run};
use vista_golden::{GoldenError, Store};
use vista_project::Project;
use vista_render::Renderer;

use crate::check::Terminal;
use crate::input::bad;

/// Every watched file under the root, by path relative to it, with the
/// hash of its bytes: `shaders/`, `kernels/`, `golden/cases.toml` and the
/// goldens, and `extra` (folders and files a `[source]` names).
fn snapshot(root: &Path, extra: &[String]) -> BTreeMap<String, String> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeMap<String, String>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, root, out);
            } else if let Ok(bytes) = std::fs::read(&p) {
                let rel = p.strip_prefix(root).unwrap_or(&p).to_string_lossy().replace('\\', "/");
                // Temp files of an atomic write are not changes yet.
                if !rel.rsplit('/').next().unwrap_or_default().starts_with('.') {
                    out.insert(rel, vista_golden::short_hash_bytes(&bytes));
                }
            }
        }
    }
    let mut out = BTreeMap::new();
    for d in ["shaders", "kernels", "golden"].into_iter().chain(extra.iter().map(String::as_str)) {
        let p = root.join(d);
        match p.is_file() {
            true => {
                if let Ok(bytes) = std::fs::read(&p) {
                    out.insert(d.to_string(), vista_golden::short_hash_bytes(&bytes));
                }
            }
            false => walk(&p, root, &mut out),
        }
    }
    out.remove("golden/manifest.toml");
    out
}

/// Runs the watch loop; `timeout` ends it (tests), else it runs until killed.
pub fn watch(
    project: &Project,
    config: &vista::Config,
    glob: Option<&str>,
    interval: Duration,
    timeout: Option<Duration>,
) -> Result<i32, GoldenError> {
    let root = project.require_root("vista watch")?.to_path_buf();
    let report_dir = project.report_dir().expect("a root");
    let shared = Renderer::shared(&config.gpu, project, config.limits)?;
    let start = Instant::now();
    let extra = vista_render::paths_outside_shaders(project)?;
    let mut seen = snapshot(&root, &extra);
    let mut filed: BTreeMap<String, Filed> = BTreeMap::new();
    // The first round checks every selected case.
    let mut changed: Option<Vec<String>> = None;
    loop {
        let store = Store::of_project(project, "vista watch")?;
        let cases = store.load_cases()?;
        let picked = vista_golden::select(&cases, glob)?;
        let manifest = store.manifest()?;
        let gpu = Renderer::new(shared.ctx, project, config.limits)?;
        let reached: Vec<&vista_golden::Case> = match &changed {
            None => picked.clone(),
            Some(files) => picked
                .iter()
                .copied()
                .filter(|c| {
                    files.iter().any(|f| {
                        f.starts_with("golden/")
                            || f == &format!("kernels/{}.toml", c.kernel.name())
                            || (f.starts_with("shaders/")
                                || extra.iter().any(|e| f == e || f.starts_with(&format!("{e}/"))))
                                && gpu
                                    .kernel_file_hashes(&c.kernel)
                                    .map(|h| h.contains_key(f.strip_prefix("shaders/").unwrap_or(f)))
                                    .unwrap_or(true)
                    })
                })
                .collect(),
        };
        if let Some(files) = &changed {
            println!(
                "changed: {} -> re-checking {} case{}",
                files.join(", "),
                reached.len(),
                if reached.len() == 1 { "" } else { "s" }
            );
        }
        let checker = Checker {
            ctx: &gpu,
            store: &store,
            manifest: &manifest,
            report_dir: &report_dir,
            detail: Default::default(),
            coverage: false,
        };
        let summary = vista_report::RunSummary {
            command: "vista watch".into(),
            backend: gpu.backend().to_string(),
            adapter: gpu.adapter_description(),
            ..Default::default()
        };
        let run = Run { checker, summary, results: Default::default(), shared: None };
        // Printed as `vista check` prints them (xfail, CRASH and all).
        for f in run.check(&reached, 1, &mut Terminal { report_dir: &report_dir, time: None }) {
            filed.insert(f.outcome.id.clone(), f);
        }
        // Cases no longer selected (renamed, deleted) leave the report, in case order.
        let all: Vec<Filed> = picked.iter().filter_map(|c| filed.get(&c.id).cloned()).collect();
        filed.retain(|id, _| picked.iter().any(|c| &c.id == id));
        let index = run.finish(&all)?;
        let failed = all.iter().filter(|f| !f.outcome.passed()).count();
        println!("{} passed, {failed} failed; report: {} (watching; Ctrl-C ends)", all.len() - failed, index.display());
        // Wait for the next change.
        loop {
            if timeout.is_some_and(|t| start.elapsed() >= t) {
                return Ok(0);
            }
            std::thread::sleep(interval);
            let now = snapshot(&root, &extra);
            if now != seen {
                let mut files: Vec<String> = now
                    .iter()
                    .filter(|(f, h)| seen.get(*f) != Some(h))
                    .map(|(f, _)| f.clone())
                    .chain(seen.keys().filter(|f| !now.contains_key(*f)).cloned())
                    .collect();
                files.sort();
                files.dedup();
                seen = now;
                changed = Some(files);
                break;
            }
        }
    }
}

/// `--interval MS`, checked.
pub fn interval(ms: u64) -> Result<Duration, GoldenError> {
    if !(50..=60_000).contains(&ms) {
        return Err(bad(format!("--interval {ms} is out of range; allowed: 50 to 60000 (milliseconds)")));
    }
    Ok(Duration::from_millis(ms))
}
