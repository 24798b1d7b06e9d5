//! [`Kernel`]: a parsed manifest, where it came from, and the CPU reference
//! a registry attached ([`CpuReference`]): its params resolved, its
//! shaders' text with defs, its display map and output bounds.

use vista_image::Image;

use crate::manifest::HashPlane;
use crate::params::{ParamSet, ParamSpec, ParamType, Preset, Value};
use crate::view::{DisplayMap, Output, is_integer_format};
use crate::{ParamError, graph, manifest};

/// What Rust keeps for a built-in kernel because data cannot say it: the
/// CPU references, cross-parameter checks and a tighter output guard.
pub trait CpuReference: Send + Sync {
    /// The f64 CPU reference of the raw output (what the GPU writes).
    fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image;
    /// The same reference computed in f32 (the private `cpu32` build): a throughput
    /// baseline for benches (checked against f64 in `tests/precision.rs`).
    fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image;
    /// Cross-parameter checks beyond each value's own range.
    fn check(&self, _p: &ParamSet) -> Result<(), ParamError> {
        Ok(())
    }
    /// Inclusive bounds every RGB value of the raw output must respect,
    /// when the math gives tighter ones than the manifest's `output_range`.
    fn output_bounds(&self, _p: &ParamSet) -> Option<(f32, f32)> {
        None
    }
    /// The shader's own algorithm run on the CPU in f32, for a kernel whose
    /// reference is a different (slower) algorithm: the like-for-like bench
    /// baseline. `None` when the reference already is that algorithm.
    fn shader_algorithm_f32(&self, _p: &ParamSet, _width: u32, _height: u32) -> Option<Image> {
        None
    }
    /// The work estimate averaged over an image's rays, for a kernel whose
    /// per-ray cost varies with the ray (clouds' step_km); `None` when the
    /// manifest's per-pixel estimate holds for every pixel.
    fn mean_work_per_pixel(&self, _p: &ParamSet, _width: u32, _height: u32) -> Option<f64> {
        None
    }
}

/// One kernel: its manifest, where it came from, and its CPU reference if
/// one is registered under its name. A registry owns its kernels and
/// shares them by `Arc`.
#[derive(Clone)]
pub struct Kernel {
    pub(crate) manifest: manifest::Manifest,
    origin: String,
    cpu: Option<&'static dyn CpuReference>,
}

impl std::fmt::Debug for Kernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Kernel {
    /// Parses a manifest (`origin` names it in errors). The kernel has no
    /// CPU reference until [`Kernel::with_reference`] attaches one.
    pub fn from_manifest(name: &str, origin: &str, text: &str) -> Result<Kernel, ParamError> {
        let manifest = manifest::parse(name, origin, text)?;
        Ok(Kernel { cpu: None, manifest, origin: origin.to_string() })
    }

    /// The kernel with `cpu`, the reference of the built-in of its name,
    /// attached, but only while its manifest (`text`) declares the
    /// built-in's params (names and types): a project kernel that shares a
    /// built-in's name with other params is a kernel of its own, with
    /// goldens and guards but no reference (the reference reads the
    /// built-in's params, and would find them missing).
    pub fn with_reference(mut self, cpu: &'static dyn CpuReference, text: &str) -> Kernel {
        // A copy of the built-in's manifest (the usual case: `vista init`,
        // the examples, every test project) declares its params without
        // parsing the built-in a second time; each `vista` process parses
        // every manifest, and the CLI suite starts hundreds of them.
        if builtin_manifest(self.name()) == Some(text) || same_params_as_builtin(&self.manifest) {
            self.cpu = Some(cpu);
        }
        self
    }

    /// The kernel's name: the manifest's file stem.
    pub fn name(&self) -> &str {
        &self.manifest.name
    }
    /// One line for `vista list`.
    pub fn summary(&self) -> &str {
        &self.manifest.summary
    }
    /// The manifest's path (or `<built-in>/kernels/...`).
    pub fn origin(&self) -> &str {
        &self.origin
    }
    /// The declared parameters, in manifest order.
    pub fn params(&self) -> &[ParamSpec] {
        &self.manifest.params
    }
    /// The named presets, in manifest order.
    pub fn presets(&self) -> &[Preset] {
        &self.manifest.presets
    }
    /// WGSL file under `shaders/` holding the compute entry point.
    pub fn shader(&self) -> &str {
        &self.manifest.shader
    }

    /// `language = "wgsl"`: its shader files are WGSL whatever their
    /// extension, so vista reads them though `shaders/` lists only
    /// `.wgsl` and `.wesl` files.
    pub fn reads_any_extension(&self) -> bool {
        self.manifest.language.is_some()
    }
    /// The PNG view the manifest gives (default display).
    pub fn output(&self) -> Output {
        self.manifest.output.unwrap_or(Output::Display)
    }
    /// The PNG view of an output of `format`: the manifest's, else
    /// normalize for an integer format and display otherwise.
    pub fn view(&self, format: &str) -> Output {
        // A graph's first output may say its own view.
        match self.graph().outputs.first().and_then(|o| o.view) {
            Some(v) => v,
            None => self.default_view(format),
        }
    }

    /// The view of an output of `format` that says none: the manifest's
    /// `output`, else normalize for an integer format and display otherwise.
    pub fn default_view(&self, format: &str) -> Output {
        match self.manifest.output {
            Some(v) => v,
            None if is_integer_format(format) => Output::Normalize,
            None => Output::Display,
        }
    }
    /// Whether a CPU reference is registered for this kernel.
    pub fn has_reference(&self) -> bool {
        self.cpu.is_some()
    }

    /// Defaults, preset and overrides, validated (ranges and cross-parameter checks).
    pub fn resolve(&self, preset: Option<&str>, overrides: &[(String, String)]) -> Result<ParamSet, ParamError> {
        let set = ParamSet::resolve(self.name(), self.params(), self.presets(), preset, overrides)?;
        if let Some(cpu) = self.cpu {
            cpu.check(&set)?;
        }
        Ok(set)
    }

    /// Raw output to display values in [0, 1].
    pub fn display(&self, raw: &Image, p: &ParamSet) -> Image {
        self.display_map(p).apply(raw).unwrap_or_else(|| raw.clone())
    }

    /// How this kernel's display values follow from its raw output for `p`.
    pub fn display_map(&self, p: &ParamSet) -> DisplayMap {
        self.display_map_of(p, "rgba32float")
    }

    /// The display map of an output of `format` (see [`Kernel::view`]).
    pub fn display_map_of(&self, p: &ParamSet, format: &str) -> DisplayMap {
        self.display_map_with(p, self.view(format), format, self.graph().outputs.first().and_then(|o| o.exposure))
    }

    /// The display map of an output of `format` shown with `view` (a graph
    /// output's own `view`), its hdr tone map at `exposure` (the output's
    /// setting; default 1). A kernel's `exposure` param wins, so cases and
    /// sweeps can vary it.
    pub fn display_map_with(&self, p: &ParamSet, view: Output, format: &str, exposure: Option<f64>) -> DisplayMap {
        // Normalized channels: one or two for r and rg formats, else RGB.
        let channels = vista_texel::Format::parse(format).map_or(3, |f| f.channels().min(3) as u8);
        DisplayMap {
            channels,
            exposure: (view == Output::Hdr).then(|| match p.value("exposure") {
                Some(_) => p.f32("exposure"),
                None => exposure.unwrap_or(1.0) as f32,
            }),
            opaque: self.manifest.opaque_display,
            normalize: view == Output::Normalize,
        }
    }

    /// The manifest's work estimate per pixel (product of its `work`
    /// entries; 1 without any), used to refuse absurd dispatches.
    pub fn work_per_pixel(&self, p: &ParamSet) -> f64 {
        self.manifest.work.iter().map(|f| f.constant + f.params.iter().map(|n| p.f64(n)).sum::<f64>()).product()
    }

    /// [`Self::work_per_pixel`] averaged over a `width` x `height` image's
    /// rays where the CPU reference knows it per ray, else the estimate.
    pub fn mean_work_per_pixel(&self, p: &ParamSet, width: u32, height: u32) -> f64 {
        self.cpu.and_then(|c| c.mean_work_per_pixel(p, width, height)).unwrap_or_else(|| self.work_per_pixel(p))
    }

    /// Inclusive bounds every RGB value of the raw output must respect.
    pub fn output_bounds(&self, p: &ParamSet) -> (f32, f32) {
        self.output_bounds_of(p, "rgba32float")
    }

    /// The bounds of an output of `format`: a normalised view (an integer
    /// format's default) bounds nothing but finiteness.
    pub fn output_bounds_of(&self, p: &ParamSet, format: &str) -> (f32, f32) {
        if let Some(b) = self.cpu.and_then(|c| c.output_bounds(p)) {
            return b;
        }
        self.output_bounds_with(p, self.view(format))
    }

    /// The bounds of an output shown with `view` (a graph output's own).
    pub fn output_bounds_with(&self, p: &ParamSet, view: Output) -> (f32, f32) {
        if let Some(b) = self.cpu.and_then(|c| c.output_bounds(p)) {
            return b;
        }
        match (self.manifest.output_range, view) {
            (Some((lo, hi)), _) => (lo as f32, hi as f32),
            (None, Output::Display) => (0.0, 1.0),
            (None, Output::Hdr) => (0.0, f32::INFINITY),
            (None, Output::Normalize) => (f32::NEG_INFINITY, f32::INFINITY),
        }
    }

    /// Settings of the high-quality reference that sweeps compare against.
    pub fn high_quality(&self) -> Vec<(&str, &str)> {
        self.manifest.sweep_reference.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect()
    }

    /// Read-only u32 table for binding 2, if the module declares it:
    /// The integer plane z of the manifest's `hash_plane` (its fixed z, or
    /// its param's value when that is an integer): the table then carries
    /// that plane's corner hashes and the shader is composed with
    /// VISTA_HASH_PLANE (lib/noise.wgsl).
    pub fn hash_plane(&self, p: &ParamSet) -> Option<i64> {
        match self.manifest.hash_plane.as_ref()? {
            HashPlane::Fixed(z) => Some(*z),
            HashPlane::Param(name) => match p.value(name) {
                Some(Value::Float(z)) if z.fract() == 0.0 => Some(*z as i64),
                _ => None,
            },
        }
    }

    /// The kernel file to compose for `p`: [`Self::shader`], followed by
    /// the naga_oil shader defs after `?`, joined by `&`: the manifest's
    /// `defs` as `NAME=value`, then those `p` selects:
    /// `VISTA_HASH_PLANE` on a hash plane, then `NAME_IS_VALUE` (upper case)
    /// for each param the manifest lists under `specialize`, e.g.
    /// `fbm.wgsl?VISTA_HASH_PLANE&BASIS_IS_PERLIN`. Each distinct name is
    /// composed, cached and compiled as its own pipeline.
    pub fn shader_for(&self, p: &ParamSet) -> String {
        self.with_defs(self.shader(), &[], &self.manifest.source, p)
    }

    /// How pass `i`'s text is assembled: the kernel's `[source]` with the
    /// pass's `source` keys over it.
    pub fn source_for(&self, i: usize) -> vista_source::SourceSpec {
        self.manifest.source.merged(&self.graph().passes[i].source)
    }

    /// How pass `i`'s separate vertex file is assembled: the pass's
    /// [`Kernel::source_for`] with the vertex's own `source` keys over it.
    pub fn vertex_source_for(&self, i: usize) -> vista_source::SourceSpec {
        let pass = self.source_for(i);
        match self.graph().passes[i].vertex_source() {
            Some(own) => pass.merged(own),
            None => pass,
        }
    }

    /// Each file of pass `i` with how it is assembled: the pass's shader,
    /// then its separate vertex file.
    fn pass_files(&self, i: usize) -> Vec<(&str, vista_source::SourceSpec)> {
        let pass = &self.graph().passes[i];
        let file = pass.shader.as_deref().unwrap_or(self.shader());
        let mut out = vec![(file, self.source_for(i))];
        if let Some(v) = pass.vertex_file() {
            out.push((v, self.vertex_source_for(i)));
        }
        out
    }

    /// Every distinct assembly the kernel's passes use, by
    /// [`vista_source::SourceSpec::id`] (none without `[source]`).
    pub fn source_specs(&self) -> Vec<(String, vista_source::SourceSpec)> {
        let n = self.graph().passes.len();
        let mut out: Vec<(String, vista_source::SourceSpec)> = Vec::new();
        let specs = (0..n).flat_map(|i| self.pass_files(i).into_iter().map(|(_, s)| s));
        for spec in specs.filter(|s| !s.is_empty()) {
            let id = spec.id();
            if !out.iter().any(|(known, _)| *known == id) {
                out.push((id, spec));
            }
        }
        out
    }

    /// Each shader file a `[source] command` generates, with its generator
    /// (a pass's files with the pass's merged `[source]`), in pass order.
    /// Two passes that generate one file differently are the caller's to
    /// refuse.
    pub fn generated_files(&self) -> Vec<(String, vista_source::Generator)> {
        let mut out: Vec<(String, vista_source::Generator)> = Vec::new();
        for i in 0..self.graph().passes.len() {
            for (file, spec) in self.pass_files(i) {
                let Some(g) = spec.generator() else { continue };
                if !out.iter().any(|(f, known)| f == file && *known == g) {
                    out.push((file.to_string(), g));
                }
            }
        }
        out
    }

    /// What each pass composes, without defs: its file, or `file|id` where
    /// a `[source]` assembles it ([`Kernel::source_specs`]). The shader
    /// hash and per-file hashes are taken over these.
    pub fn shader_units(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for i in 0..self.graph().passes.len() {
            for (file, spec) in self.pass_files(i) {
                let unit = if spec.is_empty() { file.to_string() } else { format!("{file}|{}", spec.id()) };
                if !out.contains(&unit) {
                    out.push(unit);
                }
            }
        }
        out
    }

    /// The WGSL module `vista::enums` of this kernel: every enum value as a
    /// `u32` constant named `PREFIX_VALUE` (the manifest's order), so WGSL
    /// names the values the manifest declares instead of repeating indices.
    pub fn enum_module(&self) -> String {
        let mut out = String::from("#define_import_path vista::enums\n\n");
        out.push_str(&format!("// Generated from the manifest of kernel {}.\n", self.name()));
        for (name, value) in &self.manifest.enum_constants {
            out.push_str(&format!("const {name}: u32 = {value}u;\n"));
        }
        out
    }

    /// The manifest's `[[group]]` for uniform field `field`, if any.
    pub fn group(&self, field: &str) -> Option<&manifest::ParamGroup> {
        self.manifest.groups.iter().find(|g| g.field == field)
    }

    /// `display_alpha = "opaque"`: the PNG view's alpha is 1 (its RGB is
    /// already composited) while the raw alpha means something (the clouds'
    /// 1 - T), so goldens keep that alpha beside the view.
    pub fn opaque_display(&self) -> bool {
        self.manifest.opaque_display
    }

    /// `file` with the defs of [`Kernel::shader_for`].
    ///
    /// With a `[source]`, the file becomes `file|id` and each `{ param = .. }`
    /// replacement's text follows the defs as `%i=text` (an enum's value
    /// name, a number's decimal text), so each distinct text composes once.
    fn with_defs(&self, file: &str, pass_defs: &[String], source: &vista_source::SourceSpec, p: &ParamSet) -> String {
        // A case's def replaces the kernel's of the same name, and a pass's
        // replaces both: the pass's is its structure, the case's a variant.
        let name = |d: &String| d.split('=').next().unwrap_or_default().to_string();
        let mut defs: Vec<String> = Vec::new();
        for layer in [&self.manifest.defs[..], p.defs(), pass_defs] {
            defs.retain(|d| !layer.iter().any(|q| name(q) == name(d)));
            defs.extend(layer.iter().cloned());
        }
        // An enum param's value that names a def sets it.
        for spec in &self.manifest.params {
            if let Some(Value::Enum(v)) = p.value(&spec.name)
                && let Some((_, def)) = spec.defs.iter().find(|(value, _)| value == v)
                && !defs.iter().any(|d| name(d) == *def)
            {
                defs.push(def.clone());
            }
        }
        if self.hash_plane(p).is_some() {
            defs.push("VISTA_HASH_PLANE".into());
        }
        for name in &self.manifest.specialize {
            if let Some(Value::Enum(v)) = p.value(name) {
                defs.push(format!("{name}_is_{v}").to_uppercase().replace(|c: char| !c.is_ascii_alphanumeric(), "_"));
            }
        }
        let file = match source.is_empty() {
            true => file.to_string(),
            false => format!("{file}|{}", source.id()),
        };
        for (i, name) in source.params().into_iter().enumerate() {
            let text = match p.value(name) {
                Some(Value::Enum(v)) => v.clone(),
                Some(Value::Int(v)) => v.to_string(),
                Some(Value::Float(v)) => format!("{:?}", *v as f32),
                other => unreachable!("the manifest allows only enum and number params here, got {other:?}"),
            };
            defs.push(format!("%{i}={text}"));
        }
        match defs.is_empty() {
            true => file,
            false => format!("{file}?{}", defs.join("&")),
        }
    }

    /// Every kernel file the kernel's passes use (without defs), the
    /// manifest's first.
    pub fn shader_files(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for p in &self.graph().passes {
            let s = p.shader.as_deref().unwrap_or(self.shader());
            for s in std::iter::once(s).chain(p.vertex_file()) {
                if !out.contains(&s) {
                    out.push(s);
                }
            }
        }
        out
    }

    /// The manifest's `overrides` values, by name.
    pub fn manifest_overrides(&self) -> &[(String, f64)] {
        &self.manifest.overrides
    }

    /// The pass graph (SPEC 14): a manifest without `[[pass]]`,
    /// `[[resource]]` or `[[output]]` tables is one pass (`main`) whose
    /// written storage texture is its one output.
    pub fn graph(&self) -> &graph::GraphSpec {
        &self.manifest.graph
    }

    /// Whether the manifest describes its own resources, passes or outputs
    /// (`[[pass]]`, `[[resource]]`, `[[output]]`: SPEC 14) instead of
    /// following the seed's contract (SPEC 3-4).
    pub fn describes_resources(&self) -> bool {
        self.manifest.describes_resources
    }

    /// The file of graph pass `i` as composed for `p`: its `shader` (else
    /// the manifest's) with the defs of [`Kernel::shader_for`].
    pub fn pass_shader_for(&self, i: usize, p: &ParamSet) -> String {
        let pass = &self.graph().passes[i];
        let file = pass.shader.as_deref().unwrap_or(self.shader());
        self.with_defs(file, &pass.defs, &self.source_for(i), p)
    }

    /// The file of graph pass `i`'s vertex entry when another file holds
    /// it, composed for `p` with the pass's defs and source keys.
    pub fn vertex_shader_for(&self, i: usize, p: &ParamSet) -> Option<String> {
        let pass = &self.graph().passes[i];
        pass.vertex_file().map(|file| self.with_defs(file, &pass.defs, &self.vertex_source_for(i), p))
    }

    /// The value of every `override` constant of `module` for `p`: a param
    /// of its name, else the manifest's `overrides`, else its default
    /// (`None` in the list: naga takes the default). An override with
    /// neither, or a manifest value naming no override, is refused.
    pub fn overrides(&self, module: &naga::Module, p: &ParamSet) -> Result<Vec<(String, f64)>, ParamError> {
        self.overrides_in(module, p, true)
    }

    /// [`Kernel::overrides`]; with `strict` false a manifest value naming
    /// no override of this module is left for another pass's.
    pub fn overrides_in(
        &self,
        module: &naga::Module,
        p: &ParamSet,
        strict: bool,
    ) -> Result<Vec<(String, f64)>, ParamError> {
        let bad = |message: String| ParamError::Layout { kernel: self.name().to_string(), message };
        let names: Vec<&str> = module.overrides.iter().filter_map(|(_, o)| o.name.as_deref()).collect();
        for (k, _) in &self.manifest.overrides {
            if strict && !names.contains(&k.as_str()) {
                return Err(bad(format!(
                    "overrides: {k} is not an override of {}; its overrides: {}",
                    self.shader(),
                    if names.is_empty() { "none".to_string() } else { names.join(", ") }
                )));
            }
        }
        let mut out = Vec::new();
        for (_, o) in module.overrides.iter() {
            let Some(name) = o.name.as_deref() else { continue };
            let value = match p.value(name) {
                Some(Value::Int(v)) => Some(*v as f64),
                Some(Value::Float(v)) => Some(*v),
                Some(Value::Bool(b)) => Some(*b as u8 as f64),
                Some(Value::Enum(v)) => match self.params().iter().find(|s| s.name == name).map(|s| &s.kind) {
                    Some(crate::Kind::Enum(names)) => names.iter().position(|n| n == v).map(|i| i as f64),
                    _ => None,
                },
                Some(Value::Vector(_)) => {
                    return Err(bad(format!("param {name} is a vector; an override takes one number")));
                }
                None => self.manifest.overrides.iter().find(|(k, _)| *k == name).map(|(_, v)| *v),
            };
            match (value, o.init) {
                (Some(v), _) => out.push((name.to_string(), v)),
                (None, Some(_)) => {}
                (None, None) => {
                    return Err(bad(format!(
                        "override {name} of {} has neither a default nor a value; give it one in the manifest \
                         (overrides = {{ {name} = ... }}) or a param named {name}",
                        self.shader()
                    )));
                }
            }
        }
        Ok(out)
    }

    /// Why a kernel named like a built-in has no CPU reference: how its
    /// manifest differs from the built-in's in what the reference reads.
    pub fn reference_mismatch(&self) -> Option<String> {
        if self.cpu.is_some() {
            return None;
        }
        builtin_mismatch(&self.manifest)
    }

    /// The f64 CPU reference of the raw output.
    ///
    /// # Panics
    /// If no reference is registered (check [`Kernel::has_reference`]).
    pub fn reference(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        self.cpu.unwrap_or_else(|| panic!("kernel {} has no CPU reference", self.name())).reference(p, width, height)
    }

    /// The shader's algorithm on the CPU in f32 where the reference differs
    /// from it (see [`CpuReference::shader_algorithm_f32`]).
    pub fn shader_algorithm_f32(&self, p: &ParamSet, width: u32, height: u32) -> Option<Image> {
        self.cpu.and_then(|c| c.shader_algorithm_f32(p, width, height))
    }

    /// The f32 build of the CPU reference (bench baseline).
    ///
    /// # Panics
    /// If no reference is registered.
    pub fn reference_f32(&self, p: &ParamSet, width: u32, height: u32) -> Image {
        self.cpu
            .unwrap_or_else(|| panic!("kernel {} has no CPU reference", self.name()))
            .reference_f32(p, width, height)
    }
}

/// Whether `m` declares the params of the built-in kernel of its name.
fn same_params_as_builtin(m: &manifest::Manifest) -> bool {
    builtin_mismatch(m).is_none()
}

/// The text of the built-in manifest named `name`, if there is one.
fn builtin_manifest(name: &str) -> Option<&'static str> {
    let file = format!("{name}.toml");
    vista_project::builtin::KERNELS.iter().find(|(rel, _)| *rel == file).map(|(_, text)| *text)
}

/// How manifest `m` differs from the built-in of its name in what the
/// built-in's CPU reference reads (params' names and types, `[[group]]`s),
/// or `None` when it does not (or no built-in has its name).
fn builtin_mismatch(m: &manifest::Manifest) -> Option<String> {
    let builtin = manifest::parse(&m.name, "<built-in>", builtin_manifest(&m.name)?).ok()?;
    fn sig(ps: &[ParamSpec]) -> Vec<(&str, ParamType)> {
        ps.iter().map(|p| (p.name.as_str(), p.ty.clone())).collect()
    }
    let (theirs, ours) = (sig(&builtin.params), sig(&m.params));
    let mut diffs = Vec::new();
    let missing: Vec<&str> = theirs.iter().filter(|p| !ours.contains(p)).map(|p| p.0).collect();
    let extra: Vec<&str> = ours.iter().filter(|p| !theirs.contains(p)).map(|p| p.0).collect();
    if !missing.is_empty() {
        diffs.push(format!("without the built-in's {}", missing.join(", ")));
    }
    if !extra.is_empty() {
        diffs.push(format!("with {} the built-in lacks (or types it otherwise)", extra.join(", ")));
    }
    if missing.is_empty() && extra.is_empty() && theirs != ours {
        diffs.push("its params in another order".into());
    }
    if builtin.groups != m.groups {
        diffs.push("other [[group]] tables".into());
    }
    (!diffs.is_empty()).then(|| diffs.join("; "))
}
