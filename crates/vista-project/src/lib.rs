//! vista's project model: where a project's files are, found at run time.
//!
//! A project is a directory with a `vista.toml` at its root. The root is
//! `--root DIR`, else `VISTA_ROOT`, else the nearest `vista.toml` walking up
//! from the current directory ([`Project::discover`]). The caller (the
//! binary, or a test) reads the flag, the environment and the current
//! directory once and passes them in: nothing here reads the environment,
//! and nothing is located through build-time paths, so a copied binary
//! checks whichever project it is pointed at.
//!
//! The project's `shaders/` and `kernels/` are layered over the built-ins
//! embedded in the binary ([`builtin`]): a project file of the same relative
//! path wins. Without a root only the built-ins exist, which is enough for
//! `list`, `render`, `compare`, `bench` and `sweep`; `check` and `bless`
//! need a root ([`Project::require_root`]).
//!
//! Every file a command reads from a project goes through [`guard`]: a
//! regular file inside the project after symlinks, under a size cap.
//!
//! Not for: parsing kernel manifests or cases (that is `vista-kernels` and
//! `vista-golden`), or writing anything.

#![deny(missing_docs)]

use std::collections::BTreeMap;
use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};

pub mod builtin;
pub mod guard;

/// The file that marks a project root.
pub const PROJECT_FILE: &str = "vista.toml";

/// Everything that can be wrong with finding or reading a project. Every
/// message names the path and what was expected (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProjectError {
    /// `--root` or `VISTA_ROOT` names a directory without `vista.toml`.
    #[error("{from} {dir}: no {PROJECT_FILE} there; expected a vista project directory (one holding {PROJECT_FILE})")]
    NotAProject {
        /// `--root` or `VISTA_ROOT`.
        from: &'static str,
        /// The directory given.
        dir: String,
    },
    /// A command that needs a root found none.
    #[error(
        "{command} needs a vista project: no {PROJECT_FILE} in {cwd} or any directory above it; \
         pass --root DIR or set VISTA_ROOT to a directory holding {PROJECT_FILE}"
    )]
    NoRoot {
        /// The command that needed it.
        command: String,
        /// Where the search started.
        cwd: String,
    },
    /// `vista.toml` is malformed or has unknown keys.
    #[error("{path}: {message}")]
    Config {
        /// The file.
        path: String,
        /// What is wrong, with line and column.
        message: String,
    },
    /// A project file could not be read.
    #[error("{path}: {message}")]
    Io {
        /// The file or directory.
        path: String,
        /// The OS error.
        message: String,
    },
}

/// The contents of `vista.toml`. Every key is optional; unknown keys are
/// refused so a typo does not pass silently.
#[derive(Debug, Clone, Default, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// A name for reports.
    #[serde(default)]
    pub name: Option<String>,
}

/// How the root was found (for messages and reports).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Found {
    /// `--root DIR`.
    Flag,
    /// `VISTA_ROOT`.
    Env,
    /// The nearest `vista.toml` above the current directory.
    WalkUp,
}

/// A project: its root (if any) and how it was found. Cheap to clone.
#[derive(Debug, Clone)]
pub struct Project {
    root: Option<(PathBuf, Found)>,
    /// Where a walk-up search started (named in "no root" errors).
    cwd: PathBuf,
    config: Config,
}

/// One source file: its path relative to its tree (`lib/noise.wgsl`,
/// `fbm.toml`), its text, and where it came from (a file path, or
/// `<built-in>/...`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceFile {
    /// Path relative to `shaders/` or `kernels/`, with `/` separators.
    pub rel: String,
    /// File contents.
    pub text: String,
    /// A real path, or `<built-in>/shaders/...` for embedded files.
    pub origin: String,
}

/// Whether `dir` holds a `vista.toml` entry of any kind but a folder: a
/// FIFO, device or link out of the project there still marks the project,
/// and reading it then refuses it by name (the guard), instead of the walk
/// going on up as if there were none.
fn marks_project(dir: &Path) -> bool {
    std::fs::symlink_metadata(dir.join(PROJECT_FILE)).is_ok_and(|m| !m.is_dir())
}

impl Project {
    /// Finds the root: `flag` (`--root`), else `env` (`VISTA_ROOT`), else
    /// the nearest `vista.toml` at or above `cwd`. A flag or variable that
    /// names a directory without `vista.toml` is an error; finding nothing
    /// by walking up is not (the project then has only the built-ins).
    pub fn discover(flag: Option<&Path>, env: Option<OsString>, cwd: &Path) -> Result<Project, ProjectError> {
        let cwd = absolute(cwd);
        let named = |from: &'static str, dir: &Path, found: Found| -> Result<Project, ProjectError> {
            let dir = absolute(&cwd.join(dir));
            if !marks_project(&dir) {
                return Err(ProjectError::NotAProject { from, dir: dir.display().to_string() });
            }
            Project::with_root(dir, found, cwd.clone())
        };
        if let Some(dir) = flag {
            return named("--root", dir, Found::Flag);
        }
        if let Some(dir) = env.filter(|d| !d.is_empty()) {
            return named("VISTA_ROOT", Path::new(&dir), Found::Env);
        }
        for dir in cwd.ancestors() {
            if marks_project(dir) {
                return Project::with_root(dir.to_path_buf(), Found::WalkUp, cwd.clone());
            }
        }
        Ok(Project { root: None, cwd, config: Config::default() })
    }

    /// The project rooted at `dir`, which must hold `vista.toml` (tests use
    /// this to point at a checkout explicitly).
    pub fn at(dir: &Path) -> Result<Project, ProjectError> {
        Project::discover(Some(dir), None, dir)
    }

    /// Only the built-ins: no root.
    pub fn builtin_only() -> Project {
        Project { root: None, cwd: PathBuf::from("."), config: Config::default() }
    }

    fn with_root(root: PathBuf, found: Found, cwd: PathBuf) -> Result<Project, ProjectError> {
        let path = root.join(PROJECT_FILE);
        let text = read(&root, &path)?;
        let config: Config = toml::from_str(&text).map_err(|e| ProjectError::Config {
            path: path.display().to_string(),
            message: one_line_toml_error(&text, &e),
        })?;
        Ok(Project { root: Some((root, found)), cwd, config })
    }

    /// The root directory, if one was found.
    pub fn root(&self) -> Option<&Path> {
        self.root.as_ref().map(|(r, _)| r.as_path())
    }

    /// How the root was found.
    pub fn found(&self) -> Option<Found> {
        self.root.as_ref().map(|(_, f)| *f)
    }

    /// The parsed `vista.toml` (default without a root).
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The root, or an error for `command` saying what was looked for from where.
    pub fn require_root(&self, command: &str) -> Result<&Path, ProjectError> {
        self.root()
            .ok_or_else(|| ProjectError::NoRoot { command: command.to_string(), cwd: self.cwd.display().to_string() })
    }

    /// `<root>/golden`, if there is a root.
    pub fn golden_dir(&self) -> Option<PathBuf> {
        self.root().map(|r| r.join("golden"))
    }

    /// `<root>/target/vista-report`, if there is a root.
    pub fn report_dir(&self) -> Option<PathBuf> {
        self.root().map(|r| r.join("target").join("vista-report"))
    }

    /// Every `.wgsl` and `.wesl` file: the built-ins, overlaid by the project's
    /// `shaders/` tree (same relative path wins), sorted by path.
    pub fn shader_files(&self) -> Result<Vec<SourceFile>, ProjectError> {
        self.layered("shaders", builtin::SHADERS, &["wgsl", "wesl"])
    }

    /// The text and path of a file under the root (`rel` relative to it,
    /// `/` separators, no `..`), for the files a kernel's `[source]`
    /// reaches; `None` without a root or such a file.
    pub fn read_text(&self, rel: &str) -> Option<(String, String)> {
        if rel.split('/').any(|c| c == "..") {
            return None;
        }
        let root = self.root()?;
        let path = root.join(rel);
        let text = guard::read_text(root, &path).ok()?;
        Some((text, path.display().to_string()))
    }

    /// Every file under `rel` (a folder or a file relative to the root, no
    /// `..`) with one of the extensions `ext`, `rel` paths relative to the
    /// root; empty without a root or such a path.
    pub fn files_under(&self, rel: &str, ext: &[&str]) -> Result<Vec<SourceFile>, ProjectError> {
        let Some(root) = self.root() else { return Ok(Vec::new()) };
        if rel.split('/').any(|c| c == "..") {
            return Ok(Vec::new());
        }
        let path = root.join(rel);
        let paths = match path.is_file() {
            true => vec![path],
            false if path.is_dir() => files_with_ext(root, &path, ext)?,
            false => Vec::new(),
        };
        paths
            .into_iter()
            .map(|p| {
                let rel = p.strip_prefix(root).unwrap_or(&p).to_string_lossy().replace('\\', "/");
                Ok(SourceFile { rel, text: read(root, &p)?, origin: p.display().to_string() })
            })
            .collect()
    }

    /// Every kernel manifest (`kernels/*.toml`): the built-ins overlaid by
    /// the project's, sorted by path.
    pub fn kernel_files(&self) -> Result<Vec<SourceFile>, ProjectError> {
        self.layered("kernels", builtin::KERNELS, &["toml"])
    }

    fn layered(&self, sub: &str, embedded: &[(&str, &str)], ext: &[&str]) -> Result<Vec<SourceFile>, ProjectError> {
        let mut files: BTreeMap<String, SourceFile> = embedded
            .iter()
            .map(|(rel, text)| {
                let file = SourceFile {
                    rel: rel.to_string(),
                    text: text.to_string(),
                    origin: format!("<built-in>/{sub}/{rel}"),
                };
                (rel.to_string(), file)
            })
            .collect();
        if let Some(root) = self.root() {
            let dir = root.join(sub);
            if dir.is_dir() {
                for path in files_with_ext(root, &dir, ext)? {
                    let rel = path.strip_prefix(&dir).unwrap_or(&path).to_string_lossy().replace('\\', "/");
                    let text = read(root, &path)?;
                    files.insert(rel.clone(), SourceFile { rel, text, origin: path.display().to_string() });
                }
            }
        }
        Ok(files.into_values().collect())
    }
}

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

fn read(root: &Path, path: &Path) -> Result<String, ProjectError> {
    guard::read_text(root, path).map_err(|e| ProjectError::Io { path: e.path, message: e.message })
}

/// Files with one of the extensions under `dir`, sorted. A symlinked
/// folder is followed only when it resolves inside `root` and is not one
/// of the folders it sits in (a loop); others are skipped.
fn files_with_ext(root: &Path, dir: &Path, ext: &[&str]) -> Result<Vec<PathBuf>, ProjectError> {
    let real_root = root.canonicalize().unwrap_or_else(|_| root.to_path_buf());
    let mut out = Vec::new();
    let mut stack = Vec::new();
    walk(&real_root, dir, ext, &mut stack, &mut out)?;
    out.sort();
    Ok(out)
}

fn walk(
    real_root: &Path,
    dir: &Path,
    ext: &[&str],
    stack: &mut Vec<PathBuf>,
    out: &mut Vec<PathBuf>,
) -> Result<(), ProjectError> {
    let real = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    if !real.starts_with(real_root) || stack.contains(&real) {
        return Ok(());
    }
    stack.push(real);
    let entries = fs::read_dir(dir)
        .map_err(|e| ProjectError::Io { path: dir.display().to_string(), message: format!("cannot list: {e}") })?;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            walk(real_root, &path, ext, stack, out)?;
        } else if path.extension().is_some_and(|e| ext.iter().any(|x| e == *x)) {
            out.push(path);
        }
    }
    stack.pop();
    Ok(())
}

/// A yes/no setting's value (`VISTA_ALLOW_NO_GPU`, `VISTA_VALIDATION`, ...):
/// unset, empty, `0` or `false` is no, `1` or `true` yes (either case);
/// anything else is an error naming the setting and what is allowed. The
/// one parser for every edge that reads such a setting (the binary's
/// configuration, the test harnesses).
pub fn truthy(name: &str, value: Option<&str>) -> Result<bool, String> {
    match value {
        None | Some("") | Some("0") => Ok(false),
        Some(v) if v.eq_ignore_ascii_case("false") => Ok(false),
        Some(v) if v == "1" || v.eq_ignore_ascii_case("true") => Ok(true),
        Some(v) => Err(format!("{name}={v} is not valid; expected 1|0|true|false")),
    }
}

/// A TOML parse error as one line: message, line and column.
pub fn one_line_toml_error(text: &str, e: &toml::de::Error) -> String {
    let msg = e.message().trim().replace('\n', " ");
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let col = before.rfind('\n').map_or(before.len(), |i| before.len() - i - 1) + 1;
            format!("line {line}, column {col}: {msg}")
        }
        None => msg,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn project_dir(toml: &str) -> tempfile::TempDir {
        let d = tempfile::tempdir().unwrap();
        fs::write(d.path().join(PROJECT_FILE), toml).unwrap();
        d
    }

    #[test]
    fn walk_up_finds_the_nearest_root() {
        let d = project_dir("");
        let deep = d.path().join("a/b");
        fs::create_dir_all(&deep).unwrap();
        let p = Project::discover(None, None, &deep).unwrap();
        assert_eq!(p.root(), Some(absolute(d.path()).as_path()));
        assert_eq!(p.found(), Some(Found::WalkUp));
    }

    #[test]
    fn flag_beats_env_beats_walk_up() {
        let (a, b, c) = (project_dir(""), project_dir(""), project_dir(""));
        let p = Project::discover(Some(a.path()), Some(b.path().into()), c.path()).unwrap();
        assert_eq!(p.root(), Some(a.path()));
        let p = Project::discover(None, Some(b.path().into()), c.path()).unwrap();
        assert_eq!((p.root(), p.found()), (Some(b.path()), Some(Found::Env)));
    }

    #[test]
    fn a_named_directory_without_vista_toml_is_refused() {
        let d = tempfile::tempdir().unwrap();
        let e = Project::discover(Some(d.path()), None, d.path()).unwrap_err();
        assert!(e.to_string().starts_with("--root "), "{e}");
        assert!(e.to_string().contains("no vista.toml there"), "{e}");
        let e = Project::discover(None, Some(d.path().into()), d.path()).unwrap_err();
        assert!(e.to_string().starts_with("VISTA_ROOT "), "{e}");
    }

    #[test]
    fn no_root_keeps_the_builtins_and_says_where_it_looked() {
        let d = tempfile::tempdir().unwrap();
        let p = Project::discover(None, None, d.path()).unwrap();
        assert!(p.root().is_none());
        let e = p.require_root("vista check").unwrap_err().to_string();
        assert!(e.contains("vista check needs a vista project"), "{e}");
        assert!(e.contains(&d.path().display().to_string()), "{e}");
        assert!(p.shader_files().unwrap().iter().any(|f| f.rel == "lib/noise.wgsl"));
    }

    #[test]
    fn project_files_win_over_builtins_of_the_same_name() {
        let d = project_dir("name = \"mine\"\n");
        fs::create_dir_all(d.path().join("shaders/lib")).unwrap();
        fs::write(d.path().join("shaders/fbm.wgsl"), "// mine").unwrap();
        fs::write(d.path().join("shaders/lib/extra.wgsl"), "// extra").unwrap();
        let p = Project::at(d.path()).unwrap();
        assert_eq!(p.config().name.as_deref(), Some("mine"));
        let files = p.shader_files().unwrap();
        let fbm = files.iter().find(|f| f.rel == "fbm.wgsl").unwrap();
        assert_eq!(fbm.text, "// mine");
        assert!(fbm.origin.ends_with("shaders/fbm.wgsl") && !fbm.origin.starts_with("<built-in>"));
        assert!(files.iter().any(|f| f.rel == "lib/extra.wgsl"));
        let noise = files.iter().find(|f| f.rel == "lib/noise.wgsl").unwrap();
        assert!(noise.origin.starts_with("<built-in>"));
    }

    #[test]
    fn unknown_config_keys_are_refused_with_line_and_column() {
        let d = project_dir("name = \"x\"\nkernals = 3\n");
        let e = Project::at(d.path()).unwrap_err().to_string();
        assert!(e.contains("vista.toml: line 2, column 1"), "{e}");
        assert!(e.contains("kernals"), "{e}");
    }
}
