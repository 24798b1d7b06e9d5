//! The one configuration of a vista process, built at the edge (the `vista`
//! binary, a test harness) from its flags and the environment, read once,
//! and passed down in parts: the GPU context's, the render limits, the bless
//! policy, the plot font, the browser path. No library crate reads the
//! environment; a test below greps them to keep it so.

use std::ffi::OsString;
use std::path::PathBuf;

use std::time::Duration;
use vista_golden::GoldenError;

use vista_gpu::{AdapterChoice, AdapterSettings, GpuConfig};
use vista_render::RenderLimits;

/// Everything vista's libraries are told from outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    /// Adapter, validation layer, watchdog, wgpu backends, Chromium.
    pub gpu: GpuConfig,
    /// `VISTA_MAX_WORK` and `VISTA_MAX_BYTES`: the caps on a render's
    /// work estimate and memory.
    pub limits: RenderLimits,
    /// `VISTA_COMPILE_TIMEOUT_S`: how long composing and validating one
    /// shader may take (default a minute).
    pub compile_timeout: Duration,
    /// `CI` set (to anything but 0 or false): bless is refused without `--force`.
    pub in_ci: bool,
    /// `VISTA_ALLOW_NO_GPU=1`: without an adapter, GPU tests are reported
    /// skipped (loudly) instead of failing.
    pub allow_no_gpu: bool,
    /// `VISTA_COVERAGE=1`: the harness also runs each case with coverage
    /// counters (as `vista check --coverage`).
    pub coverage: bool,
    /// `VISTA_FONT`: the font file for plot text.
    pub font: Option<PathBuf>,
    /// `VISTA_ROOT`: the project root, after `--root`.
    pub root: Option<OsString>,
    /// The crate directory cargo gives a test process (at run time, never
    /// at build time): where `vista::harness` looks for the project.
    pub crate_dir: Option<PathBuf>,
    /// `VISTA_FAULT`: fault-injection plan for the write-path tests.
    pub fault: Option<String>,
    /// `VISTA_WORKER_FAULT=<segv|abort|hang>:<case id>`: the worker
    /// raises that fault on that case (tests of the crash path).
    pub worker_fault: Option<(vista_render::worker::Fault, String)>,
    /// GPU work in worker processes (`VISTA_WORKERS`, default 1; 0 runs it
    /// in this process, where a driver crash ends the run).
    pub workers: bool,
    /// `GITHUB_ACTIONS=true`: check also prints `::error` annotations.
    pub github_actions: bool,
    /// `NEXTEST` set: the test runner is cargo-nextest, which starts a
    /// process per test, so the harness's processes share one report.
    pub nextest: bool,
    /// `NEXTEST_RUN_ID`: the id nextest gives every test process of one
    /// `cargo nextest run`.
    pub nextest_run_id: Option<String>,
    /// `VISTA_REPORT_DIR`: the harness's report folder (relative to the
    /// project root), instead of the project's `target/vista-report*`
    /// (`vista check` takes `--report-dir`).
    pub report_dir: Option<PathBuf>,
    /// `VISTA_JUNIT`: the harness also writes the run's cases as JUnit XML
    /// there, relative to the project root (`vista check` takes `--junit`).
    pub junit: Option<PathBuf>,
    /// `MESA_SHADER_CACHE_DIR` is set: the user placed Mesa's shader cache,
    /// so the binary leaves it where it is (else it goes under the
    /// project's `target/vista-cache/mesa`, see [`MESA_CACHE`]).
    pub mesa_cache_placed: bool,
    /// `VK_INSTANCE_LAYERS`, `VK_LOADER_LAYERS_ENABLE` or
    /// `VK_LOADER_LAYERS_DISABLE` is set: the user chose Vulkan layers, so
    /// the binary leaves the loader alone (see [`Config::hidden_layers`]).
    pub vulkan_layers_chosen: bool,
    /// `VK_DRIVER_FILES`, `VK_ICD_FILENAMES`, `VK_ADD_DRIVER_FILES`,
    /// `VK_LOADER_DRIVERS_SELECT` or `VK_LOADER_DRIVERS_DISABLE` is set: the
    /// user chose Vulkan drivers, so the binary leaves the loader alone (see
    /// [`Config::hidden_drivers`]).
    pub vulkan_drivers_chosen: bool,
    /// `XDG_RUNTIME_DIR` is set: otherwise Mesa's drivers print "error:
    /// XDG_RUNTIME_DIR is invalid or not set in the environment." twice in
    /// every process (containers CI jobs run in leave it unset), and the
    /// binary gives them a private one ([`Config::private_runtime_dir`]).
    pub runtime_dir_set: bool,
}

/// Where under a project root the binary places Mesa's shader cache
/// (lavapipe's compiled pipelines) unless `MESA_SHADER_CACHE_DIR` is set:
/// beside the report under `target/`, the folder CI jobs cache, so a warm
/// check compiles nothing even on a fresh runner that restores it.
pub const MESA_CACHE: &str = "target/vista-cache/mesa";

/// The command-line flags that override the environment.
#[derive(Debug, Clone, Default)]
pub struct Flags {
    /// `--backend NAME`.
    pub backend: Option<String>,
    /// `--adapter cpu|gpu`.
    pub adapter: Option<String>,
}

fn truthy(name: &str, v: Option<String>) -> Result<bool, GoldenError> {
    vista_project::truthy(name, v.as_deref()).map_err(GoldenError::BadInput)
}

/// Serves as a GPU worker and exits, when another vista process started
/// this one as one (`VISTA_WORKER`); call it first in `main`, before
/// anything prints or reads arguments.
pub fn serve_worker_if_asked() {
    if std::env::var_os(vista_render::worker::WORKER_VAR).is_some() {
        std::process::exit(vista_render::worker::serve_and_exit_code());
    }
}

impl Config {
    /// Applies the settings that are the process's: the composition time
    /// limit, and GPU work in workers re-executed from this very binary
    /// (which calls `vista_render::worker::serve_if_asked` first), unless
    /// `VISTA_WORKERS=0`.
    pub fn apply_to_process(&self) {
        vista_gpu::set_compose_limit(self.compile_timeout);
        if let (true, Ok(exe)) = (self.workers, std::env::current_exe()) {
            vista_render::worker::enable(exe, self.worker_fault.clone());
        }
    }

    /// The configuration of `flags` over settings looked up by name: flags
    /// first, then the variables. A value that does not parse is bad input
    /// naming the variable and what is allowed.
    pub fn from_lookup(flags: &Flags, get: &dyn Fn(&str) -> Option<OsString>) -> Result<Config, GoldenError> {
        let text = |k: &str| get(k).map(|v| v.to_string_lossy().into_owned());
        let adapter = AdapterSettings {
            backend_flag: flags.backend.clone(),
            adapter_flag: flags.adapter.clone(),
            wgpu_adapter_name: text("WGPU_ADAPTER_NAME"),
            backend_env: text("VISTA_BACKEND"),
            adapter_env: text("VISTA_ADAPTER"),
        };
        let max_work = match text("VISTA_MAX_WORK").filter(|v| !v.is_empty()) {
            None => vista_render::DEFAULT_MAX_WORK,
            Some(v) => v.parse::<f64>().ok().filter(|w| w.is_finite() && *w > 0.0).ok_or_else(|| {
                GoldenError::BadInput(format!(
                    "VISTA_MAX_WORK={v} is not valid; expected a positive number such as 4e10"
                ))
            })?,
        };
        let compile_timeout = match text("VISTA_COMPILE_TIMEOUT_S").filter(|v| !v.is_empty()) {
            None => vista_gpu::DEFAULT_COMPOSE_LIMIT,
            Some(v) => {
                v.parse::<f64>().ok().filter(|s| s.is_finite() && *s > 0.0).map(Duration::from_secs_f64).ok_or_else(
                    || {
                        GoldenError::BadInput(format!(
                            "VISTA_COMPILE_TIMEOUT_S={v} is not valid; expected a number of seconds > 0"
                        ))
                    },
                )?
            }
        };
        let max_bytes = match text("VISTA_MAX_BYTES").filter(|v| !v.is_empty()) {
            None => vista_render::DEFAULT_MAX_BYTES,
            Some(v) => {
                v.parse::<f64>().ok().filter(|b| b.is_finite() && *b >= 1.0).map(|b| b as u64).ok_or_else(|| {
                    GoldenError::BadInput(format!(
                        "VISTA_MAX_BYTES={v} is not valid; expected a number of bytes such as 8e9"
                    ))
                })?
            }
        };
        Ok(Config {
            gpu: GpuConfig {
                adapter: AdapterChoice::from_settings(&adapter)?,
                validate: truthy("VISTA_VALIDATION", text("VISTA_VALIDATION"))?,
                timeout: match text("VISTA_GPU_TIMEOUT_S").filter(|v| !v.is_empty()) {
                    None => vista_gpu::DEFAULT_TIMEOUT,
                    Some(v) => v
                        .parse::<f64>()
                        .ok()
                        .filter(|s| s.is_finite() && *s >= 0.0)
                        .map(Duration::from_secs_f64)
                        .ok_or_else(|| {
                            GoldenError::BadInput(format!(
                                "VISTA_GPU_TIMEOUT_S={v} is not valid; expected a number of seconds >= 0"
                            ))
                        })?,
                },
                wgpu_backends: text("WGPU_BACKEND").filter(|v| !v.is_empty()),
                browser: vista_browser::BrowserConfig::from_lookup(get),
            },
            limits: RenderLimits { max_work, max_bytes },
            compile_timeout,
            // CI systems spell it true, 1 or their own name (CI=woodpecker).
            in_ci: text("CI").is_some_and(|v| !matches!(v.to_ascii_lowercase().as_str(), "" | "0" | "false")),
            allow_no_gpu: truthy("VISTA_ALLOW_NO_GPU", text("VISTA_ALLOW_NO_GPU"))?,
            coverage: truthy("VISTA_COVERAGE", text("VISTA_COVERAGE"))?,
            font: get("VISTA_FONT").filter(|v| !v.is_empty()).map(PathBuf::from),
            root: get("VISTA_ROOT").filter(|v| !v.is_empty()),
            crate_dir: get("CARGO_MANIFEST_DIR").filter(|v| !v.is_empty()).map(PathBuf::from),
            github_actions: text("GITHUB_ACTIONS").is_some_and(|v| v.eq_ignore_ascii_case("true")),
            nextest: get("NEXTEST").is_some_and(|v| !v.is_empty()) || get("NEXTEST_RUN_ID").is_some(),
            nextest_run_id: text("NEXTEST_RUN_ID").filter(|v| !v.is_empty()),
            report_dir: get("VISTA_REPORT_DIR").filter(|v| !v.is_empty()).map(PathBuf::from),
            junit: get("VISTA_JUNIT").filter(|v| !v.is_empty()).map(PathBuf::from),
            fault: text("VISTA_FAULT"),
            worker_fault: match text("VISTA_WORKER_FAULT").filter(|v| !v.is_empty()) {
                None => None,
                Some(v) => Some(
                    vista_render::worker::Fault::parse(&v)
                        .map_err(|e| GoldenError::BadInput(format!("VISTA_WORKER_FAULT={v}: {e}")))?,
                ),
            },
            workers: match text("VISTA_WORKERS").filter(|v| !v.is_empty()) {
                None => true,
                v => truthy("VISTA_WORKERS", v)?,
            },
            mesa_cache_placed: get("MESA_SHADER_CACHE_DIR").is_some_and(|v| !v.is_empty()),
            vulkan_layers_chosen: ["VK_INSTANCE_LAYERS", "VK_LOADER_LAYERS_ENABLE", "VK_LOADER_LAYERS_DISABLE"]
                .iter()
                .any(|k| get(k).is_some_and(|v| !v.is_empty())),
            vulkan_drivers_chosen: [
                "VK_DRIVER_FILES",
                "VK_ICD_FILENAMES",
                "VK_ADD_DRIVER_FILES",
                "VK_LOADER_DRIVERS_SELECT",
                "VK_LOADER_DRIVERS_DISABLE",
            ]
            .iter()
            .any(|k| get(k).is_some_and(|v| !v.is_empty())),
            runtime_dir_set: get("XDG_RUNTIME_DIR").is_some_and(|v| !v.is_empty()),
        })
    }

    /// The runtime directory the binary gives the drivers when the
    /// environment names none: one per user under the temporary folder,
    /// as a login session would give (`None` where one is set).
    pub fn private_runtime_dir(&self, uid: u32) -> Option<PathBuf> {
        (!self.runtime_dir_set).then(|| std::env::temp_dir().join(format!("vista-runtime-{uid}")))
    }

    /// The Vulkan loader's variable, and its value, that keep the Khronos
    /// validation layer out of a `vista` process that will not validate.
    /// wgpu opens the layer whenever it is installed (to ask what it
    /// supports), and loading it was 81 of a small render's 673 million
    /// instructions (callgrind); the CLI suite and `make demo` start
    /// hundreds of `vista` processes. `None` under `VISTA_VALIDATION=1`, or
    /// when the user chose layers through the loader's own variables.
    pub fn hidden_layers(&self) -> Option<(&'static str, &'static str)> {
        (!self.gpu.validate && !self.vulkan_layers_chosen)
            .then_some(("VK_LOADER_LAYERS_DISABLE", "VK_LAYER_KHRONOS_validation"))
    }

    /// The Vulkan loader's variable, and its value, that keep a `vista`
    /// process on a software backend (lavapipe, SwiftShader, or the browser,
    /// and `check --matrix` with the first two) to the two software drivers'
    /// manifests (Mesa's `lvp_icd.*.json`, SwiftShader's `*swiftshader*`):
    /// the loader otherwise opens every installed driver (Mesa's Intel and
    /// Radeon ones on Debian, a vendor's on a workstation) to enumerate
    /// adapters vista will not pick, 8.5% of a small render's instructions
    /// here (callgrind, 427 to 391 million). `None` for `--backend gpu` or a
    /// named adapter, or when the user chose drivers through the loader's
    /// own variables. Loaders older than 1.3.234 ignore the variable.
    pub fn hidden_drivers(&self) -> Option<(&'static str, &'static str)> {
        use vista_gpu::AdapterChoice as A;
        let software = matches!(self.gpu.adapter, A::Lavapipe | A::SwiftShader | A::Browser);
        (software && !self.vulkan_drivers_chosen).then_some(("VK_LOADER_DRIVERS_SELECT", "*lvp*,*swiftshader*"))
    }

    /// The configuration of `flags` over this process's environment.
    pub fn from_env(flags: &Flags) -> Result<Config, GoldenError> {
        Config::from_lookup(flags, &|k| std::env::var_os(k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn config(flags: &Flags, vars: &[(&str, &str)]) -> Result<Config, GoldenError> {
        let vars: HashMap<String, OsString> = vars.iter().map(|(k, v)| (k.to_string(), OsString::from(v))).collect();
        Config::from_lookup(flags, &|k| vars.get(k).cloned())
    }

    #[test]
    fn flags_come_before_the_environment() {
        use vista_gpu::AdapterChoice as A;
        let env = [("VISTA_BACKEND", "swiftshader"), ("VISTA_ADAPTER", "gpu")];
        assert_eq!(config(&Flags::default(), &env).unwrap().gpu.adapter, A::SwiftShader);
        let flag = Flags { backend: Some("browser".into()), adapter: None };
        assert_eq!(config(&flag, &env).unwrap().gpu.adapter, A::Browser);
        let flag = Flags { backend: None, adapter: Some("cpu".into()) };
        assert_eq!(config(&flag, &env).unwrap().gpu.adapter, A::Lavapipe);
        assert_eq!(config(&Flags::default(), &[("VISTA_ADAPTER", "gpu")]).unwrap().gpu.adapter, A::Hardware);
        assert_eq!(config(&Flags::default(), &[]).unwrap().gpu.adapter, A::Lavapipe);
        let named = config(&Flags::default(), &[("WGPU_ADAPTER_NAME", "llvm"), ("VISTA_BACKEND", "gpu")]).unwrap();
        assert_eq!(named.gpu.adapter, A::Named("llvm".into()));
    }

    #[test]
    fn every_setting_is_read_from_the_lookup() {
        let c = config(
            &Flags::default(),
            &[
                ("VISTA_MAX_WORK", "1e6"),
                ("CI", "true"),
                ("VISTA_ALLOW_NO_GPU", "1"),
                ("VISTA_COVERAGE", "1"),
                ("VISTA_FONT", "/f.ttf"),
                ("VISTA_VALIDATION", "1"),
                ("VISTA_GPU_TIMEOUT_S", "7.5"),
                ("VISTA_COMPILE_TIMEOUT_S", "2.5"),
                ("VISTA_CHROMIUM", "/c"),
                ("VISTA_ROOT", "/r"),
                ("VISTA_FAULT", "x"),
                ("NEXTEST", "1"),
                ("NEXTEST_RUN_ID", "1f79aa0d-4ec8-4a5c-aa83-5e8dc2f36573"),
                ("VISTA_REPORT_DIR", "shard-1"),
                ("VISTA_JUNIT", "j.xml"),
            ],
        )
        .unwrap();
        assert_eq!(c.limits.max_work, 1e6);
        assert!(c.in_ci && c.allow_no_gpu && c.gpu.validate && c.coverage);
        assert_eq!(c.font.as_deref(), Some(std::path::Path::new("/f.ttf")));
        assert_eq!(c.gpu.timeout, std::time::Duration::from_secs_f64(7.5));
        assert_eq!(c.compile_timeout, std::time::Duration::from_secs_f64(2.5));
        assert_eq!(c.gpu.browser.chromium.as_deref(), Some(std::path::Path::new("/c")));
        assert_eq!(c.root.as_deref(), Some(std::ffi::OsStr::new("/r")));
        assert_eq!(c.fault.as_deref(), Some("x"));
        assert!(c.nextest);
        assert_eq!(c.nextest_run_id.as_deref(), Some("1f79aa0d-4ec8-4a5c-aa83-5e8dc2f36573"));
        assert_eq!(c.report_dir.as_deref(), Some(std::path::Path::new("shard-1")));
        assert_eq!(c.junit.as_deref(), Some(std::path::Path::new("j.xml")));
        let d = config(&Flags::default(), &[]).unwrap();
        assert!(!d.nextest && d.nextest_run_id.is_none() && d.report_dir.is_none() && d.junit.is_none());
        assert_eq!(d.limits.max_work, vista_render::DEFAULT_MAX_WORK);
        assert!(!d.in_ci && !d.allow_no_gpu && !d.gpu.validate && !d.coverage);
        for (ci, is) in [("woodpecker", true), ("1", true), ("0", false), ("false", false)] {
            assert_eq!(config(&Flags::default(), &[("CI", ci)]).unwrap().in_ci, is, "CI={ci}");
        }
    }

    #[test]
    fn a_bad_value_names_the_variable_and_what_is_allowed() {
        for (var, value, allowed) in [
            ("VISTA_MAX_WORK", "lots", "positive number"),
            ("VISTA_BACKEND", "metal", "lavapipe|swiftshader|browser|gpu"),
            ("VISTA_ADAPTER", "fast", "cpu|gpu"),
            ("VISTA_GPU_TIMEOUT_S", "-1", "seconds"),
            ("VISTA_COMPILE_TIMEOUT_S", "0", "seconds > 0"),
            ("VISTA_VALIDATION", "yes", "1|0|true|false"),
            ("VISTA_ALLOW_NO_GPU", "maybe", "1|0|true|false"),
        ] {
            let e = config(&Flags::default(), &[(var, value)]).unwrap_err().to_string();
            assert!(e.contains(var) && e.contains(value) && e.contains(allowed), "{var}: {e}");
            assert_eq!(config(&Flags::default(), &[(var, value)]).unwrap_err().exit_code(), 2, "{var}");
        }
    }

    #[test]
    fn the_validation_layer_is_hidden_only_when_nothing_asks_for_it() {
        let none = Flags::default();
        let hide = Some(("VK_LOADER_LAYERS_DISABLE", "VK_LAYER_KHRONOS_validation"));
        assert_eq!(config(&none, &[]).unwrap().hidden_layers(), hide);
        let validating = config(&none, &[("VISTA_VALIDATION", "1")]).unwrap();
        assert_eq!(validating.hidden_layers(), None, "VISTA_VALIDATION=1 needs the layer");
        for var in ["VK_INSTANCE_LAYERS", "VK_LOADER_LAYERS_ENABLE", "VK_LOADER_LAYERS_DISABLE"] {
            let chosen = config(&none, &[(var, "VK_LAYER_KHRONOS_validation")]).unwrap();
            assert_eq!(chosen.hidden_layers(), None, "{var} is the user's choice");
            assert_eq!(config(&none, &[(var, "")]).unwrap().hidden_layers(), hide, "{var} empty chooses nothing");
        }
    }

    #[test]
    fn only_the_software_drivers_are_loaded_unless_asked_otherwise() {
        let select = Some(("VK_LOADER_DRIVERS_SELECT", "*lvp*,*swiftshader*"));
        for backend in ["lavapipe", "swiftshader", "browser"] {
            let flags = Flags { backend: Some(backend.into()), adapter: None };
            assert_eq!(config(&flags, &[]).unwrap().hidden_drivers(), select, "{backend}");
        }
        assert_eq!(config(&Flags::default(), &[]).unwrap().hidden_drivers(), select, "the default, lavapipe");
        let gpu = Flags { backend: Some("gpu".into()), adapter: None };
        assert_eq!(config(&gpu, &[]).unwrap().hidden_drivers(), None, "a hardware GPU needs its driver");
        let named = config(&Flags::default(), &[("WGPU_ADAPTER_NAME", "radv")]).unwrap();
        assert_eq!(named.hidden_drivers(), None, "a named adapter may be any driver's");
        for var in [
            "VK_DRIVER_FILES",
            "VK_ICD_FILENAMES",
            "VK_ADD_DRIVER_FILES",
            "VK_LOADER_DRIVERS_SELECT",
            "VK_LOADER_DRIVERS_DISABLE",
        ] {
            let chosen = config(&Flags::default(), &[(var, "/opt/my_icd.json")]).unwrap();
            assert_eq!(chosen.hidden_drivers(), None, "{var} is the user's choice");
            assert_eq!(config(&Flags::default(), &[(var, "")]).unwrap().hidden_drivers(), select, "{var} empty");
        }
    }

    /// The non-test sources of every library crate (all of `crates/` but the
    /// binary) read no environment variable, and only the binary's start
    /// sets one.
    #[test]
    fn no_library_crate_reads_the_environment() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut offenders = Vec::new();
        let mut files = Vec::new();
        let mut dirs = vec![root.join("crates"), root.join("src")];
        while let Some(d) = dirs.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let p = e.path();
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                if p.is_dir() {
                    // Integration tests and benches are edges of their own.
                    if !matches!(name.as_str(), "tests" | "benches" | "target") {
                        dirs.push(p);
                    }
                } else if name.ends_with(".rs") {
                    files.push(p);
                }
            }
        }
        assert!(files.len() > 40, "found only {} sources under crates/ and src/", files.len());
        let binary = root.join("crates/vista-cli");
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            // Unit tests sit in a trailing `#[cfg(test)]` module.
            let code = text.split("#[cfg(test)]").next().unwrap();
            let rel = f.strip_prefix(root).unwrap().display().to_string();
            for (n, line) in code.lines().enumerate() {
                let line = line.trim_start();
                if line.starts_with("//") {
                    continue;
                }
                let reads = ["env::var(", "env::var_os(", "env::vars(", "env::vars_os(", "Backends::from_env("];
                let writes = ["set_var(", "remove_var("];
                let at_edge = f.starts_with(&binary) || rel == "src/config.rs";
                // The writes: the binary's main places Mesa's shader cache
                // and hides an unused Vulkan layer and unused drivers, before
                // any thread or device exists (see MESA_CACHE,
                // Config::hidden_layers, Config::hidden_drivers).
                let at_start = rel == "crates/vista-cli/src/main.rs"
                    && (line.contains("std::env::set_var(\"MESA_SHADER_CACHE_DIR\", dir)")
                        || line.contains("std::env::set_var(\"XDG_RUNTIME_DIR\", dir)")
                        || line.contains("std::env::set_var(name, value)"));
                if (writes.iter().any(|w| line.contains(w)) && !at_start)
                    || (!at_edge && reads.iter().any(|r| line.contains(r)))
                {
                    offenders.push(format!("{rel}:{}: {line}", n + 1));
                }
            }
        }
        assert!(offenders.is_empty(), "environment read or written outside the edge:\n{}", offenders.join("\n"));
    }
}
