//! WGSL loading and composition.
//!
//! Kernel files in `shaders/` import shared pieces from `shaders/lib/` with
//! naga_oil's `#import` (each lib file declares `#define_import_path
//! vista::NAME`). Composition yields a validated `naga::Module`; errors carry
//! the file and line.

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

use naga_oil::compose::{ComposableModuleDescriptor, Composer, ComposerError, NagaModuleDescriptor, ShaderLanguage};

use crate::GpuError;

/// Where the WGSL lives: `$VISTA_SHADERS`, else the repository's `shaders/`.
pub fn default_shader_dir() -> PathBuf {
    match std::env::var_os("VISTA_SHADERS") {
        Some(dir) => PathBuf::from(dir),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).unwrap_or(Path::new(".")).join("shaders"),
    }
}

/// The set of WGSL sources: library modules plus kernel files.
#[derive(Debug, Clone)]
pub struct ShaderSet {
    dir: PathBuf,
    /// (path relative to `dir`, source) of every file under `lib/`, sorted.
    lib: Vec<(String, String)>,
}

fn read(path: &Path) -> Result<String, GpuError> {
    fs::read_to_string(path).map_err(|e| GpuError::Shader(format!("cannot read {}: {e}", path.display())))
}

fn wgsl_files(dir: &Path) -> Result<Vec<PathBuf>, GpuError> {
    let mut out = Vec::new();
    let entries =
        fs::read_dir(dir).map_err(|e| GpuError::Shader(format!("cannot list shader dir {}: {e}", dir.display())))?;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(wgsl_files(&path)?);
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

fn rel(dir: &Path, path: &Path) -> String {
    path.strip_prefix(dir).unwrap_or(path).to_string_lossy().replace('\\', "/")
}

impl ShaderSet {
    pub fn load(dir: &Path) -> Result<ShaderSet, GpuError> {
        let lib = wgsl_files(&dir.join("lib"))?
            .into_iter()
            .map(|p| Ok((rel(dir, &p), read(&p)?)))
            .collect::<Result<Vec<_>, GpuError>>()?;
        Ok(ShaderSet { dir: dir.to_path_buf(), lib })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Every kernel file (top-level `.wgsl`, not `lib/`), relative names.
    pub fn kernel_files(&self) -> Result<Vec<String>, GpuError> {
        Ok(wgsl_files(&self.dir)?
            .into_iter()
            .map(|p| rel(&self.dir, &p))
            .filter(|r| !r.starts_with("lib/"))
            .collect())
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
                    last_error = Some(describe(&composer, &self.dir, &e));
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

    /// Composes and validates the kernel file `name` (relative to the shader dir).
    pub fn compose(&self, name: &str) -> Result<naga::Module, GpuError> {
        let path = self.dir.join(name);
        let source = read(&path)?;
        let mut composer = self.composer()?;
        let module = composer
            .make_naga_module(NagaModuleDescriptor {
                source: &source,
                file_path: name,
                ..Default::default()
            })
            .map_err(|e| GpuError::Shader(describe(&composer, &self.dir, &e)))?;
        validate(name, &module)?;
        Ok(module)
    }

    /// Hash of the kernel file and of the library modules it imports,
    /// directly or through other modules: any WGSL edit that can change this
    /// kernel's output changes it, and edits to unrelated modules do not
    /// (so they do not mark every golden's provenance stale).
    pub fn source_hash(&self, name: &str) -> Result<String, GpuError> {
        let source = read(&self.dir.join(name))?;
        let mut h = blake3::Hasher::new();
        h.update(name.as_bytes());
        h.update(source.as_bytes());
        for (path, source) in self.imported_lib(&source) {
            h.update(path.as_bytes());
            h.update(source.as_bytes());
        }
        Ok(h.finalize().to_hex()[..16].to_string())
    }

    /// Library files reachable from `source` through `#import`, in `lib` order.
    fn imported_lib(&self, source: &str) -> Vec<&(String, String)> {
        let path_of = |src: &str| {
            src.lines().find_map(|l| l.trim().strip_prefix("#define_import_path").map(|p| p.trim().to_string()))
        };
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

/// Module paths named by `#import` lines (`#import vista::noise::{a, b}` and
/// `#import vista::noise` both name `vista::noise`; only `vista::X` paths are ours).
fn imports(source: &str) -> Vec<String> {
    source
        .lines()
        .filter_map(|l| l.trim().strip_prefix("#import"))
        .filter_map(|rest| {
            let path: Vec<&str> = rest.trim().split("::").take(2).collect();
            match path.as_slice() {
                ["vista", m] => {
                    let m: String = m.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                    Some(format!("vista::{m}"))
                }
                _ => None,
            }
        })
        .collect()
}

fn describe(composer: &Composer, dir: &Path, e: &ComposerError) -> String {
    format!("WGSL error (shader dir {}):\n{}", dir.display(), e.emit_to_string(composer))
}

/// Validates a composed module with naga alone (no device needed).
pub fn validate(name: &str, module: &naga::Module) -> Result<naga::valid::ModuleInfo, GpuError> {
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(module)
        .map_err(|e| GpuError::Shader(format!("{name}: naga validation failed: {}", e.emit_to_string(""))))
}

/// Byte size and `(name, offset)` members of the struct bound at
/// `@group(0) @binding(binding)`: lets tests check a kernel's uniform layout.
pub fn binding_struct_layout(module: &naga::Module, binding: u32) -> Option<(u32, Vec<(String, u32)>)> {
    let (_, var) = module
        .global_variables
        .iter()
        .find(|(_, v)| v.binding.as_ref().is_some_and(|b| b.group == 0 && b.binding == binding))?;
    let ty = &module.types[var.ty];
    match &ty.inner {
        naga::TypeInner::Struct { members, span } => Some((
            *span,
            members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect(),
        )),
        _ => None,
    }
}
