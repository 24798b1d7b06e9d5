//! The built-in kernels' sources, embedded in the binary so that `list`,
//! `render`, `bench` and `sweep` of the built-ins work from anywhere, with
//! or without a project. The repository's own files are the same text (a
//! test keeps the two lists equal); inside the repository, or any project
//! that has a file of the same path, the file on disk wins.

macro_rules! embed {
    ($dir:literal: $($rel:literal),* $(,)?) => {
        &[$(($rel, include_str!(concat!("../../../", $dir, "/", $rel)))),*]
    };
}

/// `shaders/` files: `(path relative to shaders/, text)`.
pub const SHADERS: &[(&str, &str)] = embed!("shaders":
    "lib/hash.wgsl",
    "lib/noise.wgsl",
    "lib/fractal.wgsl",
    "lib/phase.wgsl",
    "lib/geometry.wgsl",
    "lib/terrain.wgsl",
    "lib/sky.wgsl",
    "lib/cloud_slab.wgsl",
    "fbm.wgsl",
    "ridged.wgsl",
    "atmosphere.wgsl",
    "heightfield.wgsl",
    "clouds.wgsl",
    "cloudmap.wgsl",
    "landscape.wgsl",
);

/// `kernels/` manifests: `(path relative to kernels/, text)`.
pub const KERNELS: &[(&str, &str)] = embed!("kernels":
    "fbm.toml",
    "ridged.toml",
    "atmosphere.toml",
    "clouds.toml",
    "heightfield.toml",
    "cloudmap.toml",
    "landscape.toml",
);
