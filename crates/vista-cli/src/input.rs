//! What every command reads the same way: `--set NAME=VALUE` pairs, the
//! project's kernels, and a bad value as the one error line (exit 2).

use vista_golden::GoldenError;
use vista_project::Project;

/// Splits `NAME=VALUE` pairs.
pub fn parse_sets(sets: &[String]) -> Result<Vec<(String, String)>, GoldenError> {
    sets.iter()
        .map(|s| {
            s.split_once('=')
                .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                .ok_or_else(|| GoldenError::BadInput(format!("--set '{s}' is not NAME=VALUE")))
        })
        .collect()
}

/// A bad value, as the error every command reports (exit 2).
pub fn bad(e: impl std::fmt::Display) -> GoldenError {
    GoldenError::BadInput(e.to_string())
}

/// The project's kernels (its manifests over the built-ins).
pub fn registry(project: &Project) -> Result<vista_kernels::Registry, GoldenError> {
    vista_kernels::Registry::of_project(project).map_err(bad)
}
