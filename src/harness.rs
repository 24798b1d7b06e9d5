//! vista inside another crate's `cargo test` (SPEC 15): the whole `main`
//! of a `[[test]] harness = false` target.
//!
//! ```toml
//! # Cargo.toml of the crate whose kernels vista checks
//! [dev-dependencies]
//! vista = { path = "..." }
//!
//! [[test]]
//! name = "golden"
//! harness = false
//! ```
//!
//! ```text
//! // tests/golden.rs
//! fn main() {
//!     vista::harness::main()
//! }
//! ```
//!
//! The project is found at run time: `VISTA_ROOT`, else the nearest
//! `vista.toml` at or above the crate's directory (which cargo gives its
//! test processes in a variable), else above the current directory. Each
//! case of `golden/cases.toml` is one test named `golden::<kernel>::<case>`,
//! so libtest's arguments work as in any `cargo test` (a filter, `--exact`,
//! `--list`, `--ignored`, `--skip`) and nextest lists and partitions them.
//! After the run the report is written (`target/vista-report/` of the
//! project, `target/vista-report-<backend>/` for another `VISTA_BACKEND`,
//! `target/vista-report-<backend>-validation/` under `VISTA_VALIDATION=1`,
//! or `VISTA_REPORT_DIR`, relative to the project root), so runs side by
//! side do not clear each other's case folders, with `pending.toml` and
//! `results.json` as `vista check` leaves them (the one driver,
//! `vista-check`), and a JUnit file where `VISTA_JUNIT` names one (relative
//! to the project root too). Goldens no case refers to fail one more test,
//! `golden::orphans`, present only when there are some.
//!
//! Under cargo-nextest every test is a process of its own: each records its
//! case in the report folder and rebuilds the report from every case of
//! the run (`vista_check::SharedRun`), the run being nextest's
//! `NEXTEST_RUN_ID` (else the nextest process that started this one); a
//! folder an earlier run left is cleared by the run's first process. The
//! folders of `cargo nextest run --partition count:K/N` runs, each with a
//! `VISTA_REPORT_DIR` of its own, join with `vista merge`.
//!
//! Without an adapter every case fails naming the install command, unless
//! `VISTA_ALLOW_NO_GPU=1`: then each is reported ignored and a loud line
//! names them.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use libtest_mimic::{Arguments, Failed, Trial};
use vista_check::{Checker, Filed};
use vista_golden::Store;
use vista_project::Project;
use vista_render::Renderer;

/// Runs the project's golden cases as libtest tests and exits.
pub fn main() -> ! {
    // Started as a GPU worker by this very test binary: serve it, then exit.
    crate::config::serve_worker_if_asked();
    let args = Arguments::from_args();
    let config = crate::Config::from_env(&crate::Flags::default()).unwrap_or_else(|e| fail(&e.to_string()));
    let cwd = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
    let start = config.crate_dir.clone().unwrap_or(cwd);
    let project =
        Project::discover(None, config.root.clone(), &start).unwrap_or_else(|e| fail(&format!("vista harness: {e}")));
    if project.root().is_none() {
        fail(&format!(
            "vista harness: no vista.toml at or above {} (the crate's directory); add one at the project root or set \
             VISTA_ROOT",
            start.display()
        ));
    }
    run(&args, &project, &command_name(config.nextest && args.exact))
}

/// `cargo test --test <name>` (`cargo nextest run --test <name>` under
/// nextest): this binary's test target, from its file name (`golden-<hash>`).
fn command_name(nextest: bool) -> String {
    let exe = std::env::args().next().unwrap_or_default();
    let stem = Path::new(&exe).file_stem().and_then(|s| s.to_str()).unwrap_or("golden").to_string();
    let name = match stem.rsplit_once('-') {
        Some((name, hash)) if hash.len() == 16 && hash.chars().all(|c| c.is_ascii_hexdigit()) => name.to_string(),
        _ => stem,
    };
    format!("{} --test {name}", if nextest { "cargo nextest run" } else { "cargo test" })
}

/// The harness's checker of every case: failing cases' images in full.
fn checker<'a>(
    ctx: &'a Renderer<'a>,
    store: &'a Store,
    manifest: &'a vista_golden::Manifest,
    report_dir: &'a Path,
    coverage: bool,
) -> Checker<'a> {
    Checker { ctx, store, manifest, report_dir, detail: vista_report::Detail::Failing, coverage }
}

/// Each WGSL unit test (`@test` in `shaders/**/*.test.wgsl`, `.test.wesl`) as a libtest
/// test `wgsl::<file>::<fn>`: a file runs whole, once, when the first of
/// its tests runs, and each test reports its own result.
fn wgsl_trials(
    project: &Project,
    renderer: Option<Result<&'static Renderer<'static>, String>>,
    skip: bool,
    units: &Arc<Mutex<Vec<vista_report::UnitTest>>>,
    coverage: bool,
) -> Vec<Trial> {
    type Results = Arc<std::sync::OnceLock<Vec<vista_wgsl_test::TestResult>>>;
    let files = vista_wgsl_test::test_files(project).unwrap_or_else(|e| fail(&format!("cannot read the shaders: {e}")));
    let sources: Arc<std::sync::OnceLock<Result<vista_render::Sources, String>>> = Arc::default();
    let mut trials = Vec::new();
    for (rel, text) in files {
        let ids = vista_wgsl_test::list(&rel, &text).unwrap_or_else(|_| vec![vista_wgsl_test::test_id(&rel, "*")]);
        let (results, rel, text): (Results, Arc<str>, Arc<str>) = (Arc::default(), rel.into(), text.into());
        // The file's coverage run, taken by the first of its tests to finish.
        let counted: Arc<Mutex<bool>> = Arc::default();
        for id in ids {
            let (project, renderer, sources, results, units, counted) =
                (project.clone(), renderer.clone(), sources.clone(), results.clone(), units.clone(), counted.clone());
            let (rel, text) = (rel.clone(), text.clone());
            trials.push(
                Trial::test(id.clone(), move || {
                    let ctx = match renderer {
                        Some(Ok(ctx)) => ctx,
                        Some(Err(e)) => return Err(Failed::from(format!("no GPU adapter: {e}"))),
                        None => return Err(Failed::from("listed, not run")),
                    };
                    let sources = sources
                        .get_or_init(|| vista_render::Sources::of(&project).map_err(|e| e.to_string()))
                        .as_ref()
                        .map_err(|e| Failed::from(e.clone()))?;
                    let all = results.get_or_init(|| vista_wgsl_test::run_file(ctx, sources, &rel, &text));
                    // A file that does not rewrite has one result, `*`.
                    let r = all.iter().find(|r| r.id == id).or(all.first()).ok_or_else(|| Failed::from("not run"))?;
                    let failures = if r.passed() { Vec::new() } else { r.explain() };
                    let first = coverage && !std::mem::replace(&mut *counted.lock().expect("counted"), true);
                    let coverage =
                        first.then(|| vista_wgsl_test::cover_file(ctx, sources, &rel, &text).map(|c| c.lcov(&id)));
                    let unit = vista_report::UnitTest { id: id.clone(), failures: failures.clone(), coverage };
                    units.lock().expect("unit tests").push(unit);
                    match r.passed() {
                        true => Ok(()),
                        false => Err(Failed::from(failures.join("\n"))),
                    }
                })
                .with_ignored_flag(skip),
            );
        }
    }
    trials
}

fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(2)
}

/// The harness over `project`'s cases with libtest's `args`; `command`
/// names the run in the report.
pub fn run(args: &Arguments, project: &Project, command: &str) -> ! {
    let config = crate::Config::from_env(&crate::Flags::default()).unwrap_or_else(|e| fail(&e.to_string()));
    config.apply_to_process();
    let store = Store::of_project(project, "the golden tests").unwrap_or_else(|e| fail(&e.to_string()));
    let cases = store.load_cases().unwrap_or_else(|e| fail(&format!("cannot load golden cases: {e}")));
    let manifest = Arc::new(store.manifest().unwrap_or_else(|e| fail(&format!("cannot load the manifest: {e}"))));
    // One report per implementation (VISTA_BACKEND) and for the validation
    // layer, so runs (side by side in `make test`) do not overwrite each other.
    let backend = config.gpu.adapter.backend_name();
    let report_dir = match &config.report_dir {
        Some(dir) => project.root().expect("a store has a root").join(dir),
        None => vista_check::default_report_dir(project, backend, config.gpu.validate).expect("a store has a root"),
    };
    // Under nextest each case is a process of its own (started with
    // `--exact <test>`), and the run's processes share the report. A harness
    // a test under nextest starts whole (no --exact) is a run of its own.
    let shared_id = (config.nextest && args.exact)
        .then(|| config.nextest_run_id.clone().unwrap_or_else(vista_check::parent_run_id));
    let filed: Arc<Mutex<Vec<Filed>>> = Arc::new(Mutex::new(Vec::new()));
    // Listing needs no device (nextest lists before it runs). One renderer
    // per process, shared by every case.
    static RENDERER: std::sync::OnceLock<Result<Renderer<'static>, String>> = std::sync::OnceLock::new();
    let renderer: Option<Result<&'static Renderer<'static>, String>> = (!args.list).then(|| {
        RENDERER
            .get_or_init(|| Renderer::shared(&config.gpu, project, config.limits).map_err(|e| e.to_string()))
            .as_ref()
            .map_err(Clone::clone)
    });
    let missing = renderer.as_ref().and_then(|r| r.as_ref().err().cloned());
    // A run that will render clears the last report's case folders (under
    // nextest, the run's first process does); one that skips (no adapter)
    // leaves the last report whole.
    let mut shared = None;
    if renderer.as_ref().is_some_and(|r| r.is_ok()) {
        match &shared_id {
            Some(id) => {
                shared = Some(
                    vista_check::SharedRun::join(&report_dir, id)
                        .unwrap_or_else(|e| fail(&format!("cannot join the report of run {id}: {e}"))),
                )
            }
            None => vista_report::clear_case_folders(&report_dir)
                .unwrap_or_else(|e| fail(&format!("cannot clear the report: {e}"))),
        }
    }
    let skip = missing.is_some() && config.allow_no_gpu;
    if let Some(e) = &missing
        && config.allow_no_gpu
    {
        eprintln!("\n!!! VISTA_ALLOW_NO_GPU=1 and no adapter: {e}");
        eprintln!(
            "!!! SKIPPING all {} golden cases: {}\n",
            cases.len(),
            cases.iter().map(|c| c.id.as_str()).collect::<Vec<_>>().join(", ")
        );
    }
    let mut trials: Vec<Trial> = cases
        .iter()
        .map(|case| {
            let (case, store, manifest, filed, report_dir, renderer) =
                (case.clone(), store.clone(), manifest.clone(), filed.clone(), report_dir.clone(), renderer.clone());
            let name = format!("golden::{}::{}", case.kernel.name(), case.id);
            Trial::test(name, move || {
                let ctx = match renderer {
                    Some(Ok(ctx)) => ctx,
                    Some(Err(e)) => return Err(Failed::from(format!("no GPU adapter: {e}"))),
                    None => return Err(Failed::from("listed, not run")),
                };
                let f = checker(ctx, &store, &manifest, &report_dir, config.coverage).check(&case);
                let o = &f.outcome;
                let result = match (o.passed(), f.report_errors.is_empty()) {
                    (true, true) => Ok(()),
                    (false, _) => Err(Failed::from(o.explain(&report_dir))),
                    (true, false) => Err(Failed::from(format!(
                        "passed, but its report folder could not be written: {}",
                        f.report_errors.join("; ")
                    ))),
                };
                filed.lock().expect("filed").push(f);
                result
            })
            .with_ignored_flag(skip)
        })
        .collect();
    let units: Arc<Mutex<Vec<vista_report::UnitTest>>> = Arc::default();
    trials.extend(wgsl_trials(project, renderer.clone(), skip, &units, config.coverage));
    let orphans = vista_check::orphans(&store, &cases);
    if !orphans.is_empty() {
        let listed: Vec<String> = orphans.iter().map(|o| o.display().to_string()).collect();
        trials.push(
            Trial::test("golden::orphans", move || {
                Err(Failed::from(format!(
                    "goldens with no case (a renamed or deleted case left them behind; delete them, or vista bless \
                     --prune): {}",
                    listed.join(", ")
                )))
            })
            .with_ignored_flag(skip),
        );
    }
    let conclusion = libtest_mimic::run(args, trials);
    let mut filed = filed.lock().expect("filed");
    // In case order, as `vista check` lists them.
    filed.sort_by_key(|f| cases.iter().position(|c| c.id == f.outcome.id));
    let mut units = std::mem::take(&mut *units.lock().expect("unit tests"));
    units.sort_by(|a, b| a.id.cmp(&b.id));
    if !(filed.is_empty() && units.is_empty())
        && let Some(Ok(ctx)) = &renderer
    {
        let run = vista_report::RunSummary {
            command: match ctx.backend() {
                "lavapipe" => command.to_string(),
                b => format!("VISTA_BACKEND={b} {command}"),
            },
            adapter: ctx.adapter_description(),
            backend: ctx.backend().to_string(),
            unit_tests: units,
            ..Default::default()
        };
        let root = project.root().expect("a store has a root");
        let results = vista_check::Results {
            junit: config.junit.as_ref().map(|j| root.join(j)),
            json: None,
            sources: ctx.shaders.text_reader(),
        };
        let suite: Vec<String> = cases.iter().map(|c| c.id.clone()).collect();
        let checker = checker(ctx, &store, &manifest, &report_dir, config.coverage);
        let run = vista_check::Run { checker, summary: run, results, shared: shared.map(|s| (s, suite)) };
        let written = run.finish(&filed);
        match written {
            Ok(index) => eprintln!("vista report: {}", index.display()),
            Err(e) => eprintln!("could not write the vista report: {e}"),
        }
    }
    // No worker outlives the test process: nextest calls a test whose
    // output a child still holds open leaky.
    vista_render::worker::stop_all();
    conclusion.exit()
}
