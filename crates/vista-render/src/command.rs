//! A project's own preprocessor (`[source] command`, SPEC 19): the command
//! runs in the project root on a shader file and its output is the WGSL
//! vista assembles and composes. Outputs are cached under
//! `target/vista-cache/command/` by a hash of the command, the shader and
//! every input, so a worker process or a second run does not run it again.
//! A failure (exit status, timeout, no output) is one line naming the
//! command and the last lines of its stderr.

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use vista_project::guard;
use vista_source::Generator;

/// A shader file's generated text.
#[derive(Debug, Clone)]
pub(crate) struct Generated {
    /// The WGSL the command wrote.
    pub text: String,
    /// What errors name: the template's path and the command.
    pub origin: String,
    /// Every file the output depends on besides the template: `inputs`
    /// and the command's own words that name project files (its script),
    /// with the hash of each (root-relative path, hash).
    pub inputs: Vec<(String, String)>,
}

/// How many of its stderr's last lines a failure quotes.
const STDERR_LINES: usize = 3;

/// The most output a command may write: a shader file's cap.
const MAX_OUTPUT: u64 = guard::MAX_TEXT_BYTES;

/// Results of this process, by cache key: a failed command is not run
/// again by the next [`crate::Sources`] of the same project (a worker's).
static MEMO: Mutex<Option<HashMap<String, Result<String, String>>>> = Mutex::new(None);

/// Held while a command runs (see [`generate`]).
static RUNNING: Mutex<()> = Mutex::new(());

/// Numbers each run's `{out}` file within this process.
static RUNS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// The folder of cached outputs under `root`.
const CACHE: &str = "target/vista-cache/command";

/// The files `g`'s output depends on besides the shader: its `inputs`, and
/// the command's words that are files of the project (its script), which
/// change the output as much as the inputs do. Root-relative.
pub(crate) fn dependencies(root: &Path, shader: &str, g: &Generator) -> Vec<String> {
    let mut paths: Vec<String> = g.inputs.clone();
    for w in g.command.iter().filter(|w| !w.contains('{') && !w.starts_with('-')) {
        let rel = w.trim_start_matches("./");
        let safe = !rel.is_empty() && !rel.starts_with('/') && !rel.split('/').any(|c| c == "..");
        if safe && root.join(rel).is_file() && !paths.iter().any(|p| p == rel) && rel != shader {
            paths.push(rel.to_string());
        }
    }
    paths
}

/// Runs (or finds cached) `g` on `shaders/<file>` of the project at `root`.
pub(crate) fn generate(root: &Path, file: &str, g: &Generator) -> Result<Generated, String> {
    let shader = format!("shaders/{file}");
    let fail = |why: String| format!("{shader}: [source] command `{}` {why}", g.display());
    let template =
        guard::read_bytes(root, &root.join(&shader), guard::MAX_TEXT_BYTES).map_err(|e| fail(e.to_string()))?;
    let paths = dependencies(root, &shader, g);
    let mut key = blake3::Hasher::new();
    key.update(b"vista [source] command 1\0");
    for w in &g.command {
        key.update(w.as_bytes());
        key.update(b"\0");
    }
    key.update(shader.as_bytes());
    key.update(&template);
    let mut inputs = Vec::new();
    for p in &paths {
        let bytes = guard::read_bytes(root, &root.join(p), guard::MAX_DATA_BYTES)
            .map_err(|e| fail(format!("cannot read its input {e}")))?;
        key.update(b"\0");
        key.update(p.as_bytes());
        key.update(&(bytes.len() as u64).to_le_bytes());
        key.update(&bytes);
        inputs.push((p.clone(), blake3::hash(&bytes).to_hex()[..16].to_string()));
    }
    let key = key.finalize().to_hex()[..32].to_string();
    let origin = vista_gpu::generated_origin(&root.join(&shader).display().to_string(), &g.display());
    let done = |text: String| Generated { text, origin: origin.clone(), inputs: inputs.clone() };
    if let Some(known) = MEMO.lock().expect("command memo").get_or_insert_default().get(&key) {
        return known.clone().map(done);
    }
    // One run at a time in this process: threads that ask for the same
    // output at once (a test binary's) wait, then find it in the memo.
    let _running = RUNNING.lock().expect("command lock");
    if let Some(known) = MEMO.lock().expect("command memo").get_or_insert_default().get(&key) {
        return known.clone().map(done);
    }
    let result = cached_or_run(root, &shader, g, &key).map_err(fail);
    MEMO.lock().expect("command memo").get_or_insert_default().insert(key, result.clone());
    result.map(done)
}

/// The cached output under `key`, or the command run now and its output cached.
fn cached_or_run(root: &Path, shader: &str, g: &Generator, key: &str) -> Result<String, String> {
    let dir = cache_dir(root)?;
    let cached = dir.join(format!("{key}.wgsl"));
    // Read through the guard: a cached file linked out of the project is a miss.
    if let Ok(bytes) = guard::read_bytes(root, &cached, MAX_OUTPUT)
        && let Ok(text) = String::from_utf8(bytes)
    {
        return Ok(text);
    }
    // Unique to this process and run: another process may run the same command now.
    let run_id = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let out = dir.join(format!(".out-{}-{run_id}-{key}.wgsl", std::process::id()));
    let out_rel = format!("{CACHE}/{}", out.file_name().unwrap_or_default().to_string_lossy());
    let uses_out = g.command.iter().any(|w| w.contains("{out}"));
    let argv: Vec<String> =
        g.command.iter().map(|w| w.replace("{shader}", shader).replace("{out}", &out_rel)).collect();
    let ran = run(root, &argv, Duration::from_millis(g.timeout_ms));
    let text = ran.and_then(|stdout| {
        let bytes = match uses_out {
            true => match guard::read_regular(&out, MAX_OUTPUT) {
                Ok(Some(b)) => b,
                Ok(None) => return Err(format!("wrote no {{out}} file ({out_rel})")),
                Err(e) => return Err(format!("wrote an {{out}} vista cannot read: {e}")),
            },
            false => stdout,
        };
        if bytes.iter().all(u8::is_ascii_whitespace) {
            return Err(match uses_out {
                true => "wrote an empty {out} file".to_string(),
                false => "printed nothing (without {out} in the command, its standard output is the WGSL)".into(),
            });
        }
        String::from_utf8(bytes).map_err(|_| "wrote output that is not UTF-8 text".to_string())
    });
    let _ = std::fs::remove_file(&out);
    let text = text?;
    vista_image::atomic_write(&cached, text.as_bytes())
        .map_err(|e| format!("ran, but its output was not cached: {e}"))?;
    Ok(text)
}

/// `<root>/target/vista-cache/command`, made if missing; refused if it
/// resolves outside the project (a symlinked `target/`).
fn cache_dir(root: &Path) -> Result<PathBuf, String> {
    let real_root = root.canonicalize().map_err(|e| format!("cannot resolve the project root: {e}"))?;
    let mut dir = root.to_path_buf();
    // Each folder checked before anything is made in it.
    for part in CACHE.split('/') {
        dir.push(part);
        if !dir.exists() {
            std::fs::create_dir(&dir).map_err(|e| format!("cannot make its cache folder {}: {e}", dir.display()))?;
        }
        let real = dir.canonicalize().map_err(|e| format!("cannot resolve {}: {e}", dir.display()))?;
        if !real.starts_with(&real_root) || !real.is_dir() {
            return Err(format!(
                "cannot cache its output: {} resolves to {}, outside the project; vista writes only inside it",
                dir.strip_prefix(root).unwrap_or(&dir).display(),
                real.display()
            ));
        }
    }
    Ok(dir)
}

/// Runs `argv` in `root` with no input, at most `timeout`: its standard
/// output, or why it failed (exit status or signal, timeout, with the
/// last lines of its stderr).
fn run(root: &Path, argv: &[String], timeout: Duration) -> Result<Vec<u8>, String> {
    use std::os::unix::process::CommandExt;
    let mut child = std::process::Command::new(&argv[0])
        .args(&argv[1..])
        .current_dir(root)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        // Its own process group, so that a timeout kills what it started too.
        .process_group(0)
        .spawn()
        .map_err(|e| format!("could not start: {e}"))?;
    let pipe = |r: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(r) = r {
                let _ = r.take(MAX_OUTPUT + 1).read_to_end(&mut buf);
            }
            buf
        })
    };
    let stdout = pipe(child.stdout.take().map(|p| Box::new(p) as Box<dyn Read + Send>));
    let stderr = pipe(child.stderr.take().map(|p| Box::new(p) as Box<dyn Read + Send>));
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if start.elapsed() < timeout => std::thread::sleep(Duration::from_millis(5)),
            Ok(None) => {
                // SAFETY: kill(2) on the process group the child leads.
                unsafe { libc::kill(-(child.id() as i32), libc::SIGKILL) };
                let _ = child.wait();
                return Err(format!("timed out after {} s and was killed", timeout.as_secs_f64()));
            }
            Err(e) => return Err(format!("could not be waited for: {e}")),
        }
    };
    let out = stdout.join().unwrap_or_default();
    let err = String::from_utf8_lossy(&stderr.join().unwrap_or_default()).into_owned();
    if !status.success() {
        let how = match (status.code(), std::os::unix::process::ExitStatusExt::signal(&status)) {
            (Some(c), _) => format!("exited with status {c}"),
            (None, Some(s)) => format!("was killed by signal {s}"),
            _ => "failed".to_string(),
        };
        let last: Vec<&str> = err.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
        let tail = &last[last.len().saturating_sub(STDERR_LINES)..];
        return Err(match tail.is_empty() {
            true => format!("{how} (its stderr was empty)"),
            false => format!("{how}; its stderr ends: {}", tail.join(" | ")),
        });
    }
    if out.len() as u64 > MAX_OUTPUT {
        return Err(format!("printed more than {MAX_OUTPUT} bytes"));
    }
    Ok(out)
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    fn project(template: &str) -> tempfile::TempDir {
        let d = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(d.path().join("shaders")).unwrap();
        std::fs::write(d.path().join("shaders/k.tmpl"), template).unwrap();
        d
    }

    fn sh(script: &str, inputs: &[&str], timeout_ms: u64) -> Generator {
        Generator {
            command: vec!["sh".into(), "-c".into(), script.into(), "gen".into(), "{shader}".into(), "{out}".into()],
            inputs: inputs.iter().map(|s| s.to_string()).collect(),
            timeout_ms,
        }
    }

    #[test]
    fn output_is_cached_by_the_template_and_inputs() {
        let d = project("N");
        std::fs::write(d.path().join("n.txt"), "4").unwrap();
        // Counts its runs in runs.log; writes the template with N replaced.
        let g = sh("echo run >> runs.log; sed \"s/N/$(cat n.txt)/\" \"$1\" > \"$2\"", &["n.txt"], 10_000);
        let runs = || std::fs::read_to_string(d.path().join("runs.log")).unwrap().lines().count();
        let a = generate(d.path(), "k.tmpl", &g).unwrap();
        assert_eq!(a.text, "4");
        assert!(a.origin.ends_with("shaders/k.tmpl (as `sh -c echo run >> runs.log; sed \"s/N/$(cat n.txt)/\" \"$1\" > \"$2\" gen {shader} {out}` generated it)"), "{}", a.origin);
        assert_eq!(a.inputs.iter().map(|(p, _)| p.as_str()).collect::<Vec<_>>(), ["n.txt"]);
        // The memo and then the disk cache: no second run.
        generate(d.path(), "k.tmpl", &g).unwrap();
        MEMO.lock().unwrap().take();
        assert_eq!(generate(d.path(), "k.tmpl", &g).unwrap().text, "4");
        assert_eq!(runs(), 1);
        // An input changed: run again.
        std::fs::write(d.path().join("n.txt"), "7").unwrap();
        assert_eq!(generate(d.path(), "k.tmpl", &g).unwrap().text, "7");
        assert_eq!(runs(), 2);
        // Without {out}, standard output is the WGSL.
        let g = Generator { command: vec!["cat".into(), "{shader}".into()], inputs: vec![], timeout_ms: 10_000 };
        assert_eq!(generate(d.path(), "k.tmpl", &g).unwrap().text, "N");
        let cached = std::fs::read_dir(d.path().join(CACHE)).unwrap().count();
        assert_eq!(cached, 3, "one file per output, no temporary left");
    }

    #[test]
    fn failures_name_the_command_and_its_stderr() {
        let d = project("N");
        let e = generate(
            d.path(),
            "k.tmpl",
            &sh("echo one >&2; echo two >&2; echo three >&2; echo four >&2; exit 3", &[], 10_000),
        )
        .unwrap_err();
        assert!(e.starts_with("shaders/k.tmpl: [source] command `sh -c"), "{e}");
        assert!(e.ends_with("exited with status 3; its stderr ends: two | three | four"), "{e}");
        let start = Instant::now();
        let e = generate(d.path(), "k.tmpl", &sh("sleep 30 & sleep 30", &[], 300)).unwrap_err();
        assert!(e.ends_with("timed out after 0.3 s and was killed"), "{e}");
        assert!(start.elapsed() < Duration::from_secs(10), "{:?}", start.elapsed());
        let e = generate(d.path(), "k.tmpl", &sh("true", &[], 10_000)).unwrap_err();
        assert!(e.contains("wrote no {out} file (target/vista-cache/command/.out-"), "{e}");
        let e = generate(d.path(), "k.tmpl", &sh(": > \"$2\"", &[], 10_000)).unwrap_err();
        assert!(e.ends_with("wrote an empty {out} file"), "{e}");
        let g = Generator { command: vec!["true".into()], inputs: vec![], timeout_ms: 10_000 };
        assert!(generate(d.path(), "k.tmpl", &g).unwrap_err().contains("printed nothing"));
        let g = Generator { command: vec!["no-such-program-here".into()], inputs: vec![], timeout_ms: 10_000 };
        assert!(generate(d.path(), "k.tmpl", &g).unwrap_err().contains("could not start: No such file"));
        let e = generate(d.path(), "k.tmpl", &sh("true", &["missing.json"], 10_000)).unwrap_err();
        assert!(e.contains("cannot read its input") && e.contains("missing.json"), "{e}");
    }

    #[test]
    fn a_cache_folder_outside_the_project_is_refused() {
        let d = project("N");
        let elsewhere = tempfile::tempdir().unwrap();
        std::os::unix::fs::symlink(elsewhere.path(), d.path().join("target")).unwrap();
        let e = generate(d.path(), "k.tmpl", &sh("cat \"$1\" > \"$2\"", &[], 10_000)).unwrap_err();
        assert!(e.contains("resolves to") && e.contains("outside the project"), "{e}");
        assert!(std::fs::read_dir(elsewhere.path()).unwrap().next().is_none(), "nothing written there");
    }
}
