#![deny(missing_docs)]
//! What a project says about its kernels, read against what naga reads
//! from their WGSL: a kernel's manifest (`kernels/<name>.toml`,
//! [`manifest`]) with its params ([`params`]), integer expressions
//! ([`expr`]) and pass graph ([`graph`], [`vertex`]); each entry point's
//! globals from naga's reflection ([`bindings`], [`element`]); the uniform
//! block packed from that reflection ([`layout`]); and [`Kernel`], a parsed
//! manifest with the CPU reference a registry attached (see
//! `vista-kernels`, which owns the built-ins and their references).
//!
//! Not for: GPU work (see `vista-gpu`), files or goldens (see
//! `vista-golden`). Manifests arrive as text; nothing here touches the file
//! system.

pub mod bindings;
pub mod element;
pub mod expr;
pub mod graph;
pub mod layout;
pub mod manifest;
pub mod params;
pub mod values;
pub mod vertex;

pub use layout::UniformLayout;
pub use manifest::HashPlane;
pub use params::{Kind, ParamSet, ParamSpec, ParamType, Preset, Value};
use vista_image::Image;

/// Everything that can be wrong with a kernel, its manifest or layout, a
/// preset, a parameter or a size request. Messages name the bad value and
/// what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// No kernel has the name asked for.
    #[error("unknown kernel '{name}'; valid kernels: {valid}")]
    UnknownKernel {
        /// The name asked for.
        name: String,
        /// The known kernel names, comma-separated.
        valid: String,
    },
    /// The kernel has no preset of the name asked for.
    #[error("kernel {kernel} has no preset '{name}'; valid presets: {valid}")]
    UnknownPreset {
        /// The kernel's name.
        kernel: String,
        /// The preset name asked for.
        name: String,
        /// The kernel's preset names, comma-separated.
        valid: String,
    },
    /// The kernel has no parameter of the name given.
    #[error("kernel {kernel} has no parameter '{name}'; valid parameters: {valid}")]
    UnknownParam {
        /// The kernel's name.
        kernel: String,
        /// The parameter name given.
        name: String,
        /// The kernel's parameter names, comma-separated.
        valid: String,
    },
    /// A value that parses but lies outside its allowed range (also an
    /// image width or height outside [1, [`MAX_DIMENSION`]]).
    #[error("{param}={value} is out of range; allowed: {range}")]
    OutOfRange {
        /// The parameter (or `width` / `height`).
        param: String,
        /// The value as given.
        value: String,
        /// The allowed range, as users read it (see [`Kind::range_text`]).
        range: String,
    },
    /// A value that does not parse as what its parameter takes.
    #[error("{param}={value} is not valid; expected {expected}")]
    BadValue {
        /// The parameter (or `size`).
        param: String,
        /// The text as given.
        value: String,
        /// What would have been accepted.
        expected: String,
    },
    /// A manifest that is invalid or cannot be read.
    #[error("{file}: {message}")]
    Manifest {
        /// Where the manifest came from: its path or `<built-in>/kernels/...`
        /// (`kernels/` when the folder itself cannot be read).
        file: String,
        /// What is wrong with it.
        message: String,
    },
    /// A shader that does not fit its manifest: its reflected entry point,
    /// bindings, uniform blocks or overrides.
    #[error("kernel {kernel}: {message}")]
    Layout {
        /// The kernel's name.
        kernel: String,
        /// What does not match.
        message: String,
    },
    /// A kernel's own check of its params failed (e.g. a cloud top not
    /// above its base); the message names the values.
    #[error("{0}")]
    Invalid(String),
}

/// How the raw GPU output is turned into display values for PNG goldens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// The kernel writes display values in [0, 1] directly.
    Display,
    /// The kernel writes linear radiance; display = tonemap(exposure).
    Hdr,
    /// Display = (raw - min) / (max - min) over the image's finite RGB
    /// values (`view = "normalize"`; the default for integer formats).
    Normalize,
}

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

/// Raw output to display values (SPEC 3) for one param set: the HDR tone
/// map with its exposure, and whether alpha is forced to 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayMap {
    exposure: Option<f32>,
    opaque: bool,
    normalize: bool,
    /// Channels the output's format has (1 for r32*, 2 for rg32*, else 3
    /// counted): a normalised view spans only those, a single channel shown
    /// grey.
    channels: u8,
}

impl DisplayMap {
    /// Display values are the raw values.
    pub fn identity() -> DisplayMap {
        DisplayMap { exposure: None, opaque: false, normalize: false, channels: 3 }
    }

    /// The display values of `raw`, or None where they are `raw` itself (a
    /// display kernel that keeps its alpha), so callers need not copy it.
    pub fn apply(&self, raw: &Image) -> Option<Image> {
        let mut out = match self.exposure {
            Some(e) => vista_image::tonemap(raw, e),
            None if self.normalize => normalized(raw, self.channels),
            None if self.opaque => raw.clone(),
            None => return None,
        };
        if self.opaque {
            for px in &mut out.data {
                px[3] = 1.0;
            }
        }
        Some(out)
    }
}

/// `raw` mapped to [0, 1] by the min and max of the finite values of its
/// first `channels` of R, G, B (a constant image maps to 0), alpha 1;
/// non-finite values map to 0. A single channel is shown grey.
pub fn normalized(raw: &Image, channels: u8) -> Image {
    let n = channels.clamp(1, 3) as usize;
    let finite = raw.data.iter().flat_map(|p| p[..n].iter().copied()).filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let span = if hi > lo { (hi as f64 - lo as f64) as f32 } else { f32::INFINITY };
    let map = |v: f32| if v.is_finite() { ((v - lo) / span).clamp(0.0, 1.0) } else { 0.0 };
    let data = raw
        .data
        .iter()
        .map(|p| match n {
            1 => [map(p[0]), map(p[0]), map(p[0]), 1.0],
            2 => [map(p[0]), map(p[1]), 0.0, 1.0],
            _ => [map(p[0]), map(p[1]), map(p[2]), 1.0],
        })
        .collect();
    Image::from_raw(raw.width, raw.height, data).expect("same size")
}

/// Whether a storage format holds integers (compared exactly, shown
/// normalised by default).
pub fn is_integer_format(format: &str) -> bool {
    vista_texel::Format::parse(format).is_ok_and(|f| f.is_integer())
}

/// One kernel: its manifest, where it came from, and its CPU reference if
/// one is registered under its name. A registry owns its kernels and
/// shares them by `Arc`.
#[derive(Clone)]
pub struct Kernel {
    manifest: manifest::Manifest,
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

    /// Every distinct assembly the kernel's passes use, by
    /// [`vista_source::SourceSpec::id`] (none without `[source]`).
    pub fn source_specs(&self) -> Vec<(String, vista_source::SourceSpec)> {
        let n = self.graph().passes.len();
        let mut out: Vec<(String, vista_source::SourceSpec)> = Vec::new();
        for spec in (0..n).map(|i| self.source_for(i)).filter(|s| !s.is_empty()) {
            let id = spec.id();
            if !out.iter().any(|(known, _)| *known == id) {
                out.push((id, spec));
            }
        }
        out
    }

    /// What each pass composes, without defs: its file, or `file|id` where
    /// a `[source]` assembles it ([`Kernel::source_specs`]). The shader
    /// hash and per-file hashes are taken over these.
    pub fn shader_units(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for (i, pass) in self.graph().passes.iter().enumerate() {
            let file = pass.shader.as_deref().unwrap_or(self.shader());
            let spec = self.source_for(i);
            for file in std::iter::once(file).chain(pass.vertex_file()) {
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
        pass.vertex_file().map(|file| self.with_defs(file, &pass.defs, &self.source_for(i), p))
    }

    /// Reflects every pass of the graph (`modules[i]`: pass i's composed
    /// file name and module), resolves what feeds each binding, and checks
    /// each pass's uniform blocks against the params: a leaf with no param,
    /// or a param that feeds nothing in any pass, is refused.
    pub fn graph_layouts(
        &self,
        modules: &[(&str, &naga::Module)],
    ) -> Result<(graph::Resolved, Vec<UniformLayout>), ParamError> {
        self.graph_layouts_with(modules, &[])
    }

    /// [`Kernel::graph_layouts`], with the composed file and module of each
    /// pass's vertex entry that lives in another file (`vertex[i]`).
    pub fn graph_layouts_with(
        &self,
        modules: &[(&str, &naga::Module)],
        vertex: &[Option<(&str, &naga::Module)>],
    ) -> Result<(graph::Resolved, Vec<UniformLayout>), ParamError> {
        let g = self.graph();
        let mut reflected = Vec::new();
        for (i, ((shader, module), pass)) in modules.iter().zip(&g.passes).enumerate() {
            let stage = match pass.raster {
                Some(_) => naga::ShaderStage::Fragment,
                None => naga::ShaderStage::Compute,
            };
            let mut b = bindings::reflect_all(self.name(), shader, &pass.entry, stage, module)?;
            let vs = pass.raster.as_ref().and_then(|r| r.vertex.entry());
            match (vs, vertex.get(i).copied().flatten()) {
                (Some(vs), None) => {
                    let v = bindings::reflect_all(self.name(), shader, vs, naga::ShaderStage::Vertex, module)?;
                    b = bindings::merge_stages(self.name(), b, v)?;
                }
                (Some(vs), Some((file, vmodule))) => {
                    let v = bindings::reflect_all(self.name(), file, vs, naga::ShaderStage::Vertex, vmodule)?;
                    b = bindings::match_vertex_file(self.name(), b, module, v, vmodule, file)?;
                }
                (None, _) => {}
            }
            reflected.push(b);
        }
        let passes: Vec<(&str, &[bindings::Binding], &naga::Module)> =
            modules.iter().zip(&reflected).map(|((s, m), b)| (*s, b.as_slice(), *m)).collect();
        let vertex_modules: Vec<Option<&naga::Module>> = vertex.iter().map(|v| v.map(|(_, m)| m)).collect();
        let resolved = graph::resolve(self.name(), g, &passes, &vertex_modules)?;
        let mut layouts = Vec::new();
        for (((shader, module), bindings), slots) in modules.iter().zip(reflected).zip(&resolved.slots) {
            // Params feed the uniforms and the table that no resource feeds.
            let by_params = |b: &bindings::Binding| {
                slots.iter().any(|s| {
                    (s.group, s.binding) == (b.group, b.binding)
                        && matches!(s.feed, graph::SlotFeed::Uniform(_) | graph::SlotFeed::Table)
                })
            };
            // The pass's uniform layout is its shader's: a vertex file's own
            // uniform must come from a buffer resource.
            if let Some(b) = bindings.iter().find(|b| b.in_vertex_file && by_params(b)) {
                return Err(ParamError::Layout {
                    kernel: self.name().to_string(),
                    message: format!(
                        "{shader}: the vertex entry's file binds {} (@group({}) @binding({})), which params would \
                         fill, but the fragment entry does not; declare it in the pass's shader too, or bind it to \
                         a buffer resource in the pass's bind",
                        b.name, b.group, b.binding
                    ),
                });
            }
            let fed: Vec<bindings::Binding> = bindings.iter().filter(|b| by_params(b)).cloned().collect();
            layouts.push((*shader, layout::blocks_of(self.name(), shader, module, fed)?));
        }
        // As for one pass: a group that names no struct field first.
        layout::check_groups(self, &layouts.iter().map(|(_, l)| l).collect::<Vec<_>>())?;
        for (_, l) in &mut layouts {
            layout::name_leaves(self, l);
            layout::check_fields(self, l)?;
        }
        let layouts: Vec<UniformLayout> = layouts.into_iter().map(|(_, l)| l).collect();
        layout::check_params(self, &layouts.iter().collect::<Vec<_>>())?;
        Ok((resolved, layouts))
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

    /// Each uniform block's bytes for `p` at `width` x `height`, in
    /// [`UniformLayout::blocks`] order.
    pub fn uniforms(&self, layout: &UniformLayout, p: &ParamSet, width: u32, height: u32) -> Vec<Vec<u8>> {
        layout::pack(self, layout, p, width, height)
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

/// Largest width or height any request may ask for. Devices limit 2D storage
/// textures to 8192 by default, and the check happens before GPU work.
pub const MAX_DIMENSION: u32 = 8192;

/// Validates an image size before any GPU work.
pub fn check_size(width: u32, height: u32) -> Result<(), ParamError> {
    for (what, v) in [("width", width), ("height", height)] {
        if v == 0 || v > MAX_DIMENSION {
            return Err(ParamError::OutOfRange {
                param: what.to_string(),
                value: v.to_string(),
                range: format!("[1, {MAX_DIMENSION}]"),
            });
        }
    }
    Ok(())
}

/// Parses `WxH` (e.g. `256x256`).
pub fn parse_size(text: &str) -> Result<(u32, u32), ParamError> {
    let bad = || ParamError::BadValue {
        param: "size".into(),
        value: text.into(),
        expected: format!("WIDTHxHEIGHT with each in [1, {MAX_DIMENSION}], e.g. 256x256"),
    };
    let (w, h) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    check_size(w, h)?;
    Ok((w, h))
}
