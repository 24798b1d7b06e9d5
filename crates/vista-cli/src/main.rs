//! `vista`: thin command-line glue over vista's libraries.
//! Exit codes: 0 success, 1 failed check (or run failure), 2 bad input.

use input::bad;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use vista::Config;
use vista_golden::{BlessOptions, GoldenError};
use vista_project::Project;

mod bench;
mod bless;
mod check;
mod compare;
mod graph_render;
mod init;
mod input;
mod list;
mod matrix;
mod mutate;
mod render;
mod signals;
mod sweep;
mod unit_tests;
mod watch;

#[derive(Parser)]
#[command(name = "vista", version, about = "Headless GPU compute validation for procedural WGSL kernels")]
struct Cli {
    /// Deprecated, hidden: `--adapter cpu|gpu` is `--backend lavapipe|gpu`.
    #[arg(long, global = true, hide = true)]
    adapter: Option<String>,
    /// Implementation: lavapipe (default), swiftshader, browser (headless Chromium WebGPU) or gpu. Same as VISTA_BACKEND.
    #[arg(long, global = true, value_name = "NAME")]
    backend: Option<String>,
    /// Project root (a directory holding vista.toml). Default: VISTA_ROOT,
    /// else the nearest vista.toml at or above the current directory.
    #[arg(long, global = true, value_name = "DIR")]
    root: Option<PathBuf>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write a starter project into DIR that bless and check pass right away.
    ///
    /// vista.toml, kernels/rings.toml, shaders/rings.wgsl and
    /// golden/cases.toml (two cases), into DIR (default: the current
    /// directory). Never overwrites a file.
    Init {
        /// Where to write it (created if missing).
        #[arg(default_value = ".")]
        dir: PathBuf,
    },
    /// List kernels with their parameters (ranges, defaults) and presets.
    List {
        /// Print only `KERNEL PRESET` lines (for scripts).
        #[arg(long)]
        names: bool,
        /// Print each buffer binding's layout instead: every leaf by its
        /// path (`lights[i].color`), byte offset and WGSL type, as an
        /// engine packs it.
        #[arg(long, conflicts_with = "names")]
        layout: bool,
        /// With --layout: only this kernel.
        #[arg(requires = "layout")]
        kernel: Option<String>,
        /// Run every case with coverage counters and print, per kernel,
        /// the WGSL lines and branch arms no case reaches.
        #[arg(long, conflicts_with_all = ["names", "layout"])]
        coverage: bool,
    },
    /// Render one kernel to a PNG (display values) or EXR (raw/linear values).
    Render {
        /// The kernel's name (`vista list` shows them).
        kernel: String,
        /// A preset of the kernel (default: its defaults).
        #[arg(long)]
        preset: Option<String>,
        /// Parameter override NAME=VALUE (repeatable; vectors comma-separated).
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
        /// Image size, WIDTHxHEIGHT.
        #[arg(long, default_value = "256x256")]
        size: String,
        /// Write only this rectangle of the rendered image: X,Y,W,H in pixels
        /// (the kernel still renders the whole --size frame).
        #[arg(long, value_name = "X,Y,W,H")]
        crop: Option<String>,
        /// Repeat every written pixel N x N times (nearest neighbour, 1-16).
        #[arg(long, value_name = "N", default_value_t = 1)]
        zoom: u32,
        /// The image to write: .png (display values, 16-bit) or .exr (raw values).
        #[arg(short, long)]
        out: PathBuf,
    },
    /// Compare two images (PNG or EXR): PSNR, SSIM, max-abs, bad pixels, NaN/Inf; or two
    /// `.npy` buffers: max-abs, max-rel, RMSE and the worst elements.
    Compare {
        /// The reference image (PNG or EXR).
        a: PathBuf,
        /// The image compared with it.
        b: PathBuf,
        /// Print every metric as one JSON object.
        #[arg(long)]
        json: bool,
        /// PSNR peak = max of A (for HDR/EXR data) instead of 1.
        #[arg(long)]
        hdr: bool,
        /// Box-blur both images with this radius first (0-64): what remains is
        /// structured error such as banding, not pixel noise.
        #[arg(long, value_name = "R", default_value_t = 0)]
        blur: u32,
        /// Compare only this rectangle of both images: X,Y,W,H in pixels.
        #[arg(long, value_name = "X,Y,W,H")]
        crop: Option<String>,
    },
    /// Run the WGSL unit tests: `@test` functions in shaders/**/*.test.wgsl or *.test.wesl.
    ///
    /// Assertions from `#import wgsl_test` (WESL: `import wgsl_test::{..}`; expect, expectEq, expectEqU,
    /// expectNear, expectNearV2f..V4f, expectUlp) run on the GPU; a failure
    /// names its file:line:col and values. Exit 1 if any test fails.
    Test {
        /// Only the tests whose id (`wgsl::<file>::<fn>`) contains this.
        filter: Option<String>,
        /// Every test on lavapipe, swiftshader and browser: one test x backend table.
        #[arg(long)]
        matrix: bool,
        /// Write each `@snapshot` test's render as its golden
        /// (golden/wgsl/<file>/<fn>.png) instead of judging it; refused
        /// under CI=true.
        #[arg(long, conflicts_with = "matrix")]
        bless: bool,
        /// Also run each test file again with coverage counters: the WGSL
        /// lines and branch arms the tests execute, as lcov.info and pages
        /// under the report folder's wgsl-tests/.
        #[arg(long, conflicts_with = "matrix")]
        coverage: bool,
    },
    /// Check the cases, then re-check the ones a saved file reaches (WGSL,
    /// kernel manifests, golden/) and rewrite the report, until interrupted.
    Watch {
        /// Only the cases whose id matches this glob.
        #[arg(long = "case", value_name = "GLOB")]
        case: Option<String>,
        /// How often the files are looked at, in milliseconds (50-60000).
        #[arg(long, default_value_t = 500)]
        interval: u64,
        /// Stop after this many seconds (default: never; for scripts and tests).
        #[arg(long, value_name = "SECONDS")]
        timeout: Option<f64>,
    },
    /// Render golden cases and compare them with their goldens.
    Check {
        /// Only the cases whose id matches this glob.
        #[arg(long = "case", value_name = "GLOB")]
        case: Option<String>,
        /// Where the HTML report and case images go (default: <root>/target/vista-report).
        #[arg(long, value_name = "DIR")]
        report_dir: Option<PathBuf>,
        /// Every case on lavapipe, swiftshader and browser: one case x backend table.
        #[arg(long)]
        matrix: bool,
        /// Also write JUnit XML here: one testcase per case, the failure text
        /// being the block printed for it.
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
        /// Also write the results as JSON here: per case the verdict,
        /// metrics, thresholds, problems, report anchor and golden used.
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
        /// Only the cases whose params or any reached WGSL file changed
        /// since their bless (or that have no manifest entry).
        #[arg(long)]
        changed: bool,
        /// Only the cases that failed in the last report (its results.json).
        #[arg(long)]
        failed: bool,
        /// Only partition K of N (1-based), split stably by case id.
        #[arg(long, value_name = "K/N")]
        partition: Option<String>,
        /// Report golden images that no case refers to as a warning
        /// instead of failing the check.
        #[arg(long)]
        allow_orphans: bool,
        /// Write the pixel viewer's data for passing cases too (by default
        /// only cases that do not pass get it: about 1 MB per 256x256 case).
        #[arg(long)]
        full_report: bool,
        /// Cases checked at once: while one case runs on the device, others
        /// are planned, judged and written to the report (1..=64). Under the
        /// validation layer one at a time, so each message names its case.
        #[arg(long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u16).range(1..=64))]
        jobs: u16,
        /// Also run each case with a counter per WGSL statement and branch
        /// arm, after its judged render (verdicts and goldens are those of
        /// the plain run): which lines the cases execute, as lcov.info in
        /// the report folder.
        #[arg(long)]
        coverage: bool,
    },
    /// Join the report folders of `check --partition K/N --report-dir DIR`
    /// runs into one report, results.json, JUnit and pending.toml.
    Merge {
        /// Each shard's report folder; every K of one N, once.
        #[arg(required = true, value_name = "DIR")]
        dirs: Vec<PathBuf>,
        /// Where the joined report goes.
        #[arg(long, value_name = "DIR")]
        report_dir: PathBuf,
        /// Also write JUnit XML here (as `check --junit`).
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
        /// Also write the results as JSON here (as `check --json`).
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
    },
    /// Re-render cases and write their goldens (refused under CI=true without --force).
    Bless {
        /// Only the cases whose id matches this glob.
        #[arg(long = "case", value_name = "GLOB")]
        case: Option<String>,
        /// Bless even under CI=true.
        #[arg(long)]
        force: bool,
        /// Delete golden images that no case refers to.
        #[arg(long)]
        prune: bool,
        /// Accept exactly the renders a check left in this report folder
        /// (its pending.toml: failing and missing cases), without
        /// rendering, after checking this checkout's params and WGSL still
        /// hash as they did there.
        #[arg(long, value_name = "DIR", conflicts_with = "prune")]
        from_report: Option<PathBuf>,
        /// Write golden/<kernel>/<case>@<backend>.png for this run's backend
        /// (--backend): from then on that backend is judged against it, at the
        /// same-driver threshold, and every other backend against the case's own.
        #[arg(long, conflicts_with = "from_report")]
        per_backend: bool,
    },
    /// Sweep a parameter (or a grid of two) against a high-quality reference:
    /// curve.csv, curve.svg, curve.png and a table naming the cheapest setting
    /// reaching --target-psnr.
    Sweep(sweep::Args),
    /// Mutation testing: single-token mutants of a kernel's WGSL against its
    /// golden cases and CPU reference; prints the score and the survivors.
    Mutate(mutate::Args),
    /// Median kernel throughput after a warm-up (excludes device creation and compilation).
    Bench(bench::Args),
}

fn main() -> ExitCode {
    // Started as a GPU worker by another vista process: serve it, then exit.
    vista::config::serve_worker_if_asked();
    vista_image::one_arena();
    signals::die_quietly_on_closed_pipe();
    let cli = Cli::parse();
    if let Some(a) = &cli.adapter {
        let instead = if a == "cpu" { "lavapipe" } else { a.as_str() };
        eprintln!(
            "note: --adapter is deprecated; it is --backend {instead} (--backend lavapipe|swiftshader|browser|gpu)"
        );
    }
    // The one configuration: flags first, then the environment, read here once.
    let flags = vista::Flags { backend: cli.backend.clone(), adapter: cli.adapter.clone() };
    let config = match vista::Config::from_env(&flags) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(e.exit_code() as u8);
        }
    };
    // Fault injection for the write-path tests (see vista_image::fault).
    if let Some(text) = &config.fault {
        match vista_image::fault::FaultPlan::parse(text) {
            Ok(plan) => vista_image::fault::install(plan),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        }
    }
    // init makes a project, so it needs none.
    if let Command::Init { dir } = &cli.command {
        return init::run(dir);
    }
    // merge joins report folders: it needs no project either.
    if let Command::Merge { dirs, report_dir, junit, json } = &cli.command {
        // The project's WGSL, where the current directory has one, for the coverage pages.
        let here = std::env::current_dir()
            .ok()
            .and_then(|cwd| Project::discover(cli.root.as_deref(), config.root.clone(), &cwd).ok());
        let results =
            vista_check::Results { junit: junit.clone(), json: json.clone(), sources: check::sources_of(here) };
        return check::merge(dirs, report_dir, results);
    }
    let project = match std::env::current_dir()
        .map_err(|e| GoldenError::BadInput(format!("cannot read the current directory: {e}")))
        .and_then(|cwd| Ok(Project::discover(cli.root.as_deref(), config.root.clone(), &cwd)?))
    {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(e.exit_code() as u8);
        }
    };
    if let Some(root) = project.root()
        && !config.mesa_cache_placed
    {
        let dir = root.join(vista::config::MESA_CACHE);
        // Mesa does not create the folder's parents; without it the cache
        // is off, which costs time, not correctness.
        let _ = std::fs::create_dir_all(&dir);
        // SAFETY: nothing else runs yet (no thread, no GPU context), and
        // Mesa reads the variable when the Vulkan device is created, later.
        unsafe { std::env::set_var("MESA_SHADER_CACHE_DIR", dir) };
    }
    // SAFETY (getuid): no preconditions.
    if let Some(dir) = config.private_runtime_dir(unsafe { libc::getuid() }) {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt};
        let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        // Only a folder of this user's (another's of that name is not ours).
        if std::fs::metadata(&dir).is_ok_and(|m| m.is_dir() && m.uid() == unsafe { libc::getuid() }) {
            // SAFETY: nothing else runs yet (no thread, no GPU context); Mesa
            // reads it when wgpu creates the Vulkan instance, later.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", dir) };
        }
    }
    for (name, value) in config.hidden_layers().into_iter().chain(config.hidden_drivers()) {
        // SAFETY: as above; the Vulkan loader reads them when wgpu creates
        // the instance, later.
        unsafe { std::env::set_var(name, value) };
    }
    // Workers inherit the environment set above.
    config.apply_to_process();
    let result = run(&project, &config, cli.command);
    vista_render::worker::stop_all();
    match result {
        Ok(code) => ExitCode::from(code as u8),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

fn run(project: &Project, config: &Config, cmd: Command) -> Result<i32, GoldenError> {
    match cmd {
        Command::Init { .. } => unreachable!("init runs before a project is found"),
        Command::Merge { .. } => unreachable!("merge runs before a project is found"),
        Command::Watch { case, interval, timeout } => {
            let timeout = match timeout {
                Some(t) if !(t > 0.0 && t <= 86400.0) => {
                    return Err(bad(format!("--timeout {t} is out of range; allowed: (0, 86400] seconds")));
                }
                t => t.map(std::time::Duration::from_secs_f64),
            };
            watch::watch(project, config, case.as_deref(), watch::interval(interval)?, timeout)
        }
        Command::List { layout: true, kernel, .. } => list::layouts(project, kernel.as_deref()),
        Command::List { coverage: true, .. } => list::coverage(project, config),
        Command::List { names, .. } => list::run(project, names),
        Command::Test { filter, matrix, bless, coverage } => {
            unit_tests::test(project, config, filter.as_deref(), matrix, bless, coverage)
        }
        Command::Render { kernel, preset, set, size, crop, zoom, out } => {
            render::render(project, config, render::Args { kernel, preset, set, size, crop, zoom, out })
        }
        Command::Compare { a, b, json, hdr, blur, crop } => compare::compare(&a, &b, json, hdr, blur, crop),
        Command::Check { matrix: true, junit: Some(_), .. } => {
            Err(bad("--junit is written by a check on one backend; drop --matrix (or run check per backend); \
             --matrix --json writes every cell"))
        }
        Command::Check { matrix: true, changed, failed, partition, .. } if changed || failed || partition.is_some() => {
            Err(bad("--changed, --failed and --partition select cases of a check on one backend; drop --matrix"))
        }
        Command::Check { case, report_dir, matrix: true, json, .. } => {
            matrix::matrix(project, config, case.as_deref(), report_dir, json)
        }
        Command::Check {
            case,
            report_dir,
            matrix: false,
            junit,
            json,
            changed,
            failed,
            partition,
            allow_orphans,
            full_report,
            jobs,
            coverage,
        } => {
            let partition = partition.as_deref().map(vista_golden::selection::parse_partition).transpose()?;
            let selection = vista_check::Pick { glob: case, changed, failed, partition };
            let pick = check::Pick { selection, allow_orphans, jobs: jobs as usize, coverage };
            let viewers = if full_report { vista_report::Detail::All } else { vista_report::Detail::Failing };
            let results = vista_check::Results { junit, json, ..Default::default() };
            check::check(project, config, &pick, report_dir, results, viewers)
        }
        Command::Bless { case, force, from_report: Some(dir), .. } => {
            bless::from_report(project, config, case, force, &dir)
        }
        Command::Bless { case, force, prune, per_backend, .. } => {
            bless::bless(project, config, BlessOptions { glob: case, force, prune, in_ci: config.in_ci, per_backend })
        }
        Command::Sweep(args) => sweep::sweep(project, config, args),
        Command::Mutate(args) => mutate::mutate(project, config, args),
        Command::Bench(args) => bench::bench(project, config, args),
    }
}
