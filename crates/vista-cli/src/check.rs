//! `vista check` on one backend: selection, the cases, the report,
//! results.json, JUnit and pending renders.

use std::path::{Path, PathBuf};

use vista::Config;
use vista_golden::{CheckOptions, GoldenError, Store};
use vista_gpu::Context;
use vista_project::Project;
use vista_render::Renderer;

use crate::bad;
use crate::render::check_parent_writable;

/// Which cases a check runs: `--case`, then `--changed`, `--failed`,
/// `--partition` (each narrows the one before).
pub struct Pick {
    pub glob: Option<String>,
    pub changed: bool,
    pub failed: bool,
    pub partition: Option<(u64, u64)>,
    /// Orphaned goldens warn instead of failing.
    pub allow_orphans: bool,
    /// Cases checked at once (`--jobs`).
    pub jobs: usize,
}

/// Machine-readable results a check also writes.
pub struct Results {
    pub junit: Option<PathBuf>,
    pub json: Option<PathBuf>,
}

/// A results file's directory must exist and be writable, before any GPU work.
fn check_results_path(flag: &str, path: &Path) -> Result<(), GoldenError> {
    if path.is_dir() {
        return Err(bad(format!("{flag} {} is a directory; expected a file path", path.display())));
    }
    check_parent_writable(path).map_err(|e| bad(format!("{flag} {}: {e}", path.display())))
}

/// A case's status line (`ok`, `xfail`, `FAIL`; the value it was judged
/// by; a per-backend golden named), and for a failure its explanation.
fn print_case(o: &vista_golden::Outcome, report_dir: &Path) {
    let label = match o.verdict {
        vista_golden::Verdict::Pass => "ok",
        vista_golden::Verdict::ExpectedFail => "xfail",
        _ => "FAIL",
    };
    let per_backend = match o.golden_file.rsplit_once('@') {
        Some((_, b)) => format!("  [golden @{}]", b.trim_end_matches(".png")),
        None => String::new(),
    };
    println!("{label:<6} {:<40} {:<17} {:>8.1} ms{per_backend}", o.id, o.headline(), o.gpu_ms);
    if !o.passed() {
        print!("{}", o.explain(report_dir));
    } else if o.verdict == vista_golden::Verdict::ExpectedFail {
        o.notes.iter().for_each(|n| println!("  note: {n}"));
    }
}

/// GitHub Actions `::error` annotations of the failing cases, with paths
/// relative to the working directory, where the workflow runs.
fn annotate(store: &Store, outcomes: &[vista_golden::Outcome]) {
    let cases = store.cases_path();
    let shown = std::env::current_dir()
        .ok()
        .and_then(|cwd| cases.strip_prefix(&cwd).ok().map(Path::to_path_buf))
        .unwrap_or_else(|| cases.clone());
    let text = std::fs::read_to_string(&cases).unwrap_or_default();
    for line in vista_report::github_annotations(outcomes, &shown.display().to_string(), &text) {
        println!("{line}");
    }
}

/// Narrows `picked` (the cases `--case` matches) by `--changed`,
/// `--failed` and `--partition`, in that order, and says so. Needs no
/// device: hashes from the project's WGSL, the last report.
fn narrow(
    project: &Project,
    pick: &Pick,
    manifest: &vista_golden::Manifest,
    report_dir: &Path,
    picked: &mut Vec<&vista_golden::Case>,
) -> Result<(), GoldenError> {
    let all = picked.len();
    let mut why: Vec<String> = Vec::new();
    if pick.changed {
        let shaders = vista_render::shader_set(project)?;
        picked.retain(|c| {
            // Every file any pass reaches, as the manifest records them.
            let mut files = std::collections::BTreeMap::new();
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
    if !why.is_empty() {
        println!("selected {} of {all} cases ({})", picked.len(), why.join(", "));
    }
    Ok(())
}

pub fn check(
    project: &Project,
    config: &Config,
    pick: &Pick,
    report_dir: Option<PathBuf>,
    results: Results,
    viewers: vista_report::Detail,
) -> Result<i32, GoldenError> {
    if let Some(p) = &results.junit {
        check_results_path("--junit", p)?;
    }
    if let Some(p) = &results.json {
        check_results_path("--json", p)?;
    }
    let store = Store::of_project(project, "vista check")?;
    let cases = store.load_cases()?;
    let mut picked = vista_golden::select(&cases, pick.glob.as_deref())?;
    let manifest = store.manifest()?;
    let report_dir = match report_dir {
        Some(d) => d,
        None => project.report_dir().expect("a store implies a root"),
    };
    narrow(project, pick, &manifest, &report_dir, &mut picked)?;
    let ctx = &Renderer::new(Context::shared(&config.gpu)?, project, config.limits)?;
    vista_report::clear_case_folders(&report_dir)?;
    let opts = CheckOptions { twice: false };
    let mut outcomes = Vec::new();
    let mut pending = std::collections::BTreeMap::new();
    let mut time = Phases::start(ctx);
    // The validation layer's messages are collected process-wide: one case
    // at a time, so each is attributed to the dispatch that caused it.
    let jobs = if ctx.validating() { 1 } else { pick.jobs.clamp(1, picked.len().max(1)) };
    time.jobs = jobs;
    // Outcomes come back in case order; the device serialises the workers'
    // GPU runs while the others plan, judge and write their report folder.
    vista_golden::in_order(
        &picked,
        jobs,
        |case| {
            let started = std::time::Instant::now();
            let mut checked = vista_golden::check_case(ctx, &store, &manifest, case, &opts);
            let case_time = started.elapsed();
            let entry = checked.pending.take();
            let started = std::time::Instant::now();
            let o = vista_report::file_case(&report_dir, checked, viewers);
            (o, entry, case_time, started.elapsed())
        },
        |_, (o, entry, case_time, report_time)| {
            time.cases += case_time;
            time.report += report_time;
            time.gpu += std::time::Duration::from_secs_f64(o.gpu_ms / 1000.0);
            // A failing or missing case's render, as bless --from-report may take it.
            if let Some(mut entry) = entry
                && matches!(o.verdict, vista_golden::Verdict::Fail | vista_golden::Verdict::Missing)
            {
                // A graph whose first output is a buffer has no main PNG.
                let png = match o.files.actual {
                    Some(_) => std::fs::read(vista_golden::pending::pending_png(&report_dir, &o.id))
                        .ok()
                        .map(|bytes| vista_golden::short_hash_bytes(&bytes)),
                    None => Some(String::new()),
                };
                if let Some(hash) = png {
                    entry.golden_hash = hash;
                    pending.insert(o.id.clone(), entry);
                }
            }
            print_case(&o, &report_dir);
            outcomes.push(o);
        },
    );
    let run = vista_report::RunSummary {
        command: command_line(),
        backend: ctx.backend().to_string(),
        adapter: ctx.adapter_description(),
        pending: pending.keys().cloned().collect(),
        accept_from: report_dir.display().to_string(),
    };
    let started = std::time::Instant::now();
    let index = vista_report::write_report(&report_dir, &run, &outcomes)?;
    time.report += started.elapsed();
    let accept = (!pending.is_empty()).then(|| format!("vista bless --from-report {}", report_dir.display()));
    vista_golden::pending::write_pending(&report_dir, pending)?;
    // results.json beside the report: what `check --failed` reads next time.
    let json_text = serde_json::to_string_pretty(&vista_report::json_results(&run, &outcomes)).expect("JSON values");
    vista_image::atomic_write(&report_dir.join("results.json"), json_text.as_bytes())?;
    if let Some(p) = &results.junit {
        vista_image::atomic_write(p, vista_report::junit_xml(&run, &outcomes, &report_dir)?.as_bytes())?;
    }
    if let Some(p) = &results.json {
        vista_image::atomic_write(p, json_text.as_bytes())?;
    }
    if config.github_actions {
        annotate(&store, &outcomes);
    }
    let failing: Vec<&str> = outcomes.iter().filter(|o| !o.passed()).map(|o| o.id.as_str()).collect();
    let failed = failing.len();
    println!("{} passed, {} failed", outcomes.len() - failed, failed);
    // Goldens no case refers to: a renamed or deleted case left them behind.
    let orphans = store.orphans(&cases);
    for o in &orphans {
        println!(
            "{}: golden with no case: {} (delete it, or vista bless --prune)",
            if pick.allow_orphans { "warning" } else { "FAIL" },
            o.display()
        );
    }
    let orphans_fail = !orphans.is_empty() && !pick.allow_orphans;
    if orphans_fail {
        println!(
            "{} orphaned golden{} fail the check (--allow-orphans makes them a warning)",
            orphans.len(),
            if orphans.len() == 1 { "" } else { "s" }
        );
    }
    if let Some(cmd) = vista_golden::bless_all_command(&failing) {
        println!("failed: {}", failing.join(", "));
        println!("if every change is intended, after reviewing the report: {cmd}");
        if let Some(accept) = &accept {
            println!(
                "or accept exactly what this run rendered (on another machine too, from this report folder): {accept}"
            );
        }
    }
    println!("{}", time.summary(ctx, outcomes.len()));
    println!("report: {}", index.display());
    Ok(if failed == 0 && !orphans_fail { 0 } else { 1 })
}

/// Where a check's wall time went: compiling (composing WGSL, creating
/// pipelines), the GPU runs, the rest of each case (planning, the CPU's
/// part of running it, judging), and writing the report.
struct Phases {
    started: std::time::Instant,
    compile0: std::time::Duration,
    cases: std::time::Duration,
    gpu: std::time::Duration,
    report: std::time::Duration,
    /// Cases checked at once: the phases then add up to more than the wall time.
    jobs: usize,
}

impl Phases {
    fn start(ctx: &Renderer) -> Phases {
        Phases {
            started: std::time::Instant::now(),
            compile0: ctx.compile_time() + ctx.shaders.compose_time(),
            cases: Default::default(),
            gpu: Default::default(),
            report: Default::default(),
            jobs: 1,
        }
    }

    /// One line: `time: 9.52 s for 74 cases: compiling 2.10 s (22%), ...`.
    fn summary(&self, ctx: &Renderer, cases: usize) -> String {
        let total = self.started.elapsed().as_secs_f64();
        let compile = (ctx.compile_time() + ctx.shaders.compose_time()).saturating_sub(self.compile0).as_secs_f64();
        let gpu = self.gpu.as_secs_f64();
        let rest = (self.cases.as_secs_f64() - compile - gpu).max(0.0);
        let report = self.report.as_secs_f64();
        let share = |t: f64| format!("{t:.2} s ({:.0}%)", 100.0 * t / total.max(1e-9));
        // With cases checked at once the other phases overlap the GPU runs
        // (and include waiting for the device), so only their sums are given.
        if self.jobs > 1 {
            return format!(
                "time: {total:.2} s for {cases} case{}, {} at once: GPU runs {}, the rest of the wall time {:.0}%; \
                 summed over the workers: compiling {compile:.2} s, planning and judging {rest:.2} s (waiting for the \
                 device included), report {report:.2} s{}",
                if cases == 1 { "" } else { "s" },
                self.jobs,
                share(gpu),
                100.0 * (total - gpu).max(0.0) / total.max(1e-9),
                if ctx.backend() == "browser" { " (the browser compiles inside its runs)" } else { "" }
            );
        }
        format!(
            "time: {total:.2} s for {cases} case{}: compiling {}, GPU runs {}, planning and judging {}, report {}{}",
            if cases == 1 { "" } else { "s" },
            share(compile),
            share(gpu),
            share(rest),
            share(report),
            if ctx.backend() == "browser" { " (the browser compiles inside its runs)" } else { "" }
        )
    }
}

/// This process's command line as a user would type it again (`vista` and
/// its arguments, quoted where the shell would need it), for reports.
fn command_line() -> String {
    let quote = |a: String| {
        if !a.is_empty() && a.chars().all(|c| c.is_ascii_alphanumeric() || "-_=./:,@+".contains(c)) {
            a
        } else {
            format!("'{}'", a.replace('\'', "'\\''"))
        }
    };
    std::iter::once("vista".to_string()).chain(std::env::args().skip(1).map(quote)).collect::<Vec<_>>().join(" ")
}
