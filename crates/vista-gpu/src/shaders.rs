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
use crate::coverage::{Coverage, Origins};

/// The set of WGSL sources a project has: library modules (`lib/...`,
/// each declaring `#define_import_path vista::NAME`) and kernel files.
/// Built from text the caller read (the project layer over the built-ins),
/// so this crate reads no files.
#[derive(Debug, Clone)]
pub struct ShaderSet {
    /// Names the set in errors (a project root, or "built-in").
    label: String,
    /// Every import module (files under `lib/` and any with its own
    /// `#define_import_path`), sorted by relative path.
    lib: Vec<Source>,
    /// Kernel files (not under `lib/`) by relative path.
    kernels: BTreeMap<String, Source>,
    /// Composed modules by kernel file: the sources never change once the
    /// set is built, so each file is composed once per set.
    composed: Arc<Mutex<HashMap<String, Arc<naga::Module>>>>,
    /// naga_oil composers kept between compositions: building one compiles
    /// about 20 regexes, and the library modules it holds stay parsed, so
    /// kernels that share `lib/` modules parse them once per set. A pool,
    /// so that kernels still compose in parallel.
    composers: Arc<Mutex<Vec<Pooled>>>,
    /// The generated module `vista::enums` of each kernel file (from its
    /// manifest's enum params), or why there is none (two manifests that
    /// share the file declare different enums).
    enums: BTreeMap<String, Result<String, String>>,
    /// Nanoseconds spent composing and validating (naga_oil, naga), shared
    /// by clones of the set.
    compose_nanos: Arc<std::sync::atomic::AtomicU64>,
    /// The manifests' `[source]` assemblies by id (`file|id` names use them).
    sources: BTreeMap<String, vista_source::SourceSpec>,
    /// Reads a file an assembly reaches outside this set's own files.
    reader: Reader,
    /// Assembled kernel sources by name without defs, built once per set.
    units: Arc<Mutex<HashMap<String, Arc<Unit>>>>,
    /// Kernels compose instrumented for coverage ([`ShaderSet::covered`]).
    coverage: bool,
    /// Vertex code is counted too (the device lets the vertex stage write
    /// storage).
    vertex_counted: bool,
    /// Each instrumented kernel's counters, by name.
    covers: Arc<Mutex<HashMap<String, Arc<Coverage>>>>,
    /// This set's [`ShaderSet::covered`] twins (vertex code not counted,
    /// counted), each made once and shared by clones.
    twin: Arc<[std::sync::OnceLock<ShaderSet>; 2]>,
    /// Kernel files a `[source] command` generated: the inputs it read
    /// (root-relative path, hash), or why there is no text (the command
    /// failed), said when the file is composed.
    generated: BTreeMap<String, Result<Vec<(String, String)>, String>>,
}

/// What one module's assembly did with its `replace` keys
/// ([`ShaderSet::replace_keys`]).
#[derive(Debug, Clone, Default)]
pub struct ReplaceKeys {
    /// Keys found in no line of its files.
    pub missed: Vec<String>,
    /// Keys it replaced.
    pub applied: Vec<String>,
    /// Every file it reached (root-relative).
    pub files: Vec<String>,
}

/// The origin of a file a `[source] command` generated from `path`: what
/// errors name, and a mark that coverage does not measure it (its lines
/// are the command's output, not the user's file).
pub fn generated_origin(path: &str, command: &str) -> String {
    format!("{path} (as `{command}` generated it)")
}

/// A root-relative path's text and origin, for files an assembly reaches
/// outside `shaders/` (the project layer reads them; this crate reads none).
#[derive(Clone, Default)]
pub struct Reader(Option<Arc<ReadFn>>);

/// A root-relative path to its text and origin.
type ReadFn = dyn Fn(&str) -> Option<(String, String)> + Send + Sync;

impl Reader {
    /// A reader over `read`.
    pub fn new(read: impl Fn(&str) -> Option<(String, String)> + Send + Sync + 'static) -> Reader {
        Reader(Some(Arc::new(read)))
    }

    /// The text and origin of root-relative `path`, if the reader has it.
    pub fn read(&self, path: &str) -> Option<(String, String)> {
        self.0.as_ref().and_then(|r| r(path))
    }
}

impl std::fmt::Debug for Reader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() { "Reader(project)" } else { "Reader(none)" })
    }
}

/// What a name composes: a kernel file's text, or its assembly.
#[derive(Debug)]
struct Unit {
    source: Source,
    assembled: Option<vista_source::Assembled>,
}

/// One WGSL file of a [`ShaderSet`] and what naga_oil's preprocessor reads
/// from it once, when the set is built.
#[derive(Debug, Clone)]
struct Source {
    /// Path relative to `shaders/`.
    rel: String,
    text: String,
    /// A real path or `<built-in>/...`: what errors name.
    origin: String,
    /// The path it declares with `#define_import_path`, if any.
    module: Option<String>,
    /// The modules it imports, by naga_oil's own parser.
    imports: Vec<Import>,
}

/// A module a file imports, and the line (1-based) of the `#import`
/// statement that names it.
#[derive(Debug, Clone)]
struct Import {
    module: String,
    line: Option<usize>,
}

impl Source {
    fn new(rel: String, text: String, origin: String) -> Source {
        let (module, imports) = preprocess(&text);
        Source { rel, text, origin, module, imports }
    }

    fn imports(&self, module: &str) -> bool {
        self.imports.iter().any(|i| i.module == module)
    }
}

/// A composer of [`ShaderSet`]'s pool and the generated `vista::enums`
/// text it holds, if any.
#[derive(Debug)]
struct Pooled {
    composer: Composer,
    enums: Option<String>,
}

impl Default for Pooled {
    /// A composer that validates with the [`OPTIONAL_CAPABILITIES`] allowed
    /// (naga_oil's default refuses `@blend_src`, f16, ...): whether the
    /// device has them is [`ShaderSet::declared_features`]' and
    /// [`features_used`]' question, asked per backend.
    fn default() -> Pooled {
        Pooled { composer: Composer::default().with_capabilities(all_capabilities()), enums: None }
    }
}

/// The import path of the module generated from a kernel's manifest.
pub const ENUMS_MODULE: &str = "vista::enums";

/// Whether `rel` (under `shaders/`) is a WGSL unit test file,
/// `*.test.wgsl` or `*.test.wesl`: composed as a kernel file, never listed
/// as one.
pub fn is_unit_test_file(rel: &str) -> bool {
    rel.ends_with(".test.wgsl") || rel.ends_with(".test.wesl")
}

impl ShaderSet {
    /// A set from `(relative path, text, origin)` triples; files under
    /// `lib/` are import modules (but `*.test.wgsl` files), the rest kernel
    /// files. `origin` (a real
    /// path or `<built-in>/...`) is what errors name.
    pub fn from_files(label: &str, files: impl IntoIterator<Item = (String, String, String)>) -> ShaderSet {
        let mut lib = Vec::new();
        let mut kernels = BTreeMap::new();
        for (rel, text, origin) in files {
            let source = Source::new(rel, text, origin);
            // An import module is a file under lib/ or any file with its own
            // `#define_import_path` (a project's foreign module layout); a
            // WGSL unit test file (`*.test.wgsl`, `*.test.wesl`) beside the modules it
            // tests is composed as a kernel file is.
            let test = is_unit_test_file(&source.rel) && source.module.is_none();
            if (source.rel.starts_with("lib/") && !test) || source.module.is_some() {
                lib.push(source);
            } else {
                kernels.insert(source.rel.clone(), source);
            }
        }
        lib.sort_by(|a, b| a.rel.cmp(&b.rel));
        ShaderSet {
            label: label.to_string(),
            lib,
            kernels,
            composed: Default::default(),
            composers: Default::default(),
            enums: BTreeMap::new(),
            compose_nanos: Default::default(),
            sources: BTreeMap::new(),
            reader: Reader::default(),
            units: Default::default(),
            coverage: false,
            vertex_counted: false,
            covers: Default::default(),
            twin: Default::default(),
            generated: BTreeMap::new(),
        }
    }

    /// This set with the files `[source] command`s generated (already
    /// among its files, their origins from [`generated_origin`]): each with
    /// the inputs the command read, which join its file hashes, or the
    /// command's failure, which composing the file reports.
    pub fn with_generated(
        mut self,
        files: impl IntoIterator<Item = (String, Result<Vec<(String, String)>, String>)>,
    ) -> ShaderSet {
        self.generated.extend(files);
        self.units = Default::default();
        self.composed = Default::default();
        self.twin = Default::default();
        self
    }

    /// This set composing every kernel with coverage counters (SPEC 20):
    /// for a coverage run only, never a judged one. Its source hashes
    /// differ from this set's, so no cache mistakes one module for the other.
    /// `vertex`: whether the device lets the vertex stage write storage,
    /// so that vertex entries and what they call are counted too.
    pub fn covered(&self, vertex: bool) -> ShaderSet {
        if self.coverage && self.vertex_counted == vertex {
            return self.clone();
        }
        let make = || ShaderSet {
            coverage: true,
            vertex_counted: vertex,
            composed: Default::default(),
            covers: Default::default(),
            twin: Default::default(),
            ..self.clone()
        };
        self.twin[usize::from(vertex)].get_or_init(make).clone()
    }

    /// Whether this set composes kernels for coverage.
    pub fn is_covered(&self) -> bool {
        self.coverage
    }

    /// Whether this covered set counts vertex code too.
    pub fn counts_vertex(&self) -> bool {
        self.vertex_counted
    }

    /// The counters of kernel `name` as this [`ShaderSet::covered`] set
    /// composes it (composed now if not yet).
    pub fn coverage(&self, name: &str) -> Result<Arc<Coverage>, GpuError> {
        if !self.coverage {
            return Err(GpuError::Request(format!("{name}: this shader set does not compose for coverage")));
        }
        self.compose(name)?;
        let covers = self.covers.lock().expect("coverage cache");
        covers.get(name).cloned().ok_or_else(|| GpuError::Shader(format!("{name}: no coverage counters")))
    }

    /// This set with the manifests' `[source]` assemblies (`(id, spec)`,
    /// [`vista_source::SourceSpec::id`]) and a reader for the files they
    /// reach outside `shaders/`. A name `file|id?...` composes `file` as
    /// assembled by spec `id`.
    pub fn with_sources(
        mut self,
        specs: impl IntoIterator<Item = (String, vista_source::SourceSpec)>,
        reader: Reader,
    ) -> ShaderSet {
        self.sources.extend(specs);
        self.reader = reader;
        self.composed = Default::default();
        self.twin = Default::default();
        self.units = Default::default();
        self
    }

    /// This set with a generated `vista::enums` module per kernel file:
    /// `(file, kernel, module text)` for every file each kernel's passes use.
    /// Two kernels that give one file different modules make composing it
    /// fail, naming both, when it imports `vista::enums`.
    pub fn with_enums(mut self, modules: impl IntoIterator<Item = (String, String, String)>) -> ShaderSet {
        let mut owner: BTreeMap<String, String> = BTreeMap::new();
        for (file, kernel, text) in modules {
            match self.enums.get(&file) {
                Some(Ok(t)) if *t != text => {
                    let first = owner.get(&file).cloned().unwrap_or_default();
                    let why = format!(
                        "kernels {first} and {kernel} share {file}, which imports {ENUMS_MODULE}, but declare \
                         different enum params; give each kernel its own shader file"
                    );
                    self.enums.insert(file, Err(why));
                }
                Some(_) => {}
                None => {
                    owner.insert(file.clone(), kernel);
                    self.enums.insert(file, Ok(text));
                }
            }
        }
        self.composed = Default::default();
        self.twin = Default::default();
        self.composers = Default::default();
        self
    }

    /// Time spent so far composing and validating this set's kernels.
    pub fn compose_time(&self) -> std::time::Duration {
        std::time::Duration::from_nanos(self.compose_nanos.load(std::sync::atomic::Ordering::Relaxed))
    }

    /// What this set is (a project root, or "built-in").
    pub fn label(&self) -> &str {
        &self.label
    }

    /// Every kernel file (not `lib/`, not a WGSL unit test's
    /// `*.test.wgsl` or `.wesl`), relative names, sorted.
    pub fn kernel_files(&self) -> Vec<String> {
        self.kernels.keys().filter(|k| !is_unit_test_file(k)).cloned().collect()
    }

    /// `name` is a kernel file, optionally followed by `?DEF&DEF...`: naga_oil
    /// shader defs (boolean) to compose it with, e.g. `fbm.wgsl?VISTA_HASH_PLANE`.
    fn kernel_source(&self, name: &str) -> Result<&Source, GpuError> {
        let name = file_of(name);
        if let Some(Err(why)) = self.generated.get(name) {
            return Err(GpuError::Shader(why.clone()));
        }
        // An import module may be composed as a pass's file too (bevy's
        // full-screen vertex shader is a module with its own import path).
        let module = || self.lib.iter().find(|s| s.rel == name && !s.origin.starts_with("<built-in>"));
        self.kernels.get(name).or_else(module).ok_or_else(|| {
            // The project's own files: the built-ins' are not what a
            // project's manifest means to name.
            let own: Vec<&str> = self
                .kernels
                .values()
                .filter(|s| !s.origin.starts_with("<built-in>") && !is_unit_test_file(&s.rel))
                .map(|s| s.rel.as_str())
                .collect();
            let listed = match own.is_empty() {
                true => self.kernel_files().join(", "),
                false => own.join(", "),
            };
            GpuError::Shader(format!(
                "shader {name} not found in {} (its kernel files: {listed}; a file of another extension than \
                 .wgsl or .wesl needs language = \"wgsl\" in the manifest)",
                self.label,
            ))
        })
    }

    /// What `name` composes: its kernel file, or (`file|id`) that file as
    /// the `[source]` spec `id` assembles it with the replacement texts the
    /// name carries (`%i=text`). Built once per set.
    fn unit(&self, name: &str) -> Result<Arc<Unit>, GpuError> {
        let key = unit_key(name);
        if let Some(u) = self.units.lock().expect("unit cache").get(&key) {
            return Ok(u.clone());
        }
        let kernel = self.kernel_source(name)?;
        let default = vista_source::SourceSpec::default();
        let spec = match spec_id(name) {
            None => None,
            Some(id) => Some(self.sources.get(id).ok_or_else(|| {
                GpuError::Shader(format!("{}: no [source] assembly {id} in {}", file_of(name), self.label))
            })?),
        };
        let read = |path: &str| self.read(path);
        let main = format!("shaders/{}", file_of(name));
        let assembled = if main.ends_with(".wesl") {
            // WESL: the wesl crate resolves its imports; bool defs are its features.
            let spec = spec.unwrap_or(&default);
            if spec.include.is_some() || spec.prepend.is_some() || spec.append.is_some() || !spec.replace.is_empty() {
                return Err(GpuError::Shader(format!(
                    "{}: [source] include, prepend, append and replace apply to WGSL text, not to a .wesl shader",
                    kernel.origin
                )));
            }
            let features: Vec<(String, bool)> = shader_defs(name)
                .into_iter()
                .filter_map(|(k, v)| match v {
                    naga_oil::compose::ShaderDefValue::Bool(b) => Some((k, b)),
                    _ => None,
                })
                .collect();
            Some(vista_source::compile_wesl(&main, spec, &features, &read).map_err(GpuError::Shader)?)
        } else if let Some(spec) = spec {
            let values = replacement_values(name, spec);
            Some(
                vista_source::assemble(&main, spec, &values, &read)
                    .map_err(|e| GpuError::Shader(format!("{}: {e}", kernel.origin)))?,
            )
        } else {
            None
        };
        let unit = match assembled {
            None => Unit { source: kernel.clone(), assembled: None },
            Some(a) => {
                // A compiler's output names its root file as compiled.
                let origin = match a.is_compiled() {
                    false => kernel.origin.clone(),
                    true => format!("{}{}", kernel.origin, crate::coverage::COMPILED_BY_WESL),
                };
                Unit { source: Source::new(kernel.rel.clone(), a.text.clone(), origin), assembled: Some(a) }
            }
        };
        let unit = Arc::new(unit);
        self.units.lock().expect("unit cache").insert(key, unit.clone());
        Ok(unit)
    }

    /// `name`'s assembly's `replace` keys: those it found in no line, those
    /// it applied, and every file it reached (`None`: no assembly, no
    /// keys). A pass refuses a key none of its modules applied.
    pub fn replace_keys(&self, name: &str) -> Result<Option<ReplaceKeys>, GpuError> {
        let unit = self.unit(name)?;
        Ok(unit.assembled.as_ref().filter(|a| !a.is_compiled()).map(|a| ReplaceKeys {
            missed: a.unmatched.clone(),
            applied: a.replaced.iter().map(|(k, _)| k.clone()).collect(),
            files: a.parts.iter().map(|p| p.path.clone()).collect(),
        }))
    }

    /// A reader of the files this set reads (`shaders/...` its own, others
    /// through its reader): what a coverage page shows of a file.
    pub fn text_reader(&self) -> Reader {
        let set = self.clone();
        Reader::new(move |path| set.read(path))
    }

    /// A root-relative path's text and origin: this set's own file (an
    /// edited one, under mutation) for `shaders/...`, else the reader's.
    fn read(&self, path: &str) -> Option<(String, String)> {
        if let Some(rel) = path.strip_prefix("shaders/") {
            let own = self.kernels.get(rel).or_else(|| self.lib.iter().find(|e| e.rel == rel));
            if let Some(s) = own {
                return Some((s.text.clone(), s.origin.clone()));
            }
        }
        self.reader.read(path)
    }

    /// The generated `vista::enums` text for kernel file `name` (its
    /// `source`, and `lib`, the library modules it reaches) when it or one
    /// of those modules imports it.
    fn enums_for(&self, name: &str, source: &Source, lib: &[&Source]) -> Result<Option<&str>, GpuError> {
        let file = file_of(name);
        if !source.imports(ENUMS_MODULE) && !lib.iter().any(|e| e.imports(ENUMS_MODULE)) {
            return Ok(None);
        }
        match self.enums.get(file) {
            Some(Ok(text)) => Ok(Some(text)),
            Some(Err(why)) => Err(GpuError::Shader(format!("{file}: {why}"))),
            None => Err(GpuError::Shader(format!(
                "{file} imports {ENUMS_MODULE}, which is generated from the enum params of the kernel manifest \
                 that names the file; no manifest in {} names {file}",
                self.label
            ))),
        }
    }

    /// Refuses a generated constant that a library module the kernel
    /// imports also defines with another value: the library's meaning of
    /// the index (`vista::noise`'s `BASIS_VALUE`) and the manifest's order
    /// must agree.
    fn check_enums(&self, name: &str, enums: &str, lib: &[&Source]) -> Result<(), GpuError> {
        let consts = |text: &str| -> Vec<(String, String)> {
            text.lines()
                .filter_map(|l| l.trim().strip_prefix("const "))
                .filter_map(|rest| {
                    let (name, rest) = rest.split_once(':')?;
                    let value = rest.split_once('=')?.1.trim().trim_end_matches(';').trim();
                    Some((name.trim().to_string(), value.to_string()))
                })
                .collect()
        };
        let generated = consts(enums);
        for (path, text) in lib.iter().map(|e| (&e.rel, &e.text)) {
            for (c, lib_value) in consts(text) {
                if let Some((_, value)) = generated.iter().find(|(g, _)| *g == c)
                    && *value != lib_value
                {
                    return Err(GpuError::Shader(format!(
                        "{}: enum constant {c} is {value} by the kernel's manifest but {lib_value} in {path}; list the \
                         enum's values in the order {path} gives them",
                        file_of(name)
                    )));
                }
            }
        }
        Ok(())
    }

    /// Makes `pooled` hold the generated `vista::enums` module `enums` (if
    /// the kernel needs one; replacing another drops the modules built on
    /// it) and every library module in `lib`, the modules the kernel source
    /// reaches; modules it already holds stay. naga_oil wants a module's
    /// imports added before it, so modules are added in rounds until all fit.
    fn prepare(&self, pooled: &mut Pooled, lib: &[&Source], enums: Option<&str>) -> Result<(), GpuError> {
        let composer = &mut pooled.composer;
        if let Some(text) = enums
            && pooled.enums.as_deref() != Some(text)
        {
            pooled.enums = None;
            let desc = ComposableModuleDescriptor {
                source: text,
                file_path: "<generated>/vista/enums.wgsl",
                language: ShaderLanguage::Wgsl,
                as_name: None,
                additional_imports: &[],
                shader_defs: HashMap::new(),
            };
            if let Err(e) = composer.add_composable_module(desc) {
                return Err(GpuError::Shader(describe(composer, &self.label, &e)));
            }
            pooled.enums = Some(text.to_string());
        }
        let mut pending: Vec<&Source> =
            lib.iter().filter(|e| !e.module.as_ref().is_some_and(|p| composer.contains_module(p))).copied().collect();
        while !pending.is_empty() {
            let mut failed = Vec::new();
            let mut last_error = None;
            for entry in &pending {
                let desc = ComposableModuleDescriptor {
                    source: &entry.text,
                    file_path: &entry.origin,
                    language: ShaderLanguage::Wgsl,
                    as_name: None,
                    additional_imports: &[],
                    shader_defs: HashMap::new(),
                };
                if let Err(e) = composer.add_composable_module(desc) {
                    last_error = Some(describe(composer, &self.label, &e));
                    failed.push(*entry);
                }
            }
            if failed.len() == pending.len() {
                return Err(GpuError::Shader(last_error.unwrap_or_default()));
            }
            pending = failed;
        }
        Ok(())
    }

    /// The optional features kernel `name` declares with `enable`
    /// directives (as WebGPU feature, `enable` name), whether or not the
    /// module uses them: WGSL requires the feature of every `enable`, and
    /// naga_oil drops the directive from the module. A directive inside
    /// `#ifdef X` / `#ifndef X` counts as the name's defs select it; one
    /// under another kind of `#if` does not count.
    pub fn declared_features(&self, name: &str) -> Result<Vec<(&'static str, &'static str)>, GpuError> {
        let unit = self.unit(name)?;
        let defs = shader_defs(name);
        let on = |d: &str| defs.get(d).is_some_and(|v| !matches!(v, naga_oil::compose::ShaderDefValue::Bool(false)));
        // One entry per open #if: whether its branch is taken (None: unknown).
        let mut stack: Vec<Option<bool>> = Vec::new();
        let mut out = Vec::new();
        for line in unit.source.text.lines() {
            let t = line.split("//").next().unwrap_or("").trim();
            let word = |p: &str| t.strip_prefix(p).map(|r| r.trim().to_string());
            if let Some(d) = word("#ifdef") {
                stack.push(Some(on(&d)));
            } else if let Some(d) = word("#ifndef") {
                stack.push(Some(!on(&d)));
            } else if t.starts_with("#if") {
                stack.push(None);
            } else if t.starts_with("#else") {
                if let Some(top) = stack.last_mut() {
                    *top = match (t == "#else", *top) {
                        (true, Some(b)) => Some(!b),
                        _ => None,
                    };
                }
            } else if t.starts_with("#endif") {
                stack.pop();
            } else if let Some(list) = t.strip_prefix("enable ").and_then(|r| r.strip_suffix(';'))
                && stack.iter().all(|b| *b == Some(true))
            {
                for e in list.split(',').map(str::trim) {
                    if let Some((_, f, en)) = OPTIONAL_CAPABILITIES.iter().find(|(_, _, en)| *en == e) {
                        out.push((*f, *en));
                    }
                }
            }
        }
        Ok(out)
    }

    /// Composes and validates the kernel file `name` (relative to
    /// `shaders/`), once per set.
    pub fn compose(&self, name: &str) -> Result<Arc<naga::Module>, GpuError> {
        if let Some(m) = self.composed.lock().expect("compose cache").get(name) {
            return Ok(m.clone());
        }
        let started = std::time::Instant::now();
        let module = self.compose_within_limit(name);
        self.compose_nanos.fetch_add(started.elapsed().as_nanos() as u64, std::sync::atomic::Ordering::Relaxed);
        let module = Arc::new(module?);
        self.composed.lock().expect("compose cache").insert(name.to_string(), module.clone());
        Ok(module)
    }

    /// `name` composed and written back as WGSL by naga: the program alone,
    /// without comments, spans or layout. Two sets that give one program
    /// compile `name` alike (a mutant in code `name`'s defs leave out
    /// changes nothing).
    pub fn program(&self, name: &str) -> Result<String, GpuError> {
        let module = self.compose(name)?;
        let info = validate(name, &module)?;
        naga::back::wgsl::write_string(&module, &info, naga::back::wgsl::WriterFlags::empty())
            .map_err(|e| GpuError::Shader(format!("{name}: naga's WGSL writer failed: {e}")))
    }

    /// [`ShaderSet::compose_uncached`] on a thread of its own, given at most
    /// [`compose_limit`]: naga's WGSL front end slows quadratically with a
    /// module's constants (10,000 `const` lines take seconds, 400,000 hours),
    /// and a parse cannot be stopped, so past the limit the thread is left
    /// to finish in the background ([`runaway_compositions`] counts them; a
    /// worker process then exits) and the case fails naming the setting.
    /// A panic in naga or naga_oil becomes this file's error too.
    fn compose_within_limit(&self, name: &str) -> Result<naga::Module, GpuError> {
        let limit = compose_limit();
        let (tx, rx) = std::sync::mpsc::channel();
        let (set, owned) = (self.clone(), name.to_string());
        std::thread::Builder::new()
            .name("vista-compose".into())
            .spawn(move || {
                let _ = tx.send(set.compose_uncached(&owned));
            })
            .map_err(|e| GpuError::Shader(format!("{}: no thread to compose it on: {e}", file_of(name))))?;
        match rx.recv_timeout(limit) {
            Ok(result) => result,
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                RUNAWAY.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                Err(GpuError::Shader(format!(
                    "{}: composing and validating it took longer than {} s, the limit \
                     (VISTA_COMPILE_TIMEOUT_S); naga's WGSL front end slows quadratically with module-scope \
                     constants ({} lines here): split the module or raise the limit",
                    file_of(name),
                    limit.as_secs_f64(),
                    self.unit(name).map_or(0, |u| u.source.text.lines().count())
                )))
            }
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                Err(GpuError::Shader(format!("{}: composing it panicked in naga or naga_oil", file_of(name))))
            }
        }
    }

    fn compose_uncached(&self, name: &str) -> Result<naga::Module, GpuError> {
        let unit = self.unit(name)?;
        // An assembled source's errors name the file and line each came from.
        let located = |e: GpuError| match (e, &unit.assembled) {
            (GpuError::Shader(m), Some(a)) => GpuError::Shader(locate(&m, &unit.source.origin, a)),
            (e, _) => e,
        };
        let (module, origins) = self.compose_unit(name, &unit.source).map_err(located)?;
        let Some(origins) = origins else { return Ok(module) };
        let origins = match (origins, &unit.assembled) {
            (Origins::Direct { text, file, .. }, Some(a)) if a.traced() => {
                Origins::Direct { text, file, assembled: Some(a.clone()) }
            }
            (o, _) => o,
        };
        let (module, coverage) = crate::coverage::instrument(&module, &origins, self.vertex_counted);
        validate(name, &module)?;
        self.covers.lock().expect("coverage cache").insert(name.to_string(), Arc::new(coverage));
        Ok(module)
    }

    /// The file a coverage report names for a source: its path under the
    /// project (`shaders/...`) where its lines are [`measured`].
    fn report_path(source: &Source) -> Option<String> {
        crate::coverage::measured(&source.origin).then(|| format!("shaders/{}", source.rel))
    }

    /// The module of `name`, and where its spans point when this set
    /// composes for coverage.
    fn compose_unit(&self, name: &str, kernel: &Source) -> Result<(naga::Module, Option<Origins>), GpuError> {
        let (source, origin) = (&kernel.text, &kernel.origin);
        // Expressions deeper or longer than the parsers' stacks take are
        // refused before any parser sees them.
        vista_source::check_depth(source, origin).map_err(GpuError::Shader)?;
        // A file without preprocessor directives needs no composition; naga
        // parses it directly. naga_oil 0.23 loses the expressions of an
        // `override` named in `@workgroup_size` ("Handle N of Expression is
        // either not present"), so such kernels work when they import nothing.
        if !has_directives(source) {
            let module = naga::front::wgsl::parse_str(source).map_err(|e| {
                GpuError::Shader(format!(
                    "WGSL error ({}):\n{}",
                    self.label,
                    e.emit_to_string_with_path(source, origin)
                ))
            })?;
            validate(name, &module)?;
            // An assembly's (a compiler's) lines are placed through it, below.
            let origins = self.coverage.then(|| Origins::Direct {
                text: source.clone(),
                file: ShaderSet::report_path(kernel),
                assembled: None,
            });
            return Ok((module, origins));
        }
        // The manifest's constants must agree with the library's even where
        // the kernel passes the index through without naming it.
        let lib = self.imported_lib(kernel)?;
        for module in &lib {
            vista_source::check_depth(&module.text, &module.origin).map_err(GpuError::Shader)?;
        }
        if let Some(Ok(text)) = self.enums.get(file_of(name)) {
            self.check_enums(name, text, &lib)?;
        }
        let enums = self.enums_for(name, kernel, &lib)?;
        let mut pooled = self.composers.lock().expect("composer pool").pop().unwrap_or_default();
        self.prepare(&mut pooled, &lib, enums)?;
        let module = pooled
            .composer
            .make_naga_module(NagaModuleDescriptor {
                source,
                file_path: origin,
                shader_defs: shader_defs(name),
                ..Default::default()
            })
            .map_err(|e| GpuError::Shader(describe(&pooled.composer, &self.label, &e)))?;
        // Span module indices are this composer's own: read them now.
        let origins = self.coverage.then(|| self.composed_origins(&pooled.composer, name, kernel, &lib));
        // Back to the pool only after a clean composition: a failed one
        // drops its composer rather than leave a half-built state behind.
        self.composers.lock().expect("composer pool").push(pooled);
        validate(name, &module)?;
        Ok((module, origins))
    }

    /// Each module index of `composer` with its file and preprocessed
    /// source as naga_oil parsed it (index 0: the kernel `name` itself).
    fn composed_origins(&self, composer: &Composer, name: &str, kernel: &Source, lib: &[&Source]) -> Origins {
        let defs = shader_defs(name);
        let preprocessed = |text: &str| {
            naga_oil::compose::preprocess::Preprocessor::default()
                .preprocess(text, &defs)
                .map(|o| o.preprocessed_source)
                .unwrap_or_default()
        };
        let mut modules = HashMap::new();
        modules.insert(0, (ShaderSet::report_path(kernel), preprocessed(&kernel.text)));
        for (index, module) in &composer.module_index {
            let Some(set) = composer.module_sets.get(module) else { continue };
            let file = lib.iter().find(|s| s.module.as_deref() == Some(module)).and_then(|s| ShaderSet::report_path(s));
            modules.insert(*index, (file, preprocessed(&set.sanitized_source)));
        }
        Origins::Composed { modules }
    }

    /// The text naga parses for `name` when it parses it directly (a file
    /// with no preprocessor directive, an `#include`/prepend/append/replace
    /// assembly, the wesl crate's output): what the browser hands Tint, so
    /// that Tint reads what the project wrote. `None` for a file naga_oil
    /// composes (`#import`, `#ifdef`, ...): naga's IR is all there is.
    pub fn source_text(&self, name: &str) -> Result<Option<SourceText>, GpuError> {
        let unit = self.unit(name)?;
        // A coverage run's module has counters the text lacks.
        if has_directives(&unit.source.text) || self.coverage {
            return Ok(None);
        }
        Ok(Some(SourceText {
            text: unit.source.text.clone(),
            origin: unit.source.origin.clone(),
            assembled: unit.assembled.clone(),
        }))
    }

    /// Hash of the kernel file (with its shader defs, if any) and of the library modules it imports,
    /// directly or through other modules: any WGSL edit that can change this
    /// kernel's output changes it, and edits to unrelated modules do not
    /// (so they do not mark every golden's provenance stale).
    pub fn source_hash(&self, name: &str) -> Result<String, GpuError> {
        let unit = self.unit(name)?;
        let kernel = &unit.source;
        let mut h = blake3::Hasher::new();
        h.update(name.as_bytes());
        if self.coverage {
            h.update(b"instrumented for coverage");
        }
        if self.vertex_counted {
            h.update(b"vertex code counted");
        }
        match unit.assembled.as_ref().filter(|a| a.is_compiled()) {
            // A compiler's output (WESL): the files it read, by path, not
            // its text, whose order of declarations is the compiler's own
            // and need not repeat from one process to the next.
            Some(a) => {
                let mut parts: Vec<&vista_source::Part> = a.parts.iter().collect();
                parts.sort_by(|x, y| x.path.cmp(&y.path));
                for p in parts {
                    h.update(p.path.as_bytes());
                    h.update(p.text.as_bytes());
                }
            }
            None => {
                h.update(kernel.text.as_bytes());
                // Every file an assembly read, as written.
                for p in unit.assembled.iter().flat_map(|a| &a.parts) {
                    h.update(p.path.as_bytes());
                    h.update(p.text.as_bytes());
                }
            }
        }
        let lib = self.imported_lib(kernel)?;
        for e in &lib {
            h.update(e.rel.as_bytes());
            h.update(e.text.as_bytes());
        }
        if let Some(text) = self.enums_for(name, kernel, &lib)? {
            h.update(ENUMS_MODULE.as_bytes());
            h.update(text.as_bytes());
        }
        Ok(h.finalize().to_hex()[..16].to_string())
    }

    /// The names the preprocessor lines and WESL `@if`s of the files `name`
    /// reaches test (`#ifdef X`, `#if X == 1`, `@if(X && !Y)`): the defs it
    /// reads, so that a def a case sets and nothing reads is refused.
    pub fn defs_read(&self, name: &str) -> Result<std::collections::BTreeSet<String>, GpuError> {
        const NOT_DEFS: [&str; 9] = ["if", "ifdef", "ifndef", "else", "elif", "endif", "defined", "true", "false"];
        let unit = self.unit(name)?;
        let lib = self.imported_lib(&unit.source)?;
        let mut out = std::collections::BTreeSet::new();
        for text in std::iter::once(&unit.source.text).chain(lib.iter().map(|s| &s.text)) {
            for line in text.lines().map(str::trim_start) {
                let tests = ["#if", "#else", "#elif"].iter().any(|d| line.starts_with(d))
                    || line.contains("@if(")
                    || line.contains("@elif(");
                if !tests {
                    continue;
                }
                let words = line.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'));
                out.extend(
                    words
                        .filter(|w| {
                            w.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') && !NOT_DEFS.contains(w)
                        })
                        .map(str::to_string),
                );
            }
        }
        Ok(out)
    }

    /// Each file of [`ShaderSet::import_closure`] with the hash of its text:
    /// recorded at bless time so that a check can name the files that changed.
    pub fn file_hashes(&self, name: &str) -> Result<std::collections::BTreeMap<String, String>, GpuError> {
        let unit = self.unit(name)?;
        let kernel = &unit.source;
        let hash = |text: &str| blake3::hash(text.as_bytes()).to_hex()[..16].to_string();
        let lib = self.imported_lib(kernel)?;
        let enums =
            self.enums_for(name, kernel, &lib)?.map(|text| (format!("{ENUMS_MODULE} (from the manifest)"), hash(text)));
        // An assembly: every file it reached by its own path (under
        // shaders/ relative to it, like the rest), and the replacements.
        let parts: Vec<(String, String)> = match &unit.assembled {
            Some(a) => {
                let mut v: Vec<(String, String)> =
                    a.parts.iter().map(|p| (shader_rel(&p.path), hash(&p.text))).collect();
                if let Some(spec) = spec_id(name).and_then(|id| self.sources.get(id))
                    && !spec.replace.is_empty()
                {
                    v.push(("[source] replace (from the manifest)".into(), hash(&format!("{:?}", spec.replace))));
                }
                v
            }
            None => vec![(name.to_string(), hash(&kernel.text))],
        };
        // What a command read besides the file, by its root-relative path.
        let inputs = match self.generated.get(&kernel.rel) {
            Some(Ok(inputs)) => inputs.iter().map(|(path, h)| (shader_rel(path), h.clone())).collect(),
            _ => Vec::new(),
        };
        Ok(parts
            .into_iter()
            .chain(lib.iter().map(|e| (e.rel.clone(), hash(&e.text))))
            .chain(enums)
            .chain(inputs)
            .collect())
    }

    /// The kernel file and the lib modules it reaches through `#import`
    /// (paths relative to `shaders/`), and the files its assembly reaches
    /// outside `shaders/` (relative to the root): every file whose edit can
    /// change it.
    pub fn import_closure(&self, name: &str) -> Result<Vec<String>, GpuError> {
        let unit = self.unit(name)?;
        // An assembly's parts: files of this set by their path under
        // shaders/, the others (an include folder elsewhere) by their path
        // under the root.
        let parts: Vec<String> = match &unit.assembled {
            None => vec![name.to_string()],
            Some(a) => a
                .parts
                .iter()
                .filter_map(|p| match p.path.strip_prefix("shaders/") {
                    Some(rel) => (self.kernels.contains_key(rel) || self.lib.iter().any(|e| e.rel == rel))
                        .then(|| rel.to_string()),
                    None => Some(p.path.clone()),
                })
                .collect(),
        };
        Ok(parts.into_iter().chain(self.imported_lib(&unit.source)?.into_iter().map(|e| e.rel.clone())).collect())
    }

    /// Library files reachable from `kernel` through `#import`, in `lib`
    /// order. A module that no file declares is refused, naming the file
    /// and line that import it (the generated `vista::enums` aside).
    fn imported_lib(&self, kernel: &Source) -> Result<Vec<&Source>, GpuError> {
        let mut wanted: Vec<(&Source, &Import)> = kernel.imports.iter().map(|i| (kernel, i)).collect();
        let mut used = vec![false; self.lib.len()];
        while let Some((importer, import)) = wanted.pop() {
            if import.module == ENUMS_MODULE {
                continue;
            }
            let Some(k) = self.lib.iter().position(|e| e.module.as_deref() == Some(import.module.as_str())) else {
                let at = import.line.map_or(String::new(), |l| format!(":{l}"));
                let mut known: Vec<&str> = self.lib.iter().filter_map(|e| e.module.as_deref()).collect();
                known.sort();
                return Err(GpuError::Shader(format!(
                    "{}{at}: imports module {}, which no file in {} declares with #define_import_path (modules: {})",
                    importer.origin,
                    import.module,
                    self.label,
                    known.join(", ")
                )));
            };
            if !used[k] {
                used[k] = true;
                wanted.extend(self.lib[k].imports.iter().map(|i| (&self.lib[k], i)));
            }
        }
        // naga_oil reports a cycle as "required import ... not found".
        if let Some(cycle) = self.import_cycle(&used) {
            let steps: Vec<String> = cycle
                .iter()
                .map(|(k, i)| {
                    let at = i.line.map_or(String::new(), |l| format!(":{l}"));
                    format!("{}{at} imports {}", self.lib[*k].origin, i.module)
                })
                .collect();
            return Err(GpuError::Shader(format!(
                "{}: its imports form a cycle, which naga_oil cannot compose: {}; move what both need into a third \
                 module",
                kernel.origin,
                steps.join(", which ")
            )));
        }
        Ok(self.lib.iter().zip(used).filter(|(_, u)| *u).map(|(e, _)| e).collect())
    }

    /// A cycle among the `used` library modules, as (module index, the
    /// import that leads to the next) from the first module of the cycle
    /// back to it; `None` when their imports form no cycle.
    fn import_cycle(&self, used: &[bool]) -> Option<Vec<(usize, &Import)>> {
        let index = |m: &str| self.lib.iter().position(|e| e.module.as_deref() == Some(m));
        // 0: unvisited, 1: on the path, 2: done.
        let mut state = vec![0u8; self.lib.len()];
        for start in (0..self.lib.len()).filter(|&k| used[k]) {
            if state[start] != 0 {
                continue;
            }
            // Depth-first with an explicit stack: (module, next import to try).
            let mut path: Vec<(usize, usize)> = vec![(start, 0)];
            state[start] = 1;
            while let Some(&mut (k, ref mut next)) = path.last_mut() {
                let Some(import) = self.lib[k].imports.get(*next) else {
                    state[k] = 2;
                    path.pop();
                    continue;
                };
                *next += 1;
                let Some(to) = index(&import.module) else { continue };
                match state[to] {
                    0 => {
                        state[to] = 1;
                        path.push((to, 0));
                    }
                    1 => {
                        let from = path.iter().position(|(m, _)| *m == to).expect("on the path");
                        return Some(path[from..].iter().map(|(m, n)| (*m, &self.lib[*m].imports[n - 1])).collect());
                    }
                    _ => {}
                }
            }
        }
        None
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
    // A compute pass keeps its one entry; a render pass both its stages.
    let compute = module.entry_points.iter().any(|e| e.name == entry && e.stage == naga::ShaderStage::Compute);
    let (resolved, resolved_info) = naga::back::pipeline_constants::process_overrides(
        module,
        &info,
        compute.then_some((naga::ShaderStage::Compute, entry)),
        &map,
    )
    .map_err(|e| GpuError::Shader(format!("{name}: override values do not resolve: {e}")))?;
    Ok((resolved.into_owned(), resolved_info.into_owned()))
}

/// `text` (naga's WGSL of `module`) with every struct member's offset and
/// every struct's size as in `module`. naga's writer drops `@align` and
/// `@size`, so a struct the source laid out with them would reach Tint with
/// other offsets than the ones vista packs its uniforms by (Chrome's
/// relaxed uniform layout then accepts it and reads shifted values). Each
/// member whose offset or struct size differs gets `@size(next offset -
/// offset)`; structs that already agree are left as written. Also returns
/// the writer's text parsed back (its names, entry points included, are
/// the ones the returned text has).
pub fn keep_struct_layouts(
    name: &str,
    module: &naga::Module,
    text: String,
) -> Result<(String, naga::Module), GpuError> {
    use naga::TypeInner;
    // naga's writer leaves out the enable directives its own output needs.
    let enables: String = features_used(module)
        .iter()
        .filter(|(_, e)| !text.contains(&format!("enable {e};")))
        .map(|(_, e)| format!("enable {e};\n"))
        .collect();
    let text = enables + &text;
    let written = naga::front::wgsl::parse_str(&text)
        .map_err(|e| GpuError::Shader(format!("{name}: naga cannot read back its own WGSL: {e}")))?;
    let layout = |m: &naga::Module, ty: &str| {
        m.types.iter().find_map(|(_, t)| match (&t.inner, t.name.as_deref()) {
            (TypeInner::Struct { members, span }, Some(n)) if n == ty => {
                Some((members.iter().map(|m| m.offset).collect::<Vec<u32>>(), *span))
            }
            _ => None,
        })
    };
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for (_, t) in module.types.iter() {
        let (TypeInner::Struct { members, span }, Some(ty)) = (&t.inner, t.name.as_deref()) else { continue };
        let want: Vec<u32> = members.iter().map(|m| m.offset).collect();
        let Some((got, got_span)) = layout(&written, ty) else { continue };
        if got == want && got_span == *span {
            continue;
        }
        let Some(start) = lines.iter().position(|l| l.trim() == format!("struct {ty} {{")) else {
            return Err(GpuError::Shader(format!("{name}: struct {ty} not found in naga's WGSL")));
        };
        for (i, line) in lines[start + 1..start + 1 + members.len()].iter_mut().enumerate() {
            let end = want.get(i + 1).copied().unwrap_or(*span);
            let indent = line.len() - line.trim_start().len();
            line.insert_str(indent, &format!("@size({}) ", end - want[i]));
        }
    }
    let mut out = lines.join("\n");
    out.push('\n');
    Ok((out, written))
}

/// The default of [`compose_limit`]: a minute, about 30,000 `const` lines
/// on a CI core; no shader a project ships comes near it.
pub const DEFAULT_COMPOSE_LIMIT: std::time::Duration = std::time::Duration::from_secs(60);

static COMPOSE_LIMIT: std::sync::OnceLock<std::time::Duration> = std::sync::OnceLock::new();
static RUNAWAY: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Sets this process's [`compose_limit`] (the binary's configuration does,
/// from `VISTA_COMPILE_TIMEOUT_S`); the first setting wins.
pub fn set_compose_limit(limit: std::time::Duration) {
    let _ = COMPOSE_LIMIT.set(limit);
}

/// How long composing and validating one shader may take: as set (a
/// worker gets its parent's), else [`DEFAULT_COMPOSE_LIMIT`].
pub fn compose_limit() -> std::time::Duration {
    COMPOSE_LIMIT.get().copied().unwrap_or(DEFAULT_COMPOSE_LIMIT)
}

/// Compositions that passed the limit and still run in the background.
pub fn runaway_compositions() -> usize {
    RUNAWAY.load(std::sync::atomic::Ordering::SeqCst)
}

/// A kernel's WGSL as its files give it, and where each line came from.
#[derive(Debug, Clone)]
pub struct SourceText {
    /// The text naga parses.
    pub text: String,
    /// What errors name: the kernel file's real path.
    origin: String,
    /// Set for an assembly or a compiler's output.
    assembled: Option<vista_source::Assembled>,
}

impl SourceText {
    /// The file and 1-based line that line `line` (1-based) of `text`
    /// came from; `None` where the text is a compiler's untraced output.
    pub fn locate(&self, line: usize) -> Option<(String, usize)> {
        match &self.assembled {
            None => (line >= 1 && line <= self.text.lines().count()).then(|| (self.origin.clone(), line)),
            Some(a) => a.locate(line).map(|(file, at)| (file.to_string(), at)),
        }
    }

    /// What errors name for the whole text.
    pub fn origin(&self) -> &str {
        &self.origin
    }
}

/// Whether `source` has a line naga_oil's preprocessor acts on (`#import`,
/// `#ifdef`, `#define_import_path`, ...); WGSL itself has no `#`.
fn has_directives(source: &str) -> bool {
    source.lines().any(|l| l.trim_start().starts_with('#'))
}

/// naga's writer prints an f32 as its shortest decimal, and that of
/// `f32::MAX` (3.4028235e38) is above `f32::MAX`, which Tint refuses as
/// "cannot be represented as 'f32'". Every other finite f32's shortest
/// decimal lies within half an ulp of it, inside the range. The hex form
/// is exact.
pub(crate) fn exact_f32_max(text: &str) -> String {
    text.replace("340282350000000000000000000000000000000f", "0x1.fffffep+127f")
}

/// The kernel file of a kernel name (`fbm.wgsl?A&B` -> `fbm.wgsl`,
/// `k.wgsl|1a2b3c4d?%0=r32float` -> `k.wgsl`).
fn file_of(name: &str) -> &str {
    let unit = name.split_once('?').map_or(name, |(file, _)| file);
    unit.split_once('|').map_or(unit, |(file, _)| file)
}

/// The `[source]` spec id of a name (`k.wgsl|1a2b3c4d?...`), if any.
fn spec_id(name: &str) -> Option<&str> {
    let unit = name.split_once('?').map_or(name, |(file, _)| file);
    unit.split_once('|').map(|(_, id)| id)
}

/// A name without its shader defs: what one assembly is keyed by (the
/// file, the spec id, the replacement texts).
fn unit_key(name: &str) -> String {
    // A .wesl shader's text depends on its defs (its @if features).
    if file_of(name).ends_with(".wesl") {
        return name.to_string();
    }
    let (unit, rest) = name.split_once('?').unwrap_or((name, ""));
    let values: Vec<&str> = rest.split('&').filter(|d| d.starts_with('%')).collect();
    if values.is_empty() { unit.to_string() } else { format!("{unit}?{}", values.join("&")) }
}

/// The text of each `{ param = .. }` replacement of `spec`, from the name's
/// `%i=text` items; a name without them (a hash over the manifest's
/// assembly, whatever the params) puts `<param>` in their place.
fn replacement_values(name: &str, spec: &vista_source::SourceSpec) -> Vec<String> {
    let rest = name.split_once('?').map_or("", |(_, d)| d);
    spec.params()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            rest.split('&')
                .find_map(|d| d.strip_prefix(&format!("%{i}=")))
                .map_or_else(|| format!("<{p}>"), str::to_string)
        })
        .collect()
}

/// A root-relative path as per-file hashes name files: relative to
/// `shaders/` where it lies there (as a kernel's own files), else as is.
fn shader_rel(path: &str) -> String {
    path.strip_prefix("shaders/").unwrap_or(path).to_string()
}

/// `message` with every `origin:LINE:COL` of the assembled text replaced by
/// the file and line that line came from, and the line numbers of the
/// quoted source (`36 │ let t = ...`) by that file's own.
fn locate(message: &str, origin: &str, a: &vista_source::Assembled) -> String {
    let located = locate_headers(message, origin, a);
    let mut out = String::with_capacity(located.len());
    for line in located.split_inclusive('\n') {
        let indent = line.len() - line.trim_start().len();
        let digits = line[indent..].chars().take_while(char::is_ascii_digit).count();
        let number = line[indent..indent + digits].parse::<usize>().ok();
        match number.and_then(|n| a.locate(n)) {
            Some((_, own)) if line[indent + digits..].trim_start().starts_with('│') => {
                let width = indent + digits;
                out.push_str(&format!("{own:>width$}"));
                out.push_str(&line[width..]);
            }
            _ => out.push_str(line),
        }
    }
    out
}

fn locate_headers(message: &str, origin: &str, a: &vista_source::Assembled) -> String {
    let needle = format!("{origin}:");
    let mut out = String::new();
    let mut rest = message;
    while let Some(at) = rest.find(&needle) {
        out.push_str(&rest[..at]);
        let after = &rest[at + needle.len()..];
        let digits = after.chars().take_while(char::is_ascii_digit).count();
        match after[..digits].parse::<usize>().ok().and_then(|l| a.locate(l)) {
            Some((file, line)) if after[digits..].starts_with(':') => out.push_str(&format!("{file}:{line}")),
            _ => out.push_str(&format!("{origin}:{}", &after[..digits])),
        }
        rest = &after[digits..];
    }
    out.push_str(rest);
    out
}

/// The module path `source` declares and the modules it imports, both by
/// naga_oil's own preprocessor (grouped, nested, multi-line and aliased
/// imports, as naga_oil composes them: a module counts where an item of it
/// is used). Each import carries the line of the `#import` naming it.
fn preprocess(source: &str) -> (Option<String>, Vec<Import>) {
    let (module, imports, _) = naga_oil::compose::get_preprocessor_data(source);
    // naga_oil yields nothing for a file it cannot parse; composing it then
    // reports the error. The declared path is still wanted to place the file.
    let module = module.or_else(|| {
        source.lines().find_map(|l| l.trim().strip_prefix("#define_import_path").map(|p| p.trim().to_string()))
    });
    let statements = import_statements(source);
    let imports = imports
        .into_iter()
        .map(|d| {
            let line = statements.iter().find(|(_, paths)| {
                paths
                    .iter()
                    .any(|p| *p == d.import || p.strip_prefix(d.import.as_str()).is_some_and(|r| r.starts_with("::")))
            });
            Import { module: d.import, line: line.map(|(l, _)| *l) }
        })
        .collect();
    (module, imports)
}

/// Each `#import` statement of `source` (one or several lines, until its
/// braces close): its first line (1-based) and the full paths naga_oil's
/// import parser declares from it. Only used to say where a module is
/// imported; which modules are imported comes from [`preprocess`].
fn import_statements(source: &str) -> Vec<(usize, Vec<String>)> {
    let uncommented = |l: &str| l.split("//").next().unwrap_or("").to_string();
    let lines: Vec<String> = source.lines().map(uncommented).collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        let start = k;
        let is_import = lines[k].trim_start().strip_prefix('#').is_some_and(|r| r.trim_start().starts_with("import"));
        if !is_import {
            k += 1;
            continue;
        }
        let mut text = String::new();
        let mut open = 0usize;
        while k < lines.len() {
            open += lines[k].matches('{').count();
            open = open.saturating_sub(lines[k].matches('}').count());
            text.push_str(&lines[k]);
            text.push('\n');
            k += 1;
            if open == 0 {
                break;
            }
        }
        let mut declared = Default::default();
        if naga_oil::compose::parse_imports::parse_imports(&text, &mut declared).is_ok() {
            out.push((start + 1, declared.into_values().flatten().collect()));
        }
    }
    out
}

fn describe(composer: &Composer, label: &str, e: &ComposerError) -> String {
    format!("WGSL error ({label}):\n{}", e.emit_to_string(composer))
}

/// The optional shader capabilities vista validates with, each with the
/// WebGPU feature a device needs for it and the `enable` directive WGSL
/// names it by: a device without the feature reports the case unsupported
/// ([`features_used`]).
pub const OPTIONAL_CAPABILITIES: [(naga::valid::Capabilities, &str, &str); 2] = [
    (naga::valid::Capabilities::SHADER_FLOAT16, "shader-f16", "f16"),
    (naga::valid::Capabilities::DUAL_SOURCE_BLENDING, "dual-source-blending", "dual_source_blending"),
];

/// The default capabilities and every one of [`OPTIONAL_CAPABILITIES`].
fn all_capabilities() -> naga::valid::Capabilities {
    OPTIONAL_CAPABILITIES.iter().fold(naga::valid::Capabilities::default(), |c, (cap, _, _)| c | *cap)
}

/// Validates a composed module with naga alone (no device needed), the
/// [`OPTIONAL_CAPABILITIES`] allowed.
pub fn validate(name: &str, module: &naga::Module) -> Result<naga::valid::ModuleInfo, GpuError> {
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), all_capabilities())
        .validate(module)
        .map_err(|e| GpuError::Shader(format!("{name}: naga validation failed: {}", e.emit_to_string(""))))
}

/// The shader defs after `?` in a kernel name (`fbm.wgsl?A&B&N=10&F=false`):
/// a bare name is `true`, `NAME=value` a bool or an integer (i32, else u32).
fn shader_defs(name: &str) -> HashMap<String, naga_oil::compose::ShaderDefValue> {
    use naga_oil::compose::ShaderDefValue as V;
    let defs = name.split_once('?').map_or("", |(_, d)| d);
    defs.split('&')
        .filter(|d| !d.is_empty() && !d.starts_with('%'))
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

/// The [`OPTIONAL_CAPABILITIES`] a module uses, as (WebGPU feature,
/// `enable` name): f16 in a literal or conversion needs no type of the
/// module's own, so the question goes to naga's validator: the module is
/// valid only with that capability. Nothing for a module that needs none.
pub fn features_used(module: &naga::Module) -> Vec<(&'static str, &'static str)> {
    let all = all_capabilities();
    let valid = |caps| naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps).validate(module).is_ok();
    if valid(naga::valid::Capabilities::default()) || !valid(all) {
        return Vec::new();
    }
    OPTIONAL_CAPABILITIES.iter().filter(|(cap, _, _)| !valid(all - *cap)).map(|(_, f, e)| (*f, *e)).collect()
}
