#![deny(missing_docs)]
//! vista's kernel registry and built-in kernels. A [`Registry`] parses a
//! project's manifests (`vista-manifest`, re-exported here) and attaches the
//! CPU reference registered under each built-in's name.
//!
//! Each built-in is one folder, `src/<name>/`: `mod.rs` its Rust side (the
//! [`CpuReference`] and what data cannot say) and `cpu.rs` its reference,
//! written from the math in SPEC, beside `kernels/<name>.toml` and
//! `shaders/<name>.wgsl`; it is registered by one line of
//! `builtin_kernels!` below. Every `cpu.rs`, with the shared math of
//! `src/cpu/`, is built twice: in f64 as the oracles (private `cpu64`,
//! whose items each kernel module re-exports: public once) and in f32 as
//! the throughput baseline (private `cpu32`, reached through
//! [`Kernel::reference_f32`] and [`Kernel::shader_algorithm_f32`]).
//!
//! Not for: GPU work (see `vista-gpu`), files or goldens (see `vista-golden`).
//! Kernels never touch the file system: manifests arrive as text.

/// The built-in kernels, one line each: the folder's module, its
/// [`CpuReference`] handle and its reference's source (a literal, as
/// `#[path]` needs). Passes the list to `$then`, which declares from it.
macro_rules! builtin_kernels {
    ($then:ident) => {
        $then! {
            atmosphere: AtmosphereKernel = "atmosphere/cpu.rs",
            cloudmap: CloudmapKernel = "cloudmap/cpu.rs",
            clouds: CloudsKernel = "clouds/cpu.rs",
            fbm: FbmKernel = "fbm/cpu.rs",
            heightfield: HeightfieldKernel = "heightfield/cpu.rs",
            landscape: LandscapeKernel = "landscape/cpu.rs",
            ridged: RidgedKernel = "ridged/cpu.rs",
        }
    };
}

/// Declares each built-in's module and registers its reference by name.
macro_rules! declare_kernels {
    ($($name:ident: $handle:ident = $cpu:literal),* $(,)?) => {
        $(pub mod $name;)*

        /// The CPU reference registered for a kernel name, if any.
        pub fn cpu_reference(name: &str) -> Option<&'static dyn CpuReference> {
            match name {
                $(stringify!($name) => Some(&$name::$handle),)*
                _ => None,
            }
        }

        /// The names of the built-in kernels that have a CPU reference.
        pub const WITH_REFERENCE: &[&str] = &[$(stringify!($name)),*];
    };
}

/// Declares the reference modules (each kernel's `cpu.rs`) for one float
/// type; see `cpu_references`.
macro_rules! reference_modules {
    ($($name:ident: $handle:ident = $cpu:literal),* $(,)?) => {
        $(#[path = $cpu] pub mod $name;)*
    };
}

/// Declares the CPU reference modules for one float type: the same source
/// compiled once per precision, so the f32 baseline cannot drift from the
/// f64 oracle. Literals take the type from context; code names the float
/// type `Real` and glam's 3-vector `Vec3`.
macro_rules! cpu_references {
    ($real:ident, $vec3:ty) => {
        /// The float type this build computes in.
        pub type Real = $real;
        /// glam's 3-vector of [`Real`].
        pub type Vec3 = $vec3;
        pub use std::$real::consts;
        #[path = "cpu/common.rs"]
        mod common;
        pub use common::*;
        #[path = "cpu/geometry.rs"]
        pub mod geometry;
        #[path = "cpu/noise.rs"]
        pub mod noise;
        #[path = "cpu/phase.rs"]
        pub mod phase;
        builtin_kernels!(reference_modules);
    };
}

/// A handle that derefs to the built-in kernel of its name, so the Rust
/// side of a built-in reads `FbmKernel.resolve(...)`, `&FbmKernel`.
macro_rules! builtin_handle {
    ($handle:ident, $name:literal) => {
        impl std::ops::Deref for $handle {
            type Target = $crate::Kernel;
            fn deref(&self) -> &$crate::Kernel {
                $crate::find($name).expect(concat!("built-in kernel ", $name))
            }
        }
    };
}
pub(crate) use builtin_handle;

// The f32 build is reached through `CpuReference`; most of its items
// (helpers the f64 build's callers use by name) go unused.
#[allow(dead_code)]
mod cpu32;
mod cpu64;

pub mod noise;
pub mod phase;
builtin_kernels!(declare_kernels);

use std::sync::{Arc, OnceLock};

pub use cpu64::geometry;
pub use cpu64::{pixel_uv, render_cpu};
pub use vista_manifest::*;

/// A project's kernels. A manifest that does not parse breaks only its own
/// kernel: the others (built-in or not) still run, and asking for the
/// broken one gives its error.
#[derive(Debug, Clone)]
pub struct Registry {
    kernels: Vec<Arc<Kernel>>,
    broken: Vec<(String, ParamError)>,
}

impl Registry {
    /// Parses every manifest (`<name>.toml` files; the name is the stem).
    pub fn from_files(files: &[vista_project::SourceFile]) -> Registry {
        let (mut kernels, mut broken) = (Vec::new(), Vec::new());
        for f in files {
            let Some(name) = f.rel.strip_suffix(".toml") else { continue };
            if name.contains('/') {
                continue;
            }
            match Kernel::from_manifest(name, &f.origin, &f.text) {
                Ok(k) => kernels.push(Arc::new(match cpu_reference(name) {
                    Some(cpu) => k.with_reference(cpu, &f.text),
                    None => k,
                })),
                Err(e) => broken.push((name.to_string(), e)),
            }
        }
        Registry { kernels, broken }
    }

    /// Kernels whose manifest does not parse, with the error.
    pub fn broken(&self) -> &[(String, ParamError)] {
        &self.broken
    }

    /// The project's kernels (its manifests layered over the built-ins).
    pub fn of_project(project: &vista_project::Project) -> Result<Registry, ParamError> {
        let files = project
            .kernel_files()
            .map_err(|e| ParamError::Manifest { file: "kernels/".into(), message: e.to_string() })?;
        Ok(Registry::from_files(&files))
    }

    /// The built-in kernels from the manifests embedded in the binary.
    pub fn builtin() -> &'static Registry {
        static BUILTIN: OnceLock<Registry> = OnceLock::new();
        BUILTIN.get_or_init(|| {
            let r = Registry::of_project(&vista_project::Project::builtin_only())
                .unwrap_or_else(|e| panic!("the built-in manifests cannot be read: {e}"));
            if let Some((name, e)) = r.broken.first() {
                panic!("built-in manifest {name} is invalid: {e}");
            }
            r
        })
    }

    /// Every kernel that parsed, in manifest file order.
    pub fn kernels(&self) -> &[Arc<Kernel>] {
        &self.kernels
    }

    /// Looks a kernel up by name.
    pub fn find(&self, name: &str) -> Result<&Arc<Kernel>, ParamError> {
        if let Some((_, e)) = self.broken.iter().find(|(n, _)| n == name) {
            return Err(e.clone());
        }
        self.kernels.iter().find(|k| k.name() == name).ok_or_else(|| ParamError::UnknownKernel {
            name: name.to_string(),
            valid: self.kernels.iter().map(|k| k.name()).collect::<Vec<_>>().join(", "),
        })
    }
}

/// The built-in kernels, in the order `vista list` shows them.
pub fn registry() -> &'static [Arc<Kernel>] {
    Registry::builtin().kernels()
}

/// Looks a built-in kernel up by name.
pub fn find(name: &str) -> Result<&'static Arc<Kernel>, ParamError> {
    Registry::builtin().find(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A built-in is registered by one line here and its name in
    /// vista-project's embedded list: the two name the same kernels, and
    /// each parsed built-in carries its reference.
    #[test]
    fn every_embedded_builtin_has_its_registered_reference() {
        let embedded: Vec<&str> =
            vista_project::builtin::KERNELS.iter().map(|(f, _)| f.strip_suffix(".toml").expect("a manifest")).collect();
        let mut sorted = embedded.clone();
        sorted.sort();
        assert_eq!(sorted, WITH_REFERENCE, "vista-project's embedded kernels vs builtin_kernels!");
        for name in embedded {
            assert!(find(name).expect("parses").has_reference(), "built-in {name} lost its reference");
        }
    }

    /// A registry owns its kernels: dropping it frees every kernel and the
    /// strings its manifest held, so `vista watch`, which re-reads a project's
    /// manifests on every change, does not grow with each read.
    #[test]
    fn a_dropped_registry_frees_its_kernels() {
        let file = |rel: &str, text: &str| vista_project::SourceFile {
            rel: rel.into(),
            text: text.into(),
            origin: format!("kernels/{rel}"),
        };
        let manifest =
            "summary = \"one param\"\n[[param]]\nname = \"gain\"\ntype = \"f32\"\nrange = [0, 1]\ndefault = 0.5\n";
        let registry = Registry::from_files(&[file("gain.toml", manifest)]);
        let kernel = registry.find("gain").expect("parsed");
        assert_eq!((kernel.params()[0].name.as_str(), kernel.origin()), ("gain", "kernels/gain.toml"));
        let weak = Arc::downgrade(kernel);
        let held = registry.find("gain").cloned().expect("parsed");
        drop(registry);
        assert!(weak.upgrade().is_some(), "a case's Arc keeps its kernel alive");
        drop(held);
        assert!(weak.upgrade().is_none(), "the kernel outlived every owner");
    }
}
