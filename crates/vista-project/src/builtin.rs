//! The built-in kernels' sources, embedded in the binary so that `list`,
//! `render`, `bench` and `sweep` of the built-ins work from anywhere, with
//! or without a project. The repository's own files are the same text (a
//! test keeps the two lists equal); inside the repository, or any project
//! that has a file of the same path, the file on disk wins.

macro_rules! builtins {
    (libs: $($lib:literal),* $(,)?; kernels: $($kernel:literal),* $(,)?) => {
        /// `shaders/` files: `(path relative to shaders/, text)`.
        pub const SHADERS: &[(&str, &str)] = &[
            $(($lib, include_str!(concat!("../../../shaders/", $lib))),)*
            $((concat!($kernel, ".wgsl"), include_str!(concat!("../../../shaders/", $kernel, ".wgsl"))),)*
        ];

        /// `kernels/` manifests: `(path relative to kernels/, text)`.
        pub const KERNELS: &[(&str, &str)] = &[
            $((concat!($kernel, ".toml"), include_str!(concat!("../../../kernels/", $kernel, ".toml"))),)*
        ];
    };
}

// A built-in kernel is one name here (its `kernels/<name>.toml` and
// `shaders/<name>.wgsl`) and one line of vista-kernels' `builtin_kernels!`
// (its Rust folder); a test there keeps the two lists equal.
builtins! {
    libs:
        "lib/hash.wgsl",
        "lib/noise.wgsl",
        "lib/fractal.wgsl",
        "lib/phase.wgsl",
        "lib/geometry.wgsl",
        "lib/terrain.wgsl",
        "lib/sky.wgsl",
        "lib/cloud_slab.wgsl",
        "lib/wgsl_test.wgsl";
    kernels: "fbm", "ridged", "atmosphere", "clouds", "heightfield", "cloudmap", "landscape",
}
