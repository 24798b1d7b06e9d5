//! `vista check` on one backend: selection, the cases, the report,
//! results.json, JUnit and pending renders.

use std::path::{Path, PathBuf};

use vista::Config;
use vista_check::{Checker, Filed, Results, Run};
use vista_golden::{GoldenError, Store};
use vista_project::Project;
use vista_render::Renderer;

use crate::input::bad;
use crate::render::check_parent_writable;

/// Which cases a check runs, and how.
pub struct Pick {
    /// `--case`, `--changed`, `--failed`, `--partition`.
    pub selection: vista_check::Pick,
    /// Orphaned goldens warn instead of failing.
    pub allow_orphans: bool,
    /// Cases checked at once (`--jobs`).
    pub jobs: usize,
    /// Each case runs a second time with coverage counters (`--coverage`).
    pub coverage: bool,
}

/// A results file's directory must exist and be writable, before any GPU work.
pub(crate) fn check_results_path(flag: &str, path: &Path) -> Result<(), GoldenError> {
    if path.is_dir() {
        return Err(bad(format!("{flag} {} is a directory; expected a file path", path.display())));
    }
    check_parent_writable(path).map_err(|e| bad(format!("{flag} {}: {e}", path.display())))
}

/// A case's status line (`ok`, `xfail`, `FAIL`; the value it was judged
/// by; a per-backend golden named), and for a failure its explanation.
pub(crate) fn print_case(o: &vista_golden::Outcome, report_dir: &Path) {
    let label = match o.verdict {
        vista_golden::Verdict::Pass => "ok",
        vista_golden::Verdict::ExpectedFail => "xfail",
        _ => "FAIL",
    };
    let per_backend = match o.golden_file.rsplit_once('@') {
        Some((_, b)) => format!("  [golden @{}]", b.trim_end_matches(".png")),
        None => String::new(),
    };
    if o.crashed {
        // One block: what crashed, where, and that the run went on. An
        // expected crash keeps its cause (moved to the notes by the
        // expectation) and says it was expected.
        let cause = o.problems.first().or_else(|| o.notes.first()).map(String::as_str).unwrap_or("the worker died");
        let cause = cause.rsplit_once("it failed with: ").map_or(cause, |(_, c)| c);
        println!("CRASH {}: {}", o.id, cause);
        if o.verdict == vista_golden::Verdict::ExpectedFail {
            o.notes.iter().for_each(|n| println!("  xfail: {n}"));
        }
        return;
    }
    println!("{label:<6} {:<40} {:<17} {:>8.1} ms{per_backend}", o.id, o.headline(), o.gpu_ms);
    if !o.passed() {
        print!("{}", o.explain(report_dir));
    } else if o.verdict == vista_golden::Verdict::ExpectedFail {
        o.notes.iter().for_each(|n| println!("  note: {n}"));
    }
}

/// What `vista check` and `vista watch` print as each case is filed: its
/// status line ([`print_case`]) and any report folder it could not write;
/// its times are added to `time` where one is kept.
pub(crate) struct Terminal<'a> {
    pub report_dir: &'a Path,
    pub time: Option<&'a mut Phases>,
}

impl vista_check::Reporter for Terminal<'_> {
    fn case(&mut self, f: &Filed) {
        if let Some(time) = self.time.as_deref_mut() {
            time.cases += f.check_time;
            time.report += f.report_time;
            time.gpu += std::time::Duration::from_secs_f64(f.outcome.gpu_ms / 1000.0);
        }
        print_case(&f.outcome, self.report_dir);
        for e in &f.report_errors {
            println!("error: {}: its report folder could not be written: {e}", f.outcome.id);
        }
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

/// The coverage summary line, each case not measured, and the tracefile.
fn print_coverage(counts: &vista_coverage::Counts, outcomes: &[vista_golden::Outcome], report_dir: &Path) {
    for o in outcomes {
        if let Some(Err(why)) = &o.coverage {
            println!("coverage: {} not measured: {why}", o.id);
        }
    }
    println!(
        "coverage: {}: {}",
        vista_report::coverage_line(counts),
        report_dir.join(vista_check::LCOV_FILE).display()
    );
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
    let manifest = store.manifest()?;
    let report_dir = match report_dir {
        Some(d) => d,
        None => vista_check::default_report_dir(project, config.gpu.adapter.backend_name(), config.gpu.validate)
            .expect("a store implies a root"),
    };
    let (picked, narrowed) = vista_check::select(project, &cases, &manifest, &pick.selection, &report_dir)?;
    if let Some(line) = narrowed {
        println!("{line}");
    }
    let ctx = &Renderer::shared(&config.gpu, project, config.limits)?;
    vista_report::clear_case_folders(&report_dir)?;
    // Ctrl-C: the cases that finished still get their report.
    crate::signals::stop_on_interrupt();
    let mut time = Phases::start(ctx);
    let checker = Checker {
        ctx,
        store: &store,
        manifest: &manifest,
        report_dir: &report_dir,
        detail: viewers,
        coverage: pick.coverage,
    };
    time.jobs = checker.jobs(pick.jobs, picked.len());
    let summary = vista_report::RunSummary {
        command: command_line(),
        backend: ctx.backend().to_string(),
        adapter: ctx.adapter_description(),
        partition: pick.selection.partition,
        ..Default::default()
    };
    let results = Results { sources: ctx.shaders.text_reader(), ..results };
    let mut run = Run { checker, summary, results, shared: None };
    let filed = run.check(&picked, pick.jobs, &mut Terminal { report_dir: &report_dir, time: Some(&mut time) });
    let report_failed = filed.iter().any(|f| !f.report_errors.is_empty());
    let started = std::time::Instant::now();
    run.note_interrupt(filed.len(), picked.len());
    let index = run.finish(&filed)?;
    time.report += started.elapsed();
    let run = run.summary;
    let accept = vista_check::accept_command(&report_dir, &filed);
    let outcomes: Vec<vista_golden::Outcome> = filed.into_iter().map(|f| f.outcome).collect();
    if config.github_actions {
        annotate(&store, &outcomes);
    }
    let failing: Vec<&str> = outcomes.iter().filter(|o| !o.passed()).map(|o| o.id.as_str()).collect();
    let failed = failing.len();
    // An expected failure is neither a pass nor a failure: counted apart.
    let xfail = outcomes.iter().filter(|o| o.verdict == vista_golden::Verdict::ExpectedFail).count();
    match xfail {
        0 => println!("{} passed, {} failed", outcomes.len() - failed, failed),
        n => println!("{} passed, {} failed, {n} expected to fail", outcomes.len() - failed - n, failed),
    }
    // Goldens no case refers to: a renamed or deleted case left them behind.
    let orphans = vista_check::orphans(&store, &cases);
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
    // A crash is the driver's: bless cannot fix it.
    let crashed: Vec<&str> = outcomes.iter().filter(|o| o.crashed).map(|o| o.id.as_str()).collect();
    if !crashed.is_empty() {
        println!("crashed: {} (the driver, not the kernel's output: see CRASH above)", crashed.join(", "));
    }
    let failing: Vec<&str> = failing.into_iter().filter(|id| !crashed.contains(id)).collect();
    if let Some(cmd) = vista_golden::bless_all_command(&failing) {
        println!("failed: {}", failing.join(", "));
        println!("if every change is intended, after reviewing the report: {cmd}");
        if let Some(accept) = &accept {
            println!(
                "or accept exactly what this run rendered (on another machine too, from this report folder): {accept}"
            );
        }
    }
    if let Some(counts) = vista_check::coverage_total(&outcomes, &[]) {
        print_coverage(&counts, &outcomes, &report_dir);
    }
    println!("{}", time.summary(ctx, outcomes.len()));
    if let Some(line) = &run.stopped {
        println!("interrupted: {line}");
    }
    println!("report: {}", index.display());
    if vista_check::interrupted() {
        // 128 + SIGINT, as a shell reports a command Ctrl-C ended.
        return Ok(130);
    }
    Ok(if failed == 0 && !orphans_fail && !report_failed { 0 } else { 1 })
}

/// Where a check's wall time went: compiling (composing WGSL, creating
/// pipelines), the GPU runs, the rest of each case (planning, the CPU's
/// part of running it, judging), and writing the report.
pub(crate) struct Phases {
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
/// its arguments, quoted where the shell would need it: shlex's quoting),
/// for reports.
pub(crate) fn command_line() -> String {
    let args: Vec<String> = std::iter::once("vista".to_string()).chain(std::env::args().skip(1)).collect();
    // An argument cannot hold a NUL (the OS passes C strings).
    shlex::try_join(args.iter().map(String::as_str)).expect("arguments hold no NUL")
}

/// `vista merge`: the shards' report folders joined into `out`; prints each
/// case that did not pass as `check` does, then the totals; exit 1 if any
/// failed, 2 for bad input (a shard missing, given twice, of another split).
/// The WGSL files of `project` (none: no text) for the coverage pages.
pub fn sources_of(project: Option<Project>) -> vista_render::Reader {
    project.and_then(|p| vista_render::shader_set(&p).ok()).map(|s| s.text_reader()).unwrap_or_default()
}

pub fn merge(dirs: &[PathBuf], out: &Path, results: Results) -> std::process::ExitCode {
    match merged(dirs, out, results) {
        Ok(code) => std::process::ExitCode::from(code),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::from(e.exit_code() as u8)
        }
    }
}

fn merged(dirs: &[PathBuf], out: &Path, results: Results) -> Result<u8, GoldenError> {
    if let Some(p) = &results.junit {
        check_results_path("--junit", p)?;
    }
    if let Some(p) = &results.json {
        check_results_path("--json", p)?;
    }
    let (index, outcomes) = vista_check::merge(dirs, out, &results, command_line())?;
    for o in outcomes.iter().filter(|o| !o.passed()) {
        print_case(o, out);
    }
    let failing: Vec<&str> = outcomes.iter().filter(|o| !o.passed()).map(|o| o.id.as_str()).collect();
    println!("merged {} shards: {} passed, {} failed", dirs.len(), outcomes.len() - failing.len(), failing.len());
    if !failing.is_empty() {
        println!("failed: {}", failing.join(", "));
    }
    if out.join(vista_golden::pending::PENDING_FILE).exists() {
        println!("accept exactly what the shards rendered: vista bless --from-report {}", out.display());
    }
    println!("report: {}", index.display());
    Ok(if failing.is_empty() { 0 } else { 1 })
}
