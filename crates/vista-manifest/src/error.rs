//! Everything that can be wrong with a kernel, as one error type.

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
