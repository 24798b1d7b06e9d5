//! WGSL loading and composition.
//!
//! Kernel files import shared pieces from `lib/` with
//! naga_oil's `#import` (each lib file declares `#define_import_path
//! vista::NAME`). Composition yields a validated `naga::Module`; errors carry
//! the file and line.

use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex};

use naga_oil::compose::{ComposableModuleDescriptor, Composer, ComposerError, NagaModuleDescriptor, ShaderLanguage};

use crate::GpuError;

/// The set of WGSL sources a project has: library modules (`lib/...`,
/// each declaring `#define_import_path vista::NAME`) and kernel files.
/// Built from text the caller read (the project layer over the built-ins),
/// so this crate reads no files.
#[derive(Debug, Clone)]
pub struct ShaderSet {
    /// Names the set in errors (a project root, or "built-in").
    label: String,
    /// (path relative to `shaders/`, source) of every file under `lib/`, sorted.
    lib: Vec<(String, String)>,
    /// Kernel files (not under `lib/`): relative path -> (source, origin path).
    kernels: BTreeMap<String, (String, String)>,
    /// Composed modules by kernel file: the sources never change once the
    /// set is built, so each file is composed once per set.
    composed: Arc<Mutex<HashMap<String, Arc<naga::Module>>>>,
}

impl ShaderSet {
    /// A set from `(relative path, text, origin)` triples; files under
    /// `lib/` are import modules, the rest kernel files. `origin` (a real
    /// path or `<built-in>/...`) is what errors name.
    pub fn from_files(label: &str, files: impl IntoIterator<Item = (String, String, String)>) -> ShaderSet {
        let mut lib = Vec::new();
        let mut kernels = BTreeMap::new();
        for (rel, text, origin) in files {
            // An import module is a file under lib/ or any file with its own
            // `#define_import_path` (a project's foreign module layout).
            if rel.starts_with("lib/") || import_path(&text).is_some() {
                lib.push((rel, text));
            } else {
                kernels.insert(rel, (text, origin));
            }
        }
        lib.sort();
        ShaderSet { label: label.to_string(), lib, kernels, composed: Default::default() }
    }

    /// What this set is (a project root, or "built-in").
    pub fn label(&self) -> &str {
        &self.label
    }

    /// Every kernel file (not `lib/`), relative names, sorted.
    pub fn kernel_files(&self) -> Vec<String> {
        self.kernels.keys().cloned().collect()
    }

    /// `name` is a kernel file, optionally followed by `?DEF&DEF...`: naga_oil
    /// shader defs (boolean) to compose it with, e.g. `fbm.wgsl?VISTA_HASH_PLANE`.
    fn kernel_source(&self, name: &str) -> Result<&(String, String), GpuError> {
        let name = name.split_once('?').map_or(name, |(file, _)| file);
        self.kernels.get(name).ok_or_else(|| {
            GpuError::Shader(format!(
                "shader {name} not found in {} (kernel files: {})",
                self.label,
                self.kernels.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })
    }

    /// A composer holding every library module. naga_oil wants a module's
    /// imports added before it, so modules are added in rounds until all fit.
    fn composer(&self) -> Result<Composer, GpuError> {
        let mut composer = Composer::default();
        let mut pending: Vec<&(String, String)> = self.lib.iter().collect();
        while !pending.is_empty() {
            let mut failed = Vec::new();
            let mut last_error = None;
            for entry in &pending {
                let (path, source) = (&entry.0, &entry.1);
                let desc = ComposableModuleDescriptor {
                    source,
                    file_path: path,
                    language: ShaderLanguage::Wgsl,
                    as_name: None,
                    additional_imports: &[],
                    shader_defs: HashMap::new(),
                };
                if let Err(e) = composer.add_composable_module(desc) {
                    last_error = Some(describe(&composer, &self.label, &e));
                    failed.push(*entry);
                }
            }
            if failed.len() == pending.len() {
                return Err(GpuError::Shader(last_error.unwrap_or_default()));
            }
            pending = failed;
        }
        Ok(composer)
    }

    /// Composes and validates the kernel file `name` (relative to
    /// `shaders/`), once per set.
    pub fn compose(&self, name: &str) -> Result<Arc<naga::Module>, GpuError> {
        if let Some(m) = self.composed.lock().expect("compose cache").get(name) {
            return Ok(m.clone());
        }
        let module = Arc::new(self.compose_uncached(name)?);
        self.composed.lock().expect("compose cache").insert(name.to_string(), module.clone());
        Ok(module)
    }

    fn compose_uncached(&self, name: &str) -> Result<naga::Module, GpuError> {
        let (source, origin) = self.kernel_source(name)?;
        // A file without preprocessor directives needs no composition; naga
        // parses it directly. naga_oil 0.23 loses the expressions of an
        // `override` named in `@workgroup_size` ("Handle N of Expression is
        // either not present"), so such kernels work when they import nothing.
        if !source.lines().any(|l| l.trim_start().starts_with('#')) {
            let module = naga::front::wgsl::parse_str(source).map_err(|e| {
                GpuError::Shader(format!(
                    "WGSL error ({}):\n{}",
                    self.label,
                    e.emit_to_string_with_path(source, origin)
                ))
            })?;
            validate(name, &module)?;
            return Ok(module);
        }
        let mut composer = self.composer()?;
        let module = composer
            .make_naga_module(NagaModuleDescriptor {
                source,
                file_path: origin,
                shader_defs: shader_defs(name),
                ..Default::default()
            })
            .map_err(|e| GpuError::Shader(describe(&composer, &self.label, &e)))?;
        validate(name, &module)?;
        Ok(module)
    }

    /// Hash of the kernel file (with its shader defs, if any) and of the library modules it imports,
    /// directly or through other modules: any WGSL edit that can change this
    /// kernel's output changes it, and edits to unrelated modules do not
    /// (so they do not mark every golden's provenance stale).
    pub fn source_hash(&self, name: &str) -> Result<String, GpuError> {
        let (source, _) = self.kernel_source(name)?;
        let mut h = blake3::Hasher::new();
        h.update(name.as_bytes());
        h.update(source.as_bytes());
        for (path, source) in self.imported_lib(source) {
            h.update(path.as_bytes());
            h.update(source.as_bytes());
        }
        Ok(h.finalize().to_hex()[..16].to_string())
    }

    /// Each file of [`ShaderSet::import_closure`] with the hash of its text:
    /// recorded at bless time so that a check can name the files that changed.
    pub fn file_hashes(&self, name: &str) -> Result<std::collections::BTreeMap<String, String>, GpuError> {
        let (source, _) = self.kernel_source(name)?;
        let hash = |text: &str| blake3::hash(text.as_bytes()).to_hex()[..16].to_string();
        Ok(std::iter::once((name.to_string(), hash(source)))
            .chain(self.imported_lib(source).into_iter().map(|(path, text)| (path.clone(), hash(text))))
            .collect())
    }

    /// The kernel file and the lib modules it reaches through `#import`
    /// (paths relative to `shaders/`): every file whose edit can change it.
    pub fn import_closure(&self, name: &str) -> Result<Vec<String>, GpuError> {
        let (source, _) = self.kernel_source(name)?;
        Ok(std::iter::once(name.to_string())
            .chain(self.imported_lib(source).into_iter().map(|e| e.0.clone()))
            .collect())
    }

    /// Library files reachable from `source` through `#import`, in `lib` order.
    fn imported_lib(&self, source: &str) -> Vec<&(String, String)> {
        let path_of = |src: &str| import_path(src);
        let defined: Vec<String> = self.lib.iter().filter_map(|e| import_path(&e.1)).collect();
        let imports = |src: &str| imports(src, &defined);
        let mut wanted: Vec<String> = imports(source);
        let mut used = vec![false; self.lib.len()];
        while let Some(module) = wanted.pop() {
            for (k, entry) in self.lib.iter().enumerate() {
                if !used[k] && path_of(&entry.1).as_deref() == Some(module.as_str()) {
                    used[k] = true;
                    wanted.extend(imports(&entry.1));
                }
            }
        }
        self.lib.iter().zip(used).filter(|(_, u)| *u).map(|(e, _)| e).collect()
    }
}

/// `module` validated, with its `override` constants resolved to
/// `constants` for compute entry point `entry` (absent ones take their
/// defaults) when it has any: naga's pipeline-constant pass, which also
/// settles an overridden `@workgroup_size`.
pub fn resolve_overrides(
    name: &str,
    module: &naga::Module,
    entry: &str,
    constants: &[(String, f64)],
) -> Result<(naga::Module, naga::valid::ModuleInfo), GpuError> {
    let info = validate(name, module)?;
    if module.overrides.is_empty() {
        return Ok((module.clone(), info));
    }
    let map: naga::back::PipelineConstants = constants.iter().cloned().collect();
    let (resolved, resolved_info) = naga::back::pipeline_constants::process_overrides(
        module,
        &info,
        Some((naga::ShaderStage::Compute, entry)),
        &map,
    )
    .map_err(|e| GpuError::Shader(format!("{name}: override values do not resolve: {e}")))?;
    Ok((resolved.into_owned(), resolved_info.into_owned()))
}

/// The path a module declares with `#define_import_path`, if any.
fn import_path(source: &str) -> Option<String> {
    source.lines().find_map(|l| l.trim().strip_prefix("#define_import_path").map(|p| p.trim().to_string()))
}

/// Module paths named by `#import` lines: for each, the longest declared
/// module path it starts with (`#import vista::noise::{a, b}`,
/// `#import vista::noise`, `#import mylib::sky::types as t` and
/// `#import mylib::sky::types::scale` all name their module).
fn imports(source: &str, defined: &[String]) -> Vec<String> {
    source
        .lines()
        .filter_map(|l| l.trim().strip_prefix("#import"))
        .filter_map(|rest| {
            let text = rest.trim();
            let text = text.split(" as ").next().unwrap_or(text).trim();
            let text = text.split("::{").next().unwrap_or(text).trim();
            defined
                .iter()
                .filter(|p| text == p.as_str() || text.starts_with(&format!("{p}::")))
                .max_by_key(|p| p.len())
                .cloned()
        })
        .collect()
}

fn describe(composer: &Composer, label: &str, e: &ComposerError) -> String {
    format!("WGSL error ({label}):\n{}", e.emit_to_string(composer))
}

/// Validates a composed module with naga alone (no device needed).
pub fn validate(name: &str, module: &naga::Module) -> Result<naga::valid::ModuleInfo, GpuError> {
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(module)
        .map_err(|e| GpuError::Shader(format!("{name}: naga validation failed: {}", e.emit_to_string(""))))
}

/// The shader defs after `?` in a kernel name (`fbm.wgsl?A&B&N=10&F=false`):
/// a bare name is `true`, `NAME=value` a bool or an integer (i32, else u32).
fn shader_defs(name: &str) -> HashMap<String, naga_oil::compose::ShaderDefValue> {
    use naga_oil::compose::ShaderDefValue as V;
    let defs = name.split_once('?').map_or("", |(_, d)| d);
    defs.split('&')
        .filter(|d| !d.is_empty())
        .map(|d| match d.split_once('=') {
            None => (d.to_string(), V::Bool(true)),
            Some((k, v)) => {
                let value = match v {
                    "true" => V::Bool(true),
                    "false" => V::Bool(false),
                    _ => match v.parse::<i32>() {
                        Ok(i) => V::Int(i),
                        Err(_) => V::UInt(v.parse().unwrap_or_default()),
                    },
                };
                (k.to_string(), value)
            }
        })
        .collect()
}
