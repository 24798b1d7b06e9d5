//! `vista`: thin command-line glue over vista's libraries.
//! Exit codes: 0 success, 1 failed check (or run failure), 2 bad input.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use vista::Config;
use vista_golden::{BlessOptions, CheckOptions, GoldenError, Store};
use vista_gpu::Context;
use vista_image::metrics;
use vista_project::Project;
use vista_render::Renderer;

mod bench;
mod graph_render;
mod init;
mod matrix;
mod mutate;
mod sweep;
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
    Mutate {
        /// Only this kernel's mutants (against its golden cases).
        #[arg(long, conflicts_with = "case")]
        kernel: Option<String>,
        /// The kernels of the cases whose id matches this glob, against those cases.
        #[arg(long = "case", value_name = "GLOB")]
        case: Option<String>,
        /// Mutants per kernel, sampled with --seed (default: all).
        #[arg(long)]
        sample: Option<usize>,
        /// The sampling seed: the same seed, the same mutants.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Worker threads sharing the device.
        #[arg(long, default_value_t = 1)]
        jobs: usize,
        /// A deterministic slice of the mutants, nextest's syntax: k/n or count:k/n.
        #[arg(long)]
        partition: Option<String>,
        /// Write the report as JSON (score, mutants[] with file, line, col, operator, before, after, outcome, killed_by).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Join partition reports (JSON files) into one score and report instead of running.
        #[arg(long, num_args = 1.., value_name = "JSON")]
        merge: Vec<PathBuf>,
        /// Survivors argued equivalent (TOML [[mutant]] kernel, file, line, col, after, why):
        /// excluded from the score and listed apart.
        #[arg(long, value_name = "TOML")]
        equivalent: Option<PathBuf>,
    },
    /// Median kernel throughput after a warm-up (excludes device creation and compilation).
    Bench {
        /// The kernel's name.
        kernel: String,
        /// A preset of the kernel.
        #[arg(long)]
        preset: Option<String>,
        /// Parameter override NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
        /// Image size, WIDTHxHEIGHT.
        #[arg(long, default_value = "1024x1024")]
        size: String,
        /// Timed runs after the warm-up (the median is reported).
        #[arg(long, default_value_t = 7)]
        runs: u32,
        /// Print the result as one JSON object (field mpix_per_s among them).
        #[arg(long)]
        json: bool,
        /// Also time the kernel's CPU reference built in f32 on all cores
        /// (median of up to 3 runs) and print the CPU / GPU ratio.
        #[arg(long)]
        cpu: bool,
    },
}

/// A closed stdout (`vista list | head -1`) ends vista quietly like other
/// Unix tools: Rust ignores SIGPIPE, which turns every println! after the
/// reader left into a panic.
#[cfg(unix)]
fn die_quietly_on_closed_pipe() {
    // SAFETY: called first thing in main, before any thread starts; SIG_DFL
    // is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    #[cfg(unix)]
    die_quietly_on_closed_pipe();
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
        return match init::init(dir) {
            Ok(written) => {
                for p in &written {
                    println!("wrote {}", p.display());
                }
                println!(
                    "next: cd {} && vista bless && vista check   (then edit kernels/rings.toml and \
                     shaders/rings.wgsl, or add your own kernel beside them)",
                    dir.display()
                );
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(e.exit_code() as u8)
            }
        };
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
    match run(&project, &config, cli.command) {
        Ok(code) => ExitCode::from(code as u8),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// Splits `NAME=VALUE` pairs.
pub fn parse_sets(sets: &[String]) -> Result<Vec<(String, String)>, GoldenError> {
    sets.iter()
        .map(|s| {
            s.split_once('=')
                .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                .ok_or_else(|| GoldenError::BadInput(format!("--set '{s}' is not NAME=VALUE")))
        })
        .collect()
}

fn bad(e: impl std::fmt::Display) -> GoldenError {
    GoldenError::BadInput(e.to_string())
}

fn run(project: &Project, config: &Config, cmd: Command) -> Result<i32, GoldenError> {
    match cmd {
        Command::Init { .. } => unreachable!("init runs before a project is found"),
        Command::Watch { case, interval, timeout } => {
            let timeout = match timeout {
                Some(t) if !(t > 0.0 && t <= 86400.0) => {
                    return Err(bad(format!("--timeout {t} is out of range; allowed: (0, 86400] seconds")));
                }
                t => t.map(std::time::Duration::from_secs_f64),
            };
            watch::watch(project, config, case.as_deref(), watch::interval(interval)?, timeout)
        }
        Command::List { names } => {
            let kernels = registry(project)?;
            if names {
                for k in kernels.kernels() {
                    for p in k.presets() {
                        println!("{} {}", k.name(), p.name);
                    }
                }
            } else {
                list(&kernels);
            }
            // A broken manifest is shown, and fails the listing, but hides
            // no other kernel.
            for (name, e) in kernels.broken() {
                println!("{name} — broken manifest: {e}\n");
                eprintln!("error: kernel {name} is not usable: {e}");
            }
            // So is a kernel whose WGSL does not compose.
            let shaders = vista_render::shader_set(project)?;
            let mut bad_wgsl = 0;
            for k in kernels.kernels() {
                if let Err(e) = vista_render::composes(&shaders, k) {
                    println!("{} — bad — WGSL: {e}\n", k.name());
                    eprintln!("error: kernel {} does not compose: {e}", k.name());
                    bad_wgsl += 1;
                }
            }
            Ok(if kernels.broken().is_empty() && bad_wgsl == 0 { 0 } else { 2 })
        }
        Command::Render { kernel, preset, set, size, crop, zoom, out } => {
            let k = registry(project)?.find(&kernel).cloned().map_err(bad)?;
            let p = k.resolve(preset.as_deref(), &parse_sets(&set)?).map_err(bad)?;
            let (w, h) = vista_kernels::parse_size(&size).map_err(bad)?;
            if !(1..=16).contains(&zoom) {
                return Err(bad(format!("--zoom {zoom} is out of range; allowed: 1 to 16")));
            }
            if k.graph().is_some() {
                if crop.is_some() || zoom > 1 {
                    return Err(bad(
                        "--crop and --zoom apply to one-pass kernels; a pass graph writes every output whole",
                    ));
                }
                check_parent_writable(&out)?;
                let shaders = vista_render::shader_set(project)?;
                // Every check that needs no device (bindings, input files) before one is made.
                vista_render::check_request(&k, &p, w, h, &config.limits)?;
                let plan = vista_render::plan_graph(&shaders, project.root(), &k, &p, &[], w, h)?;
                let ctx = &Renderer {
                    ctx: Context::shared(&config.gpu)?,
                    shaders,
                    limits: config.limits,
                    root: project.root().map(Into::into),
                };
                return graph_render::render(ctx, &k, &plan, &out);
            }
            check_output_path(&out)?;
            let shaders = vista_render::shader_set(project)?;
            let plan = vista_render::plan(&shaders, &k, &p, w, h, &config.limits)?;
            // Layers and slices are stacked top to bottom: crop that image.
            let rect = crop.as_deref().map(|c| parse_crop(c, plan.width, plan.height * plan.layers)).transpose()?;
            let ctx = &Renderer {
                ctx: Context::shared(&config.gpu)?,
                shaders,
                limits: config.limits,
                root: project.root().map(Into::into),
            };
            let r = vista_render::run(ctx, &plan)?;
            let is_exr = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
            let mut img = if is_exr { r.raw.clone() } else { r.display().clone() };
            if let Some((x, y, cw, ch)) = rect {
                img = img.crop(x, y, cw, ch).expect("the crop was checked against the size");
            }
            if zoom > 1 {
                img = img.zoom(zoom);
            }
            vista_image::save(&out, &img)?;
            let shape = match plan.dimension {
                vista_gpu::Dimension::D2 if plan.layers == 1 && (plan.width, plan.height) == (w, h) => {
                    format!("{w}x{h}")
                }
                d => format!(
                    "{}x{}x{} ({} output, stacked {}x{})",
                    plan.width,
                    plan.height,
                    plan.layers,
                    d.name(),
                    plan.width,
                    plan.height * plan.layers
                ),
            };
            eprintln!(
                "rendered {kernel} {shape} on {} in {:.1} ms -> {}",
                ctx.adapter_description(),
                r.stats.gpu_wall.as_secs_f64() * 1e3,
                out.display()
            );
            if let Some((x, y)) = r.raw.first_nonfinite() {
                eprintln!("error: output has {} NaN/Inf pixels, first at ({x}, {y})", r.raw.nonfinite_count());
                return Ok(1);
            }
            if r.unwritten > 0 && !k.partial() {
                eprintln!("error: kernel {kernel}: {}", vista_golden::unwritten_problem(r.unwritten, &r.raw));
                return Ok(1);
            }
            Ok(0)
        }
        Command::Compare { a, b, json, hdr, blur, crop } => {
            let npy = |p: &Path| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy"));
            if npy(&a) || npy(&b) {
                return compare_npy(&a, &b, json);
            }
            if blur > 64 {
                return Err(bad(format!("--blur {blur} is out of range; allowed: 0 to 64")));
            }
            let (mut ia, mut ib) = (vista_image::load(&a)?, vista_image::load(&b)?);
            if let Some(c) = crop {
                let (x, y, w, h) = parse_crop(&c, ia.width.min(ib.width), ia.height.min(ib.height))?;
                let cut = |i: &vista_image::Image| i.crop(x, y, w, h).expect("the crop was checked against both sizes");
                (ia, ib) = (cut(&ia), cut(&ib));
            }
            if blur > 0 {
                (ia, ib) = (ia.box_blur(blur), ib.box_blur(blur));
            }
            let m = if hdr { metrics::compare_hdr(&ia, &ib)? } else { metrics::compare(&ia, &ib)? };
            if json {
                // Serialised from the one metrics type, so no metric is left out.
                println!("{}", serde_json::to_string(&m).map_err(|e| bad(format!("JSON encode: {e}")))?);
            } else {
                println!("PSNR       {}", metrics::format_psnr(m.psnr));
                println!("SSIM       {:.6}", m.ssim);
                match m.flip_mean {
                    Some(f) => println!("FLIP       {f:.6} (mean LDR-FLIP)"),
                    None => println!("FLIP       - (not defined for --hdr)"),
                }
                println!("max abs    {:.6e}", m.max_abs);
                println!("bad pixels {} (> 1/255)", m.bad_pixels);
                println!("NaN/Inf    {}", m.nan);
            }
            Ok(0)
        }
        Command::Check { matrix: true, junit: Some(_), .. } | Command::Check { matrix: true, json: Some(_), .. } => {
            Err(bad(
                "--junit and --json are written by a check on one backend; drop --matrix (or run check per backend)",
            ))
        }
        Command::Check { matrix: true, changed, failed, partition, .. } if changed || failed || partition.is_some() => {
            Err(bad("--changed, --failed and --partition select cases of a check on one backend; drop --matrix"))
        }
        Command::Check { case, report_dir, matrix: true, .. } => {
            matrix::matrix(project, config, case.as_deref(), report_dir)
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
        } => {
            let partition = partition.as_deref().map(vista_golden::selection::parse_partition).transpose()?;
            let pick = Pick { glob: case, changed, failed, partition, allow_orphans, jobs: jobs as usize };
            let viewers = if full_report { vista_report::Detail::All } else { vista_report::Detail::Failing };
            check(project, config, &pick, report_dir, Results { junit, json }, viewers)
        }
        Command::Bless { case, force, from_report: Some(dir), .. } => {
            let store = Store::of_project(project, "vista bless")?;
            if config.in_ci && !force {
                return Err(GoldenError::Refused(
                    "CI=true: refusing to bless goldens in CI; bless locally from the CI report, or pass --force"
                        .into(),
                ));
            }
            let shaders = vista_render::shader_set(project)?;
            let files_now = |shader: &str| -> Result<std::collections::BTreeMap<String, String>, String> {
                shaders.file_hashes(shader).map_err(|e| e.to_string())
            };
            let summary = vista_golden::pending::bless_from_report(&store, &dir, case.as_deref(), &files_now)?;
            println!("{:<40} {:<10} PSNR against the golden it replaces", "case", "status");
            for r in &summary.rows {
                println!("{:<40} {:<10} {}", r.id, r.status, r.psnr_vs_previous);
            }
            let n = summary.rows.len();
            println!(
                "accepted {n} render{} from {} as golden{}",
                if n == 1 { "" } else { "s" },
                dir.display(),
                if n == 1 { "" } else { "s" }
            );
            Ok(0)
        }
        Command::Bless { case, force, prune, per_backend, .. } => {
            let store = Store::of_project(project, "vista bless")?;
            let ctx = &Renderer::new(Context::shared(&config.gpu)?, project, config.limits)?;
            let opts = BlessOptions { glob: case, force, prune, in_ci: config.in_ci, per_backend };
            let summary = vista_golden::bless(ctx, &store, &opts)?;
            println!("{:<40} {:<10} PSNR new vs old", "case", "status");
            for r in &summary.rows {
                println!("{:<40} {:<10} {}", r.id, r.status, r.psnr_vs_previous);
            }
            for w in &summary.warnings {
                println!("warning: {w}");
            }
            for o in &summary.orphans {
                println!(
                    "{} golden with no case: {}",
                    if summary.pruned { "deleted" } else { "orphaned" },
                    o.display()
                );
            }
            let n = summary.rows.len();
            println!("blessed {n} case{} on {}", if n == 1 { "" } else { "s" }, ctx.adapter_description());
            Ok(0)
        }
        Command::Sweep(args) => sweep::sweep(project, config, args),
        Command::Mutate { kernel, case, sample, seed, jobs, partition, json, merge, equivalent } => mutate::mutate(
            project,
            config,
            mutate::Args { kernel, case, sample, seed, jobs, partition, json, merge, equivalent },
        ),
        Command::Bench { kernel, preset, set, size, runs, json, cpu } => {
            bench::bench(project, config, &kernel, preset.as_deref(), &set, &size, runs, json, cpu)
        }
    }
}

/// `X,Y,W,H` inside a `width` x `height` frame.
fn parse_crop(text: &str, width: u32, height: u32) -> Result<(u32, u32, u32, u32), GoldenError> {
    let allowed = format!("X,Y,W,H in pixels with W, H >= 1, X + W <= {width} and Y + H <= {height} (the image)");
    let v: Vec<u32> = text
        .split(',')
        .map(|s| s.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad(format!("--crop {text} is not valid; expected {allowed}")))?;
    match v[..] {
        [x, y, w, h]
            if w >= 1 && h >= 1 && x as u64 + w as u64 <= width as u64 && y as u64 + h as u64 <= height as u64 =>
        {
            Ok((x, y, w, h))
        }
        _ => Err(bad(format!("--crop {text} does not fit; expected {allowed}"))),
    }
}

/// Refuses an output path whose directory does not exist or is not writable,
/// before any GPU work.
/// `vista compare` of two `.npy` buffers: the same dtype and shape, then
/// max-abs, max-rel, RMSE, the count that differ and the worst elements.
fn compare_npy(a: &Path, b: &Path, json: bool) -> Result<i32, GoldenError> {
    let (na, nb) = (vista_image::npy::read_npy(a)?, vista_image::npy::read_npy(b)?);
    if (na.descr.as_str(), &na.shape) != (nb.descr.as_str(), &nb.shape) {
        return Err(bad(format!(
            "{} is {} {:?} but {} is {} {:?}; compare buffers of one dtype and shape",
            a.display(),
            na.descr,
            na.shape,
            b.display(),
            nb.descr,
            nb.shape
        )));
    }
    let (va, vb) = (
        vista_image::npy::values(&na).map_err(|e| bad(format!("{}: {e}", a.display())))?,
        vista_image::npy::values(&nb).map_err(|e| bad(format!("{}: {e}", b.display())))?,
    );
    let diff: Vec<f64> = va.iter().zip(&vb).map(|(x, y)| (x - y).abs()).collect();
    let max_abs = diff.iter().copied().fold(0.0, f64::max);
    let max_rel = va.iter().zip(&diff).map(|(x, d)| d / x.abs().max(f64::MIN_POSITIVE)).fold(0.0, f64::max);
    let rmse = (diff.iter().map(|d| d * d).sum::<f64>() / diff.len().max(1) as f64).sqrt();
    let differ = va.iter().zip(&vb).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
    let mut worst: Vec<usize> = (0..diff.len()).filter(|i| diff[*i] > 0.0).collect();
    worst.sort_by(|x, y| diff[*y].total_cmp(&diff[*x]));
    worst.truncate(5);
    if json {
        let w: Vec<serde_json::Value> =
            worst.iter().map(|&i| serde_json::json!({ "index": i, "a": va[i], "b": vb[i] })).collect();
        let v = serde_json::json!({
            "values": va.len(), "differ": differ, "max_abs": max_abs, "max_rel": max_rel, "rmse": rmse, "worst": w,
        });
        println!("{v}");
    } else {
        println!("values     {} ({} {:?})", va.len(), na.descr, na.shape);
        println!("differ     {differ}");
        println!("max abs    {max_abs:.6e}");
        println!("max rel    {max_rel:.6e}");
        println!("RMSE       {rmse:.6e}");
        for &i in &worst {
            println!("  [{i}] {} vs {}", va[i], vb[i]);
        }
    }
    Ok(0)
}

fn check_output_path(out: &Path) -> Result<(), GoldenError> {
    let ext_ok = out
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png") || e.eq_ignore_ascii_case("exr"));
    if !ext_ok {
        return Err(bad(format!("output {} must end in .png or .exr", out.display())));
    }
    check_parent_writable(out)
}

/// The directory a file will be written into exists, is one, and is writable.
fn check_parent_writable(file: &Path) -> Result<(), GoldenError> {
    let dir = match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if dir.exists() && !dir.is_dir() {
        return Err(bad(format!("output directory {} is not a directory (it is a file)", dir.display())));
    }
    if !dir.is_dir() {
        return Err(bad(format!("output directory {} does not exist", dir.display())));
    }
    probe_writable(&dir)
}

/// Creates the output directory of a sweep if needed and checks it is writable.
pub fn check_output_dir(dir: &Path) -> Result<(), GoldenError> {
    if dir.exists() && !dir.is_dir() {
        return Err(bad(format!("--out {} exists and is not a directory", dir.display())));
    }
    std::fs::create_dir_all(dir).map_err(|e| bad(format!("cannot create output directory {}: {e}", dir.display())))?;
    probe_writable(dir)
}

fn probe_writable(dir: &Path) -> Result<(), GoldenError> {
    let probe = dir.join(format!(".vista-write-probe-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| bad(format!("output directory {} is not writable: {e}", dir.display())))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// Which cases a check runs: `--case`, then `--changed`, `--failed`,
/// `--partition` (each narrows the one before).
struct Pick {
    glob: Option<String>,
    changed: bool,
    failed: bool,
    partition: Option<(u64, u64)>,
    /// Orphaned goldens warn instead of failing.
    allow_orphans: bool,
    /// Cases checked at once (`--jobs`).
    jobs: usize,
}

/// Machine-readable results a check also writes.
struct Results {
    junit: Option<PathBuf>,
    json: Option<PathBuf>,
}

/// A results file's directory must exist and be writable, before any GPU work.
fn check_results_path(flag: &str, path: &Path) -> Result<(), GoldenError> {
    if path.is_dir() {
        return Err(bad(format!("{flag} {} is a directory; expected a file path", path.display())));
    }
    check_parent_writable(path).map_err(|e| bad(format!("{flag} {}: {e}", path.display())))
}

fn check(
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
    // Selection needs no device: hashes from the project's WGSL, the last report.
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
            vista_golden::selection::change(c, &manifest, &files).is_some()
        });
        why.push("--changed".into());
    }
    if pick.failed {
        let failures = vista_golden::selection::last_failures(&report_dir)?;
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
            let label = match o.verdict {
                vista_golden::Verdict::Pass => "ok",
                vista_golden::Verdict::ExpectedFail => "xfail",
                _ => "FAIL",
            };
            // A per-backend golden is named on the case's line.
            let per_backend = match o.golden_file.rsplit_once('@') {
                Some((_, b)) => format!("  [golden @{}]", b.trim_end_matches(".png")),
                None => String::new(),
            };
            println!("{label:<6} {:<40} {:<17} {:>8.1} ms{per_backend}", o.id, o.headline(), o.gpu_ms);
            if !o.passed() {
                print!("{}", o.explain(&report_dir));
            } else if o.verdict == vista_golden::Verdict::ExpectedFail {
                o.notes.iter().for_each(|n| println!("  note: {n}"));
            }
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
        // Paths relative to the working directory, where the workflow runs.
        let cases = store.cases_path();
        let shown = std::env::current_dir()
            .ok()
            .and_then(|cwd| cases.strip_prefix(&cwd).ok().map(Path::to_path_buf))
            .unwrap_or_else(|| cases.clone());
        let text = std::fs::read_to_string(&cases).unwrap_or_default();
        for line in vista_report::github_annotations(&outcomes, &shown.display().to_string(), &text) {
            println!("{line}");
        }
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

/// The project's kernels (its manifests over the built-ins).
pub fn registry(project: &Project) -> Result<vista_kernels::Registry, GoldenError> {
    vista_kernels::Registry::of_project(project).map_err(bad)
}

fn list(kernels: &vista_kernels::Registry) {
    for k in kernels.kernels() {
        println!("{} — {}", k.name(), k.summary());
        println!("  params:");
        for p in k.params() {
            println!("    {:<22} default {:<14} {:<40} {}", p.name, p.default, p.kind.range_text(), p.doc);
        }
        println!("  presets:");
        for p in k.presets() {
            let set = p.set.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ");
            println!(
                "    {:<22} {}{}",
                p.name,
                p.doc,
                if set.is_empty() { String::new() } else { format!("  [{set}]") }
            );
        }
        println!();
    }
}
