//! A project's WGSL read once ([`Sources`]): its shader files, each
//! kernel's generated enum module and `[source]` assemblies, from which
//! the project's [`ShaderSet`] (or one with a file replaced) is made.

use vista_gpu::ShaderSet;

use crate::RenderError;

/// A file a `[source] command` generated: its path under `shaders/` and
/// the inputs it read (root-relative path, hash), or why there is no text.
type GeneratedFile = (String, Result<Vec<(String, String)>, String>);

/// A project's WGSL read once: its `shaders/` files over the built-ins,
/// each kernel's generated `vista::enums` module, its `[source]`
/// assemblies and a reader of the files they reach outside `shaders/`.
/// Makes the project's [`ShaderSet`], or one with a file's text replaced
/// (each mutant of `vista mutate`), without reading the project again.
#[derive(Debug, Clone)]
pub struct Sources {
    label: String,
    /// (path relative to `shaders/`, text, origin).
    files: Vec<(String, String, String)>,
    enums: Vec<(String, String, String)>,
    specs: Vec<(String, vista_source::SourceSpec)>,
    reader: vista_gpu::Reader,
    /// Files a `[source] command` generated: the inputs it read, or why not.
    generated: Vec<GeneratedFile>,
}

impl Sources {
    /// The project's sources, read now.
    pub fn of(project: &vista_project::Project) -> Result<Sources, RenderError> {
        let label = match project.root() {
            Some(r) => format!("project {}", r.display()),
            None => "built-in shaders".to_string(),
        };
        // The manifests, parsed once for all that follows.
        let registry = registry(project)?;
        let mut files: Vec<(String, String, String)> =
            project.shader_files()?.into_iter().map(|f| (f.rel, f.text, f.origin)).collect();
        files.extend(other_extensions(project, &registry, &files));
        let generated = generate(project, &registry, &mut files);
        let (specs, reader) = specs_of(project, &registry);
        files.extend(generated_modules(&specs)?);
        let mut enums = enums_of(&registry);
        enums.extend(test_file_enums(&files, &enums));
        Ok(Sources { label, files, enums, specs, reader, generated })
    }

    /// The project's shader set.
    pub fn shader_set(&self) -> ShaderSet {
        ShaderSet::from_files(&self.label, self.files.iter().cloned())
            .with_enums(self.enums.iter().cloned())
            .with_sources(self.specs.iter().cloned(), self.reader.clone())
            .with_generated(self.generated.iter().cloned())
    }

    /// The set with file `rel` holding `text` instead (a path relative to
    /// `shaders/`, or relative to the root for a file a `[source]` reaches
    /// outside it).
    pub fn with_file(&self, label: &str, rel: &str, text: String) -> ShaderSet {
        self.with_files(label, &[(rel.to_string(), text)])
    }

    /// The set with each `(rel, text)` of `edits` replacing its file (as
    /// [`Sources::with_file`]): a mutant and a unit test file's rewrite at once.
    pub fn with_files(&self, label: &str, edits: &[(String, String)]) -> ShaderSet {
        let edited = |rel: &str| edits.iter().find(|(r, _)| r == rel).map(|(_, t)| t.clone());
        let files: Vec<(String, String, String)> = self
            .files
            .iter()
            .map(|f| match edited(&f.0) {
                Some(text) => (f.0.clone(), text, f.2.clone()),
                None => f.clone(),
            })
            .collect();
        let (read, edits) = (self.reader.clone(), edits.to_vec());
        let reader = vista_gpu::Reader::new(move |path| match edits.iter().find(|(r, _)| r == path) {
            Some((_, text)) => read.read(path).map(|(_, origin)| (text.clone(), origin)),
            None => read.read(path),
        });
        ShaderSet::from_files(label, files)
            .with_enums(self.enums.iter().cloned())
            .with_sources(self.specs.iter().cloned(), reader)
            .with_generated(self.generated.iter().cloned())
    }
}

/// Runs every kernel's `[source] command`s (or takes their cached output)
/// and puts each output in place of its template among `files`. A command
/// that fails, or a file two passes generate differently, is kept as the
/// file's error, said when a case composes it.
fn generate(
    project: &vista_project::Project,
    registry: &vista_kernels::Registry,
    files: &mut Vec<(String, String, String)>,
) -> Vec<GeneratedFile> {
    let mut out: Vec<GeneratedFile> = Vec::new();
    let mut by: Vec<(String, String, vista_source::Generator)> = Vec::new();
    for k in registry.kernels() {
        for (file, g) in k.generated_files() {
            if let Some((_, other, known)) = by.iter().find(|(f, _, _)| *f == file) {
                if *known != g {
                    let who = match other == k.name() {
                        true => format!("two passes of kernel {other}"),
                        false => format!("kernels {other} and {}", k.name()),
                    };
                    let why = format!(
                        "shaders/{file}: {who} generate it with different [source] commands, inputs or timeouts \
                         (`{}`; `{}`); give each its own file",
                        known.describe(),
                        g.describe()
                    );
                    out.retain(|(f, _)| *f != file);
                    out.push((file, Err(why)));
                }
                continue;
            }
            by.push((file.clone(), k.name().to_string(), g.clone()));
            let made = match project.root() {
                Some(root) => crate::command::generate(root, &file, &g),
                None => Err(format!("shaders/{file}: a [source] command runs in a project root; there is none")),
            };
            match made {
                Ok(made) => {
                    files.retain(|(rel, _, _)| *rel != file);
                    files.push((file.clone(), made.text, made.origin));
                    out.push((file, Ok(made.inputs)));
                }
                Err(why) => out.push((file, Err(why))),
            }
        }
    }
    out
}

/// The modules the kernels' `[source] modules` generate, as import-module
/// files (`<generated>/<path>.wgsl`). One import path is one module in a
/// project: two kernels that give it different constants are refused.
fn generated_modules(
    specs: &[(String, vista_source::SourceSpec)],
) -> Result<Vec<(String, String, String)>, RenderError> {
    let mut out: Vec<(String, String, String)> = Vec::new();
    for (name, text) in specs.iter().flat_map(|(_, s)| &s.modules) {
        let rel = format!("generated/{}.wgsl", name.replace("::", "/"));
        match out.iter().find(|(r, _, _)| *r == rel) {
            Some((_, other, _)) if other != text => {
                return Err(RenderError::BadInput(format!(
                    "[source] modules: two kernels generate module {name} with different constants; one import \
                     path is one module in a project (rename one)"
                )));
            }
            Some(_) => {}
            None => out.push((rel, text.clone(), format!("<generated>/{name}.wgsl ([source] modules)"))),
        }
    }
    Ok(out)
}

/// Every kernel's `[source]` assemblies, by id (SPEC 16), and a reader of
/// the project's files for what they reach outside `shaders/`.
pub fn source_specs(
    project: &vista_project::Project,
) -> Result<(Vec<(String, vista_source::SourceSpec)>, vista_gpu::Reader), RenderError> {
    Ok(specs_of(project, &registry(project)?))
}

/// The project's kernel manifests.
pub(crate) fn registry(project: &vista_project::Project) -> Result<vista_kernels::Registry, RenderError> {
    vista_kernels::Registry::of_project(project).map_err(|e| RenderError::BadInput(e.to_string()))
}

/// [`source_specs`] of manifests already parsed.
fn specs_of(
    project: &vista_project::Project,
    registry: &vista_kernels::Registry,
) -> (Vec<(String, vista_source::SourceSpec)>, vista_gpu::Reader) {
    let project = project.clone();
    let specs = registry.kernels().iter().flat_map(|k| k.source_specs()).collect();
    (specs, vista_gpu::Reader::new(move |rel| project.read_text(rel)))
}

/// Each kernel's generated `vista::enums` module (from its manifest's enum
/// params), as `(shader file, kernel, text)` for every file its passes use.
/// A manifest that does not parse contributes none (its error comes when
/// the kernel is named).
pub fn enum_modules(project: &vista_project::Project) -> Result<Vec<(String, String, String)>, RenderError> {
    Ok(enums_of(&registry(project)?))
}

/// [`enum_modules`] of manifests already parsed.
fn enums_of(registry: &vista_kernels::Registry) -> Vec<(String, String, String)> {
    let mut out = Vec::new();
    for k in registry.kernels() {
        let text = k.enum_module();
        for f in k.shader_files() {
            out.push((f.to_string(), k.name().to_string(), text.clone()));
        }
    }
    out
}

/// The shader files of kernels with `language = "wgsl"` that `shaders/`'s
/// listing leaves out (any extension but `.wgsl` and `.wesl`), read through
/// the project's guard; one that is not there is left to the
/// not-found error that names the kernel files.
fn other_extensions(
    project: &vista_project::Project,
    registry: &vista_kernels::Registry,
    listed: &[(String, String, String)],
) -> Vec<(String, String, String)> {
    let mut out: Vec<(String, String, String)> = Vec::new();
    for k in registry.kernels().iter().filter(|k| k.reads_any_extension()) {
        for f in k.shader_files() {
            if listed.iter().chain(&out).any(|(rel, _, _)| rel == f) {
                continue;
            }
            if let Some((text, origin)) = project.read_text(&format!("shaders/{f}")) {
                out.push((f.to_string(), text, origin));
            }
        }
    }
    out
}

/// The `vista::enums` of each WGSL unit test file, which no manifest
/// names: every kernel's enum constants (so a test of a library module
/// that imports them composes), but a constant two kernels give different
/// values, which is left out (a test that names it fails to compose,
/// naming it).
fn test_file_enums(
    files: &[(String, String, String)],
    kernels: &[(String, String, String)],
) -> Vec<(String, String, String)> {
    let mut consts: std::collections::BTreeMap<String, Option<String>> = Default::default();
    for (_, _, text) in kernels {
        for line in text.lines().filter(|l| l.starts_with("const ")) {
            let name = line["const ".len()..].split(':').next().unwrap_or_default().trim().to_string();
            consts
                .entry(name)
                .and_modify(|v| {
                    if v.as_deref() != Some(line) {
                        *v = None
                    }
                })
                .or_insert_with(|| Some(line.to_string()));
        }
    }
    let mut text = format!(
        "#define_import_path {}\n\n// Every kernel's enum constants, for the WGSL unit tests; those two kernels give \
         different values are left out.\n",
        vista_gpu::ENUMS_MODULE
    );
    for line in consts.values().flatten() {
        text.push_str(line);
        text.push('\n');
    }
    files
        .iter()
        .filter(|f| vista_gpu::is_unit_test_file(&f.0))
        .map(|f| (f.0.clone(), "the project's kernels (a WGSL unit test)".to_string(), text.clone()))
        .collect()
}

/// The project's WGSL as one [`ShaderSet`].
pub fn shader_set(project: &vista_project::Project) -> Result<ShaderSet, RenderError> {
    Ok(Sources::of(project)?.shader_set())
}

/// The project's WGSL with every file's text passed through `edit(relative
/// path, text)` (a mutant, a deliberate fault), composed in memory: nothing
/// is written. Kernel files keep their generated `vista::enums` modules.
pub fn edited_shader_set(
    project: &vista_project::Project,
    label: &str,
    edit: impl Fn(&str, String) -> String,
) -> Result<ShaderSet, RenderError> {
    let mut sources = Sources::of(project)?;
    sources.label = label.to_string();
    for f in &mut sources.files {
        f.1 = edit(&f.0, std::mem::take(&mut f.1));
    }
    Ok(sources.shader_set())
}
