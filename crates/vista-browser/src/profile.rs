//! Chromium's profile folder, one per browser process, in the temp folder.
//! A browser held by a process-wide context is never dropped, and a killed
//! vista runs no exit code, so a folder (2.3 MB) is removed three ways:
//! when its [`crate::cdp::Chromium`] drops, by an exit handler, and by the
//! next launch once the vista process named in the folder's name is gone.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once};

const PREFIX: &str = "vista-chromium-";

/// Browsers still running at exit, by Chromium's pid, with their folders.
static LIVE: Mutex<Vec<(u32, PathBuf)>> = Mutex::new(Vec::new());
static AT_EXIT: Once = Once::new();

/// A fresh profile folder `vista-chromium-<our pid>-XXXXXX`, after removing
/// those of vista processes that have ended.
pub(crate) fn create() -> std::io::Result<tempfile::TempDir> {
    let temp = std::env::temp_dir();
    sweep(&temp);
    AT_EXIT.call_once(|| {
        // SAFETY: registers a plain `extern "C" fn` with no arguments.
        unsafe { libc::atexit(at_exit) };
    });
    tempfile::Builder::new().prefix(&format!("{PREFIX}{}-", std::process::id())).tempdir_in(temp)
}

/// Chromium `pid` runs with `dir` as its profile until [`ended`].
pub(crate) fn started(pid: u32, dir: &Path) {
    LIVE.lock().expect("profiles").push((pid, dir.to_path_buf()));
}

/// Kills Chromium `pid` with its renderer and GPU processes: they share
/// its process group, and each writes into the profile until it ends.
pub(crate) fn kill_group(pid: u32) {
    // SAFETY: signals the group Chromium leads (spawned with its own).
    unsafe { libc::killpg(pid as libc::pid_t, libc::SIGKILL) };
}

/// Chromium `pid` was killed and waited for: removes its folder.
pub(crate) fn ended(pid: u32, dir: &Path) {
    LIVE.lock().expect("profiles").retain(|(p, _)| *p != pid);
    remove(dir);
}

/// Removes `dir`, again while a dying helper process still adds files,
/// and the folder of its `SingletonSocket`: Chromium keeps the socket in
/// `<temp>/org.chromium.Chromium.XXXXXX`, linked from the profile, and
/// removes it only when it exits itself (a `make test` left 74 of them).
fn remove(dir: &Path) {
    let socket_dir = std::fs::read_link(dir.join("SingletonSocket"))
        .ok()
        .and_then(|to| to.parent().map(Path::to_path_buf))
        .filter(|d| d.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("org.chromium.Chromium.")));
    if let Some(d) = socket_dir {
        let _ = std::fs::remove_dir_all(d);
    }
    for _ in 0..20 {
        if std::fs::remove_dir_all(dir).is_ok() || !dir.exists() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

extern "C" fn at_exit() {
    // Another thread may hold the lock as the process exits: leave the
    // folders to the next launch's sweep rather than wait.
    let Ok(live) = LIVE.try_lock() else { return };
    for (pid, dir) in live.iter() {
        kill_group(*pid);
        // SAFETY: reaping our own child process.
        unsafe { libc::waitpid(*pid as libc::pid_t, std::ptr::null_mut(), 0) };
        remove(dir);
    }
}

/// Removes the profile folders in `temp` whose vista process has ended.
pub(crate) fn sweep(temp: &Path) {
    let Ok(entries) = std::fs::read_dir(temp) else { return };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(owner) else { continue };
        if pid != std::process::id() && !alive(pid) {
            remove(&entry.path());
        }
    }
}

/// The pid in `vista-chromium-<pid>-XXXXXX`.
fn owner(name: &str) -> Option<u32> {
    let (pid, _) = name.strip_prefix(PREFIX)?.split_once('-')?;
    pid.parse().ok()
}

fn alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return false };
    // SAFETY: signal 0 only asks whether the process exists.
    unsafe { libc::kill(pid, 0) == 0 || *libc::__errno_location() == libc::EPERM }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweep_removes_only_folders_of_ended_processes() {
        let temp = tempfile::tempdir().unwrap();
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let ours = std::process::id();
        for name in [format!("{PREFIX}{dead}-a"), format!("{PREFIX}{ours}-b"), format!("{PREFIX}x"), "other-1-c".into()]
        {
            std::fs::create_dir(temp.path().join(&name)).unwrap();
            std::fs::write(temp.path().join(&name).join("Local State"), "{}").unwrap();
        }
        sweep(temp.path());
        let mut left: Vec<String> =
            std::fs::read_dir(temp.path()).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        left.sort();
        assert_eq!(left, ["other-1-c".to_string(), format!("{PREFIX}{ours}-b"), format!("{PREFIX}x")]);
    }

    #[test]
    fn a_profile_goes_with_its_singleton_socket_folder_and_nothing_else() {
        let temp = tempfile::tempdir().unwrap();
        let (profile, socket, other) = (
            temp.path().join(format!("{PREFIX}1-a")),
            temp.path().join("org.chromium.Chromium.Xy12Ab"),
            temp.path().join("elsewhere"),
        );
        for d in [&profile, &socket, &other] {
            std::fs::create_dir(d).unwrap();
        }
        std::fs::write(socket.join("SingletonSocket"), "").unwrap();
        std::os::unix::fs::symlink(socket.join("SingletonSocket"), profile.join("SingletonSocket")).unwrap();
        remove(&profile);
        assert!(!profile.exists() && !socket.exists(), "the profile and its socket's folder are gone");
        // A link to anything but Chromium's socket folder removes only the profile.
        std::fs::create_dir(&profile).unwrap();
        std::fs::write(other.join("SingletonSocket"), "").unwrap();
        std::os::unix::fs::symlink(other.join("SingletonSocket"), profile.join("SingletonSocket")).unwrap();
        remove(&profile);
        assert!(!profile.exists() && other.join("SingletonSocket").exists());
    }

    #[test]
    fn owner_reads_the_pid() {
        assert_eq!(owner("vista-chromium-4711-Ab3dEf"), Some(4711));
        assert_eq!(owner("vista-chromium-Ab3dEf"), None);
        assert_eq!(owner("vista-browser-4711-x"), None);
    }
}
