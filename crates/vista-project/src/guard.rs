//! Reading a project's files as untrusted input: every file vista reads
//! is a regular file inside the project after resolving symlinks, and no
//! larger than a cap, checked before a byte is read. A symlink out of the
//! project (`shaders/inc/pw -> /etc/passwd`), a device (`/dev/zero`), a
//! FIFO (which would block forever) or a file past the cap is refused with
//! one line naming the path, what it resolves to, and what is allowed.

use std::io::Read;
use std::path::{Path, PathBuf};

/// The largest text file vista reads (shaders, manifests, cases, TOML):
/// 16 MiB. The largest shader the project knows is under 100 KiB.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// The largest data file vista reads (inputs, goldens): 1 GiB, a 16384^2
/// rgba32float image's fourth. A larger input is refused, not streamed:
/// the machine vista runs on in CI has 24 GiB for every process.
pub const MAX_DATA_BYTES: u64 = 1 << 30;

/// Why a file was not read: one line, naming the path.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct GuardError {
    /// The path as given.
    pub path: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

fn refuse(path: &Path, message: String) -> GuardError {
    GuardError { path: path.display().to_string(), message }
}

/// `path` checked as a file vista may read under `root`: where it resolves
/// to, after every symlink, which must be a regular file inside the
/// resolved `root`, at most `max` bytes long.
pub fn check_file(root: &Path, path: &Path, max: u64) -> Result<PathBuf, GuardError> {
    let real_root = root.canonicalize().map_err(|e| refuse(root, format!("cannot resolve the project root: {e}")))?;
    let real = path.canonicalize().map_err(|e| refuse(path, format!("cannot read: {e}")))?;
    if !real.starts_with(&real_root) {
        return Err(refuse(
            path,
            format!(
                "resolves to {}, outside the project {}; vista reads only files inside the project",
                real.display(),
                real_root.display()
            ),
        ));
    }
    let meta = std::fs::metadata(&real).map_err(|e| refuse(path, format!("cannot read: {e}")))?;
    let via = if real != path { format!(" (resolves to {})", real.display()) } else { String::new() };
    regular(path, &meta, &via, max)?;
    Ok(real)
}

/// A regular file of at most `max` bytes (`via`: where a symlink led).
fn regular(path: &Path, meta: &std::fs::Metadata, via: &str, max: u64) -> Result<(), GuardError> {
    if !meta.is_file() {
        return Err(refuse(path, format!("is {}{via}; expected a regular file", kind_of(meta))));
    }
    if meta.len() > max {
        return Err(refuse(path, format!("{} bytes is larger than vista reads ({max} bytes at most)", meta.len())));
    }
    Ok(())
}

/// The bytes of `real` (checked), named `path` in errors: reading stops at
/// `max` bytes whatever the file grew to after the check.
fn read_capped(path: &Path, real: &Path, max: u64) -> Result<Vec<u8>, GuardError> {
    let file = std::fs::File::open(real).map_err(|e| refuse(path, format!("cannot read: {e}")))?;
    let mut bytes = Vec::new();
    file.take(max + 1).read_to_end(&mut bytes).map_err(|e| refuse(path, format!("cannot read: {e}")))?;
    if bytes.len() as u64 > max {
        return Err(refuse(path, format!("grew past {max} bytes while read; vista reads at most that")));
    }
    Ok(bytes)
}

fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if meta.is_dir() { "a directory" } else { "not a regular file" }
}

/// The bytes of `path`, checked by [`check_file`].
pub fn read_bytes(root: &Path, path: &Path, max: u64) -> Result<Vec<u8>, GuardError> {
    let real = check_file(root, path, max)?;
    read_capped(path, &real, max)
}

/// The bytes of `path` where no project root applies (a golden found by
/// its manifest): a regular file after symlinks, at most `max` bytes.
/// `Ok(None)` when there is no such file.
pub fn read_regular(path: &Path, max: u64) -> Result<Option<Vec<u8>>, GuardError> {
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(refuse(path, format!("cannot read: {e}"))),
    };
    regular(path, &meta, "", max)?;
    read_capped(path, path, max).map(Some)
}

/// The text of `path` (UTF-8), checked by [`check_file`] with
/// [`MAX_TEXT_BYTES`].
pub fn read_text(root: &Path, path: &Path) -> Result<String, GuardError> {
    let bytes = read_bytes(root, path, MAX_TEXT_BYTES)?;
    String::from_utf8(bytes).map_err(|_| refuse(path, "is not UTF-8 text".into()))
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::fs::symlink;

    fn project() -> tempfile::TempDir {
        let d = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(d.path().join("shaders")).unwrap();
        std::fs::write(d.path().join("shaders/a.wgsl"), "// a").unwrap();
        d
    }

    #[test]
    fn a_file_inside_reads_and_a_symlink_inside_too() {
        let d = project();
        symlink("a.wgsl", d.path().join("shaders/b.wgsl")).unwrap();
        assert_eq!(read_text(d.path(), &d.path().join("shaders/a.wgsl")).unwrap(), "// a");
        assert_eq!(read_text(d.path(), &d.path().join("shaders/b.wgsl")).unwrap(), "// a");
    }

    #[test]
    fn a_symlink_out_of_the_project_is_refused_naming_its_target() {
        let d = project();
        let outside = tempfile::tempdir().unwrap();
        std::fs::write(outside.path().join("secret"), "root:x:0:0").unwrap();
        symlink(outside.path().join("secret"), d.path().join("shaders/pw")).unwrap();
        let e = read_text(d.path(), &d.path().join("shaders/pw")).unwrap_err().to_string();
        assert!(e.contains("outside the project") && e.contains("secret"), "{e}");
        assert!(!e.contains("root:x"), "{e}");
    }

    #[test]
    fn devices_and_fifos_are_refused_before_reading() {
        let d = project();
        symlink("/dev/zero", d.path().join("shaders/z.wgsl")).unwrap();
        let e = read_text(d.path(), &d.path().join("shaders/z.wgsl")).unwrap_err().to_string();
        assert!(e.contains("/dev/zero"), "{e}");
        let fifo = d.path().join("shaders/f.wgsl");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        // Returns at once (a read would block forever with no writer).
        let e = read_text(d.path(), &fifo).unwrap_err().to_string();
        assert!(e.contains("a FIFO") && e.contains("expected a regular file"), "{e}");
    }

    #[test]
    fn a_file_past_the_cap_is_refused_with_its_size_and_the_cap() {
        let d = project();
        let big = d.path().join("big.bin");
        std::fs::write(&big, vec![0u8; 100]).unwrap();
        let e = read_bytes(d.path(), &big, 99).unwrap_err().to_string();
        assert!(e.contains("100 bytes") && e.contains("99 bytes at most"), "{e}");
        assert_eq!(read_bytes(d.path(), &big, 100).unwrap().len(), 100);
    }
}
