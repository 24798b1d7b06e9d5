//! Structure-aware fuzzing of what vista reads: the
//! checkout's own manifests, cases, `vista.toml`, pending renders, `.npy`,
//! `.png`, `.exr` and `.wgsl` files, mutated, must each be accepted or
//! refused with an error, never a panic, a signal or a hang.
//!
//! TOML files are mutated as TOML (a key dropped, a value swapped for one
//! of another type or an extreme, an unknown key, a table emptied) and as
//! text; binary files and WGSL are truncated and bit-flipped. The parsers
//! run in this process under `catch_unwind`; `vista.toml` and `pending.toml`
//! go through the binary (`vista list`, `vista bless --from-report`), whose
//! exit must be 0, 1 or 2. `make test` runs `VISTA_FUZZ_ITERATIONS`
//! (default 200) rounds from a fixed seed; `make fuzz` runs 20,000 from a
//! new one. Every input that ever failed is kept in `tests/fuzz/` and
//! replayed first.
//!
//! `mod hostile` runs the binary on whole projects made hostile: symlinks
//! out of the project where vista reads and writes, FIFOs and devices in
//! place of read files, shapes past the memory budget and the size limits,
//! includes and expressions past the parsers' depth (see its docs).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).expect("the checkout").to_path_buf()
}

/// xorshift64*: a fixed seed gives the same inputs on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Values that break assumptions: wrong types, extremes, empties.
fn odd_value(rng: &mut Rng) -> toml::Value {
    use toml::Value as V;
    match rng.below(12) {
        0 => V::Integer(-1),
        1 => V::Integer(i64::MAX),
        2 => V::Float(f64::NAN),
        3 => V::Float(-1e308),
        4 => V::Float(f64::INFINITY),
        5 => V::String(String::new()),
        6 => V::String("../../etc/passwd".into()),
        7 => V::Array(Vec::new()),
        8 => V::Array(vec![V::Integer(0); 5]),
        9 => V::Boolean(true),
        10 => V::Table(toml::Table::new()),
        _ => V::String("\u{0}\u{ffff}".into()),
    }
}

/// Walks to a random table or array inside `v` and mutates it once.
fn mutate_value(v: &mut toml::Value, rng: &mut Rng, depth: usize) {
    match v {
        toml::Value::Table(t) if !t.is_empty() => {
            let keys: Vec<String> = t.keys().cloned().collect();
            let k = rng.pick(&keys).clone();
            match rng.below(5) {
                0 => {
                    t.remove(&k);
                }
                1 => {
                    t.insert(k, odd_value(rng));
                }
                2 => {
                    t.insert(format!("zz_unknown_{}", rng.below(100)), odd_value(rng));
                }
                _ if depth < 6 => mutate_value(t.get_mut(&k).expect("a key"), rng, depth + 1),
                _ => {
                    t.insert(k, odd_value(rng));
                }
            }
        }
        toml::Value::Array(a) if !a.is_empty() => {
            let i = rng.below(a.len());
            match rng.below(4) {
                0 => {
                    a.remove(i);
                }
                1 => {
                    let copy = a[i].clone();
                    a.push(copy);
                }
                _ if depth < 6 => mutate_value(&mut a[i], rng, depth + 1),
                _ => a[i] = odd_value(rng),
            }
        }
        other => *other = odd_value(rng),
    }
}

/// A TOML text mutated as TOML (most rounds) or as text.
fn mutate_toml(text: &str, rng: &mut Rng) -> String {
    match (rng.below(4), toml::from_str::<toml::Value>(text)) {
        (0, _) | (_, Err(_)) => String::from_utf8_lossy(&mutate_bytes(text.as_bytes(), rng)).into_owned(),
        (_, Ok(mut v)) => {
            for _ in 0..1 + rng.below(3) {
                mutate_value(&mut v, rng, 0);
            }
            toml::to_string(&v).unwrap_or_default()
        }
    }
}

/// Bytes truncated, bit-flipped, or a run of them repeated.
fn mutate_bytes(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = bytes.to_vec();
    if b.is_empty() {
        return b;
    }
    match rng.below(3) {
        0 => b.truncate(rng.below(b.len())),
        1 => {
            for _ in 0..1 + rng.below(8) {
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
        }
        _ => {
            let i = rng.below(b.len());
            let n = rng.below(64).min(b.len() - i);
            let run = b[i..i + n].to_vec();
            b.splice(i..i, run);
        }
    }
    b
}

/// Files under `dir` (recursively) whose name ends with `ext`.
fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else { return out };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() && !p.ends_with("target") {
            out.extend(files(&p, ext));
        } else if p.to_string_lossy().ends_with(ext) {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// Where an input that failed is kept, named by its bytes.
fn kept_path(kind: &str, input: &[u8]) -> PathBuf {
    repo().join("tests/fuzz").join(format!("{kind}-{:016x}", blake3_ish(input)))
}

fn keep(kind: &str, input: &[u8]) -> PathBuf {
    let kept = kept_path(kind, input);
    let _ = std::fs::create_dir_all(kept.parent().expect("a parent"));
    let _ = std::fs::write(&kept, input);
    kept
}

/// Runs `f`, failing with `what` and the input kept under tests/fuzz/ if it
/// panics; if it runs past `limit` (a hang), a watchdog keeps the input and
/// ends the test binary, since a hung parser cannot be interrupted.
fn survive(what: &str, kind: &str, input: &[u8], limit: Duration, f: impl FnOnce() + std::panic::UnwindSafe) {
    let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    {
        let (done, kind, input, what) = (done.clone(), kind.to_string(), input.to_vec(), what.to_string());
        std::thread::spawn(move || {
            let start = Instant::now();
            while start.elapsed() < limit {
                if done.load(std::sync::atomic::Ordering::Relaxed) {
                    return;
                }
                std::thread::sleep(Duration::from_millis(20));
            }
            let kept = keep(&kind, &input);
            eprintln!("{what}: still running after {limit:?} on a mutated input (a hang), kept as {}", kept.display());
            std::process::exit(101);
        });
    }
    let outcome = std::panic::catch_unwind(f);
    done.store(true, std::sync::atomic::Ordering::Relaxed);
    if outcome.is_err() {
        let kept = keep(kind, input);
        panic!("{what}: panicked on a mutated input, kept as {} (replayed by every later run)", kept.display());
    }
}

/// A stable name for an input (FNV-1a; no cryptographic need).
fn blake3_ish(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ *b as u64).wrapping_mul(0x100_0000_01b3))
}

/// One input of `kind` through its parser.
fn parse_one(kind: &str, bytes: &[u8], registry: &vista_kernels::Registry, scratch: &Path) {
    let text = || String::from_utf8_lossy(bytes).into_owned();
    let limit = Duration::from_secs(20);
    let what = format!("{kind} parser");
    match kind {
        "manifest" => survive(&what, kind, bytes, limit, || {
            let _ = vista_kernels::manifest::parse("fuzzed", "fuzzed.toml", &text());
        }),
        "cases" => survive(
            &what,
            kind,
            bytes,
            limit,
            std::panic::AssertUnwindSafe(|| {
                let _ = vista_golden::cases::parse_cases(Path::new("cases.toml"), &text(), registry);
            }),
        ),
        "npy" => survive(&what, kind, bytes, limit, || {
            let _ = vista_image::npy::decode_npy(Path::new("fuzzed.npy"), bytes);
        }),
        "png" => survive(&what, kind, bytes, limit, || {
            let _ = vista_image::decode_png16(Path::new("fuzzed.png"), bytes);
        }),
        "exr" => {
            let path = scratch.join("fuzzed.exr");
            std::fs::write(&path, bytes).expect("scratch");
            survive(&what, kind, bytes, limit, || {
                let _ = vista_image::read_exr(&path);
            });
        }
        "wgsl" => survive(&what, kind, bytes, limit, || {
            let project = vista_project::Project::builtin_only();
            let edited = text();
            if let Ok(set) = vista_render::edited_shader_set(&project, "fuzzed", |rel, t| match rel {
                "fbm.wgsl" => edited.clone(),
                _ => t,
            }) {
                let _ = set.compose("fbm.wgsl");
            }
        }),
        other => panic!("unknown kind {other}"),
    }
}

fn iterations() -> usize {
    std::env::var("VISTA_FUZZ_ITERATIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(200)
}

fn seed() -> u64 {
    std::env::var("VISTA_FUZZ_SEED").ok().and_then(|v| v.parse().ok()).unwrap_or(0x5eed_f00d)
}

#[test]
fn mutated_inputs_are_accepted_or_refused_never_a_panic_or_a_hang() {
    let root = repo();
    let registry = vista_kernels::Registry::builtin();
    let scratch = tempfile::tempdir().expect("a temp dir");
    // Every input that ever failed, first.
    for kept in files(&root.join("tests/fuzz"), "") {
        let name = kept.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
        let kind = name.split('-').next().unwrap_or_default();
        if ["manifest", "cases", "npy", "png", "exr", "wgsl"].contains(&kind) {
            parse_one(kind, &std::fs::read(&kept).expect("kept input"), registry, scratch.path());
        }
    }
    let corpus: Vec<(&str, Vec<PathBuf>)> = vec![
        (
            "manifest",
            [files(&root.join("kernels"), ".toml"), files(&root.join("examples"), ".toml")]
                .concat()
                .into_iter()
                .filter(|p| p.to_string_lossy().contains("/kernels/"))
                .collect(),
        ),
        ("cases", files(&root.join("golden"), "cases.toml")),
        ("npy", files(&root.join("examples/graphs"), ".npy")),
        ("png", files(&root.join("golden/fbm"), ".png")),
        ("exr", files(&root.join("examples/graphs/golden/boids"), ".exr")),
        ("wgsl", vec![root.join("shaders/fbm.wgsl")]),
    ];
    for (kind, paths) in &corpus {
        assert!(!paths.is_empty(), "no {kind} files to fuzz from");
    }
    let mut rng = Rng(seed());
    let n = iterations();
    let mut counts = std::collections::BTreeMap::new();
    for i in 0..n {
        let (kind, paths) = &corpus[i % corpus.len()];
        // Composing WGSL is the slowest parser: one round in four.
        if *kind == "wgsl" && rng.below(4) != 0 {
            continue;
        }
        let seed_bytes = std::fs::read(rng.pick(paths)).expect("a corpus file");
        let input = match *kind {
            "manifest" | "cases" => mutate_toml(&String::from_utf8_lossy(&seed_bytes), &mut rng).into_bytes(),
            _ => mutate_bytes(&seed_bytes, &mut rng),
        };
        parse_one(kind, &input, registry, scratch.path());
        *counts.entry(*kind).or_insert(0) += 1;
    }
    eprintln!("fuzz: {n} rounds from seed {:#x}: {counts:?}", seed());
}

/// `vista.toml` and `pending.toml` through the binary: its exit is 0, 1 or
/// 2 and it never prints a panic.
#[test]
fn mutated_project_and_pending_files_exit_0_1_or_2() {
    let bin = env!("CARGO_BIN_EXE_vista");
    let mut rng = Rng(seed() ^ 0x7a11);
    let rounds = (iterations() / 10).max(5);
    let d = tempfile::tempdir().expect("a temp dir");
    let project = d.path();
    std::fs::create_dir_all(project.join("golden")).expect("golden");
    std::fs::write(project.join("golden/cases.toml"), "[[case]]\nid = \"a\"\nkernel = \"fbm\"\nsize = \"16x16\"\n")
        .expect("cases");
    let report = project.join("report");
    std::fs::create_dir_all(&report).expect("report");
    let vista_toml = "[project]\nname = \"fuzzed\"\n";
    // A pending entry shaped like the ones `vista check` writes.
    let manifest = std::fs::read_to_string(repo().join("golden/manifest.toml")).expect("manifest");
    let one: toml::Value = toml::from_str(&manifest).expect("manifest");
    let entry = one["case"]["fbm-perlin-default"].clone();
    let pending = toml::to_string(&toml::Value::Table(toml::Table::from_iter([(
        "case".to_string(),
        toml::Value::Table(toml::Table::from_iter([("a".to_string(), entry)])),
    )])))
    .expect("pending");
    for i in 0..rounds {
        let (file, args): (PathBuf, Vec<&str>) = match i % 2 {
            0 => {
                std::fs::write(project.join("vista.toml"), mutate_toml(vista_toml, &mut rng)).expect("write");
                (project.join("vista.toml"), vec!["list", "--names"])
            }
            _ => {
                std::fs::write(project.join("vista.toml"), "").expect("write");
                std::fs::write(report.join("pending.toml"), mutate_toml(&pending, &mut rng)).expect("write");
                (report.join("pending.toml"), vec!["bless", "--from-report", "report"])
            }
        };
        let mut child = Command::new(bin)
            .args(&args)
            .current_dir(project)
            .env("VISTA_ROOT", project)
            .env_remove("CI")
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("vista runs");
        // A hang is a failure too: killed after a minute.
        let start = Instant::now();
        while child.try_wait().expect("wait").is_none() && start.elapsed() < Duration::from_secs(60) {
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = child.kill();
        let out = child.wait_with_output().expect("vista's output");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let code = out.status.code();
        if !matches!(code, Some(0..=2)) || stderr.contains("panicked") {
            let kind = if i % 2 == 0 { "vista-toml" } else { "pending-toml" };
            let kept = repo()
                .join("tests/fuzz")
                .join(format!("{kind}-{:016x}", blake3_ish(&std::fs::read(&file).expect("the input"))));
            let _ = std::fs::create_dir_all(kept.parent().expect("a parent"));
            let _ = std::fs::copy(&file, &kept);
            panic!("vista {} exited {code:?} on a mutated {kind} (kept as {}): {stderr}", args[0], kept.display());
        }
    }
}

/// Hostile projects through the binary: a temporary project (two kernels,
/// one fed by `.npy`, `.bin` and `.png` inputs through an `#include` and an
/// `#import`, one a WESL kernel importing a module of its package; goldens
/// blessed once) with one file or folder made hostile per round, then
/// `vista check`, `bless`, `list` or `render` under a watchdog. Five
/// classes: symlinks out of the project (read files and folders, and
/// folders and files vista writes), FIFOs and devices in place of read
/// files, shapes past the memory budget or the size limits, and includes
/// and expressions past the parsers' depth. Every run must exit 0, 1 or 2
/// (never a signal, a panic or a hang: killed after a minute), stay under
/// a memory cap, leave every file outside the project byte-identical and
/// never echo one, and a refusal must be the documented line naming the
/// path. `make test` covers every sub-case once with random variants
/// (which file, target, command, depth); `make fuzz` runs many more. A
/// round that failed is kept in `tests/fuzz/hostile-<class>-...` (its
/// sub-case and seed) and replayed first by every later run.
///
/// The gaps these classes found once (each now in its class) also run as
/// fixed rounds, so each stays closed: see [`hostile::ONCE_OPEN`].
#[cfg(unix)]
mod hostile {
    use super::{Rng, iterations, repo, seed};
    use std::io::{Read, Seek};
    use std::path::{Path, PathBuf};
    use std::process::Command;
    use std::time::{Duration, Instant};

    /// A run still going after this is a hang.
    const HANG: Duration = Duration::from_secs(60);
    /// A run whose resident memory (vista's and its workers' together)
    /// passes this is a blow-up: these 8 x 8 cases need about 110 MB, the
    /// one 1 GiB buffer the device cannot bind about 1.1 GB.
    const RSS_CAP_KB: u64 = 1536 * 1024;
    /// Written into every outside file: it must never reach vista's output.
    const SECRET: &str = "HOSTILE-SECRET root:x:0:0:do-not-echo";

    const VISTA_TOML: &str = "name = \"hostile\"\n";
    const K_TOML: &str = r#"summary = "fuzz: two buffers, a PNG and an integer texture, through an #include and an #import"

[source]
include = ["shaders/inc"]

[[resource]]
name = "weights"
kind = "buffer"
file = "inputs/w.npy"

[[resource]]
name = "bias"
kind = "buffer"
file = "inputs/b.bin"

[[resource]]
name = "photo"
kind = "texture"
format = "rgba16float"
file = "inputs/t.png"

[[resource]]
name = "mask"
kind = "texture"
format = "r32uint"
file = "inputs/m.npy"

[[resource]]
name = "picture"
kind = "texture"
format = "rgba32float"

[[pass]]
entry = "main"
bind = { weights = "weights", bias = "bias", photo = "photo", mask = "mask", output = "picture" }

[[param]]
name = "gain"
type = "f32"
range = [0, 1]
default = 0.5
doc = "scale of the picture"
"#;
    const K_WGSL: &str = r#"#include "common"
#import hostile::util::lift

struct Params {
    width: u32,
    height: u32,
    gain: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> weights: array<f32>;
@group(0) @binding(2) var<storage, read> bias: array<f32>;
@group(0) @binding(3) var photo: texture_2d<f32>;
@group(0) @binding(4) var mask: texture_2d<u32>;
@group(0) @binding(5) var output: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let t = id.xy % vec2(4u);
    let v = lift(params.gain) * weights[t.x] * bias[t.y] * textureLoad(photo, t, 0).x;
    textureStore(output, id.xy, vec4(vec3(shade(v * f32(textureLoad(mask, t, 0).x) / 15.0)), 1.0));
}
"#;
    const COMMON_WGSL: &str = "fn shade(v: f32) -> f32 {\n    return clamp(v, 0.0, 1.0);\n}\n";
    const UTIL_WGSL: &str = "#define_import_path hostile::util\n\nfn lift(v: f32) -> f32 {\n    return v * 1.0;\n}\n";
    const W_TOML: &str = r#"summary = "fuzz: a WESL kernel importing a module of its own package"
shader = "wl/w.wesl"

[[param]]
name = "gain"
type = "f32"
range = [0, 1]
default = 0.5
doc = "grey level"
"#;
    const W_WESL: &str = r#"import package::wl::util::lift;

struct Params {
    width: u32,
    height: u32,
    gain: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    textureStore(output, id.xy, vec4(vec3(lift(params.gain)), 1.0));
}
"#;
    const WL_UTIL_WESL: &str = "fn lift(v: f32) -> f32 {\n    return v * 1.0;\n}\n";
    const CASES: &str = "[[case]]\nid = \"a\"\nkernel = \"k\"\nsize = \"8x8\"\n\n[[case]]\nid = \"b\"\nkernel = \"w\"\nsize = \"8x8\"\n";
    /// The same cases rendering other pictures: `check` fails both.
    const CASES_CHANGED: &str = "[[case]]\nid = \"a\"\nkernel = \"k\"\nsize = \"8x8\"\nset = { gain = 0.25 }\n\n\
                                 [[case]]\nid = \"b\"\nkernel = \"w\"\nsize = \"8x8\"\nset = { gain = 0.25 }\n";

    /// A command of a round.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum Cmd {
        Check,
        Bless,
        List,
        RenderK,
        RenderW,
    }

    impl Cmd {
        fn args(self) -> Vec<String> {
            let v: &[&str] = match self {
                Cmd::Check => &["check"],
                Cmd::Bless => &["bless"],
                Cmd::List => &["list"],
                Cmd::RenderK => &["render", "k", "-o", "render.png"],
                Cmd::RenderW => &["render", "w", "-o", "render.png"],
            };
            v.iter().map(|s| s.to_string()).collect()
        }
    }

    const ALL: &[Cmd] = &[Cmd::Check, Cmd::Bless, Cmd::List, Cmd::RenderK, Cmd::RenderW];
    const K_READERS: &[Cmd] = &[Cmd::Check, Cmd::Bless, Cmd::List, Cmd::RenderK];
    const INPUT_READERS: &[Cmd] = &[Cmd::Check, Cmd::Bless, Cmd::RenderK];
    const CASE_READERS: &[Cmd] = &[Cmd::Check, Cmd::Bless];

    /// How vista treats a file it reads.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum How {
        /// Through `vista_project::guard`: a symlink out of the project, a
        /// FIFO or a device is refused naming the path.
        Guarded,
        /// `vista.toml`: it marks the project whatever it is, and is then
        /// read through the guard (a FIFO or device refused naming it).
        ProjectFile,
        /// Goldens and `golden/manifest.toml`: found through the manifest,
        /// a regular file after symlinks, wherever they lead (by design:
        /// nothing is written through them and nothing of them is
        /// echoed); a FIFO or a device is refused naming the path.
        Golden,
    }

    /// A file vista reads, and the commands that read it.
    struct ReadFile {
        rel: &'static str,
        readers: &'static [Cmd],
        how: How,
    }

    const READ_FILES: &[ReadFile] = &[
        ReadFile { rel: "vista.toml", readers: ALL, how: How::ProjectFile },
        ReadFile { rel: "kernels/k.toml", readers: ALL, how: How::Guarded },
        ReadFile { rel: "kernels/w.toml", readers: ALL, how: How::Guarded },
        // Every shader file is read (listed for modules) by any command
        // that loads the project's kernels.
        ReadFile { rel: "shaders/k.wgsl", readers: ALL, how: How::Guarded },
        ReadFile { rel: "shaders/inc/common.wgsl", readers: ALL, how: How::Guarded },
        ReadFile { rel: "shaders/lib/util.wgsl", readers: ALL, how: How::Guarded },
        ReadFile { rel: "shaders/wl/w.wesl", readers: ALL, how: How::Guarded },
        ReadFile { rel: "shaders/wl/util.wesl", readers: ALL, how: How::Guarded },
        ReadFile { rel: "golden/cases.toml", readers: CASE_READERS, how: How::Guarded },
        ReadFile { rel: "inputs/w.npy", readers: INPUT_READERS, how: How::Guarded },
        ReadFile { rel: "inputs/b.bin", readers: INPUT_READERS, how: How::Guarded },
        ReadFile { rel: "inputs/t.png", readers: INPUT_READERS, how: How::Guarded },
        ReadFile { rel: "inputs/m.npy", readers: INPUT_READERS, how: How::Guarded },
        ReadFile { rel: "golden/manifest.toml", readers: CASE_READERS, how: How::Golden },
        ReadFile { rel: "golden/k/a.png", readers: CASE_READERS, how: How::Golden },
        ReadFile { rel: "golden/k/a.exr", readers: CASE_READERS, how: How::Golden },
        ReadFile { rel: "golden/w/b.png", readers: CASE_READERS, how: How::Golden },
    ];

    /// Folders vista reads files from, the commands that read them, and
    /// what a symlink out of the project there comes to: a project folder
    /// (`kernels/`, `shaders/` and below) is walked only where it resolves
    /// inside the project, else skipped (its files are then missing); a
    /// file read by path is refused naming it.
    const READ_FOLDERS: &[(&str, &[Cmd], &[&str])] = &[
        ("kernels", &[Cmd::Check, Cmd::Bless, Cmd::RenderK, Cmd::RenderW], &["unknown kernel '"]),
        ("shaders", ALL, &["not found in project"]),
        ("shaders/inc", K_READERS, &["#include \"common\" not found"]),
        ("inputs", INPUT_READERS, &["inputs/", "outside the project"]),
        ("golden", CASE_READERS, &["golden/cases.toml", "outside the project"]),
    ];

    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum Hostile {
        Outside,
        Fifo,
        Device,
    }

    /// What a round must end with (besides exit 0, 1 or 2, no panic, no
    /// hang, the memory cap and the outside untouched).
    #[derive(Debug, Clone)]
    enum Expect {
        /// Exit 0.
        Accepted,
        /// Exactly this exit.
        Exit(i32),
        /// Exit 2 with exactly one `error` line holding every needle; for
        /// `check`, that or exit 1 with a `FAIL:` line holding them.
        Refused(Vec<String>),
        /// Exit 0, 1 or 2.
        Survives,
        /// Exit 0 without this text in stdout (a project file skipped, not read).
        AcceptedWithout(String),
        /// Exit 1 with an `error` line (or `check`'s `FAIL:` line) naming
        /// the device limit, before any GPU work; or exit 0 on a device
        /// that grants it.
        Unsupported(String),
    }

    /// One run of the binary on a hostile project.
    struct Round {
        what: String,
        cmd: Cmd,
        args: Vec<String>,
        env: Vec<(String, String)>,
        expect: Expect,
        /// A path (relative to the project) that, if it exists after the
        /// run, must be a real folder: vista replaced a planted symlink.
        real_folder_after: Option<String>,
        /// A path (relative to the project) that must not exist after the run.
        absent_after: Option<String>,
        /// Outside paths hashed before and after (besides the round's
        /// outside folder).
        also_outside: Vec<PathBuf>,
    }

    impl Round {
        fn new(what: String, cmd: Cmd, expect: Expect) -> Round {
            Round {
                what,
                cmd,
                args: cmd.args(),
                env: Vec::new(),
                expect,
                real_folder_after: None,
                absent_after: None,
                also_outside: Vec::new(),
            }
        }
    }

    /// What a run of vista came to.
    struct Outcome {
        code: Option<i32>,
        signal: Option<i32>,
        stdout: String,
        stderr: String,
        elapsed: Duration,
        /// The most resident memory vista and its workers held together.
        peak_rss_kb: u64,
        hung: bool,
        blew_up: bool,
    }

    /// One Mesa shader cache for every run (as tests/cli.rs does).
    fn mesa_cache() -> PathBuf {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mesa-cache");
        std::fs::create_dir_all(&dir).expect("the suite's Mesa cache folder");
        dir
    }

    fn status_kb(pid: u32, key: &str) -> Option<u64> {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
        let line = status.lines().find(|l| l.starts_with(key))?;
        line.split_whitespace().nth(1)?.parse().ok()
    }

    /// `pid` and its descendants (vista runs GPU work in worker processes
    /// of its own binary).
    fn process_tree(pid: u32) -> Vec<u32> {
        let mut tree = vec![pid];
        let mut i = 0;
        while i < tree.len() {
            if let Ok(tasks) = std::fs::read_dir(format!("/proc/{}/task", tree[i])) {
                for t in tasks.flatten() {
                    if let Ok(kids) = std::fs::read_to_string(t.path().join("children")) {
                        tree.extend(kids.split_whitespace().filter_map(|k| k.parse::<u32>().ok()));
                    }
                }
            }
            i += 1;
        }
        tree
    }

    /// Runs vista in `project` with `env`, in a process group of its own
    /// (with its workers), all killed past `limit` (a hang) or once their
    /// resident memory together passes [`RSS_CAP_KB`] (a blow-up).
    fn run_vista(project: &Path, env: &[(String, String)], args: &[String], limit: Duration) -> Outcome {
        use std::os::unix::process::CommandExt;
        let mut out = tempfile::tempfile().expect("a temp file");
        let mut err = tempfile::tempfile().expect("a temp file");
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_vista"));
        cmd.args(args)
            .current_dir(project)
            .process_group(0)
            .env("XDG_RUNTIME_DIR", "/tmp")
            .env("MESA_SHADER_CACHE_DIR", mesa_cache())
            .env_remove("CI")
            .env_remove("VISTA_ROOT")
            .env_remove("VISTA_MAX_BYTES")
            .env_remove("VISTA_BACKEND")
            .env_remove("VISTA_VALIDATION")
            .stdin(std::process::Stdio::null())
            .stdout(out.try_clone().expect("a file"))
            .stderr(err.try_clone().expect("a file"));
        for (k, v) in env {
            cmd.env(k, v);
        }
        let start = Instant::now();
        let mut child = cmd.spawn().expect("vista runs");
        let (mut peak, mut hung, mut blew_up) = (0u64, false, false);
        let status = (0u64..)
            .find_map(|tick| {
                if let Some(status) = child.try_wait().expect("wait") {
                    return Some(status);
                }
                // The exit every 10 ms, memory every 40 ms (a read of
                // /dev/zero took a second to pass the cap).
                if tick % 4 == 0 {
                    let rss: u64 = process_tree(child.id()).into_iter().filter_map(|p| status_kb(p, "VmRSS:")).sum();
                    peak = peak.max(rss);
                    blew_up = rss > RSS_CAP_KB;
                }
                hung = start.elapsed() > limit;
                if hung || blew_up {
                    // The group is vista's and its workers' (the leader is
                    // not reaped yet, so its id still names this group).
                    // SAFETY: kill(2) with a negative pid signals that group only.
                    unsafe { libc::kill(-(child.id() as i32), libc::SIGKILL) };
                    return Some(child.wait().expect("wait"));
                }
                std::thread::sleep(Duration::from_millis(10));
                None
            })
            .expect("an exit");
        let elapsed = start.elapsed();
        let read = |f: &mut std::fs::File| {
            let mut s = Vec::new();
            f.rewind().expect("rewind");
            f.read_to_end(&mut s).expect("read");
            String::from_utf8_lossy(&s).into_owned()
        };
        use std::os::unix::process::ExitStatusExt;
        Outcome {
            code: status.code(),
            signal: status.signal(),
            stdout: read(&mut out),
            stderr: read(&mut err),
            elapsed,
            peak_rss_kb: peak,
            hung,
            blew_up,
        }
    }

    fn write(root: &Path, rel: &str, bytes: impl AsRef<[u8]>) {
        let p = root.join(rel);
        std::fs::create_dir_all(p.parent().expect("a parent")).expect("a folder");
        std::fs::write(&p, bytes).unwrap_or_else(|e| panic!("write {}: {e}", p.display()));
    }

    fn f32s(v: &[f32]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    /// The project every round starts from, its goldens blessed.
    fn template() -> tempfile::TempDir {
        let d = tempfile::tempdir().expect("a temp dir");
        let root = d.path();
        for (rel, text) in [
            ("vista.toml", VISTA_TOML),
            ("kernels/k.toml", K_TOML),
            ("kernels/w.toml", W_TOML),
            ("shaders/k.wgsl", K_WGSL),
            ("shaders/inc/common.wgsl", COMMON_WGSL),
            ("shaders/lib/util.wgsl", UTIL_WGSL),
            ("shaders/wl/w.wesl", W_WESL),
            ("shaders/wl/util.wesl", WL_UTIL_WESL),
            ("golden/cases.toml", CASES),
        ] {
            write(root, rel, text);
        }
        write(root, "inputs/b.bin", f32s(&[1.0, 0.75, 0.5, 0.25]));
        write(root, "inputs/w.npy", vista_image::npy::encode_npy("<f4", &[4], &f32s(&[0.1, 0.5, 0.9, 1.0])));
        let mask: Vec<u8> = (0u32..16).flat_map(|v| v.to_le_bytes()).collect();
        write(root, "inputs/m.npy", vista_image::npy::encode_npy("<u4", &[4, 4], &mask));
        let mut photo = vista_image::Image::new(4, 4);
        for y in 0..4 {
            for x in 0..4 {
                photo.set(x, y, [x as f32 / 3.0, y as f32 / 3.0, 0.5, 1.0]);
            }
        }
        vista_image::write_png16(&root.join("inputs/t.png"), &photo).expect("t.png");
        let b = run_vista(root, &[], &["bless".to_string()], HANG);
        assert!(
            b.code == Some(0),
            "the hostile-project template does not bless (is lavapipe installed? make lavapipe): {}{}",
            b.stdout,
            b.stderr
        );
        for rel in ["golden/k/a.png", "golden/k/a.exr", "golden/w/b.png", "golden/manifest.toml"] {
            assert!(root.join(rel).is_file(), "bless wrote no {rel}");
        }
        let _ = std::fs::remove_dir_all(root.join("target"));
        d
    }

    fn copy_tree(from: &Path, to: &Path) {
        std::fs::create_dir_all(to).expect("a folder");
        for e in std::fs::read_dir(from).expect("a folder").flatten() {
            let (src, dst) = (e.path(), to.join(e.file_name()));
            if e.file_type().expect("a type").is_dir() {
                copy_tree(&src, &dst);
            } else {
                std::fs::copy(&src, &dst).expect("a copy");
            }
        }
    }

    /// Every entry under `dir` (symlinks not followed) with its kind and
    /// its bytes' hash: what must not change outside the project.
    fn snapshot(dir: &Path) -> Vec<(PathBuf, String)> {
        let mut out = Vec::new();
        let Ok(meta) = std::fs::symlink_metadata(dir) else { return vec![(dir.to_path_buf(), "absent".into())] };
        if meta.is_dir() {
            out.push((dir.to_path_buf(), "folder".into()));
            let mut entries: Vec<PathBuf> =
                std::fs::read_dir(dir).expect("a folder").flatten().map(|e| e.path()).collect();
            entries.sort();
            for p in entries {
                out.extend(snapshot(&p));
            }
        } else if meta.file_type().is_symlink() {
            out.push((dir.to_path_buf(), format!("link {:?}", std::fs::read_link(dir).ok())));
        } else if meta.is_file() {
            let bytes = std::fs::read(dir).expect("a file outside");
            out.push((dir.to_path_buf(), format!("{} bytes {:016x}", bytes.len(), super::blake3_ish(&bytes))));
        } else {
            out.push((dir.to_path_buf(), "special".into()));
        }
        out
    }

    fn symlink(target: &Path, link: &Path) {
        let _ = std::fs::remove_file(link);
        let _ = std::fs::remove_dir_all(link);
        std::fs::create_dir_all(link.parent().expect("a parent")).expect("a folder");
        std::os::unix::fs::symlink(target, link)
            .unwrap_or_else(|e| panic!("symlink {} -> {}: {e}", link.display(), target.display()));
    }

    fn mkfifo(path: &Path) {
        use std::os::unix::ffi::OsStrExt;
        let _ = std::fs::remove_file(path);
        let c = std::ffi::CString::new(path.as_os_str().as_bytes()).expect("a path without NUL");
        // SAFETY: `c` is a NUL-terminated path that outlives the call.
        let rc = unsafe { libc::mkfifo(c.as_ptr(), 0o644) };
        assert_eq!(rc, 0, "mkfifo {}: {}", path.display(), std::io::Error::last_os_error());
    }

    /// Rounds of a class: every sub-case once under `make test` (200
    /// iterations), 500 rounds under `make fuzz` (20,000).
    fn rounds(subcases: usize) -> usize {
        (iterations() / 40).max(subcases)
    }

    /// The lines of a refusal: stderr's `error` lines (exit 2) or stdout's
    /// `FAIL:` lines (`check`, exit 1).
    fn refusal_lines(o: &Outcome) -> Vec<String> {
        match o.code {
            Some(2) => o.stderr.lines().filter(|l| l.starts_with("error")).map(str::to_string).collect(),
            _ => {
                o.stdout.lines().filter(|l| l.trim_start().starts_with("FAIL:")).map(|l| l.trim().to_string()).collect()
            }
        }
    }

    /// Why `o` breaks the round's rules, if it does.
    fn judge(r: &Round, o: &Outcome, project: &Path, limit: Duration) -> Result<Option<String>, String> {
        if o.hung {
            return Err(format!("still running after {limit:?}: a hang"));
        }
        if o.blew_up {
            return Err(format!("resident memory passed {} MiB: a memory blow-up", RSS_CAP_KB / 1024));
        }
        let Some(code) = o.code else { return Err(format!("killed by signal {:?}", o.signal)) };
        if !(0..=2).contains(&code) {
            return Err(format!("exit {code}: 0, 1 or 2 only (101 is a panic, 134 an abort)"));
        }
        if o.stderr.contains("panicked") || o.stdout.contains("panicked") {
            return Err("printed a panic".into());
        }
        if o.stdout.contains(SECRET) || o.stderr.contains(SECRET) {
            return Err("echoed the contents of a file outside the project".into());
        }
        let example = match &r.expect {
            Expect::Accepted if code != 0 => return Err(format!("exit {code}, but this is accepted (exit 0)")),
            Expect::Exit(want) if code != *want => return Err(format!("exit {code}, want {want}")),
            Expect::Unsupported(limit) if code != 0 => {
                let lines: Vec<String> = [
                    refusal_lines(o),
                    o.stderr.lines().filter(|l| l.starts_with("error")).map(str::to_string).collect(),
                ]
                .concat();
                match (code, lines.iter().find(|l| l.contains("unsupported") && l.contains(limit.as_str()))) {
                    (1, Some(l)) => Some(l.clone()),
                    _ => return Err(format!("exit {code}, want 1 naming the unsupported {limit} (or 0)")),
                }
            }
            Expect::AcceptedWithout(text) if code != 0 || o.stdout.contains(text.as_str()) => {
                return Err(format!("exit {code}, want 0 without {text:?} in stdout (the files skipped, not read)"));
            }
            Expect::Refused(needles) => {
                let allowed: &[i32] = if r.cmd == Cmd::Check { &[1, 2] } else { &[2] };
                if !allowed.contains(&code) {
                    return Err(format!("exit {code}, but this must be refused (exit {allowed:?}) naming {needles:?}"));
                }
                let lines = refusal_lines(o);
                // `list` names every kernel that does not compose, one line each.
                if code == 2 && lines.len() != 1 && r.cmd != Cmd::List {
                    return Err(format!("want exactly one error line, got {}", lines.len()));
                }
                match lines.iter().find(|l| needles.iter().all(|n| l.contains(n.as_str()))) {
                    Some(l) => Some(l.clone()),
                    None => return Err(format!("no refusal line holds all of {needles:?}")),
                }
            }
            _ => refusal_lines(o).into_iter().next(),
        };
        if let Some(rel) = &r.absent_after
            && std::fs::symlink_metadata(project.join(rel)).is_ok()
        {
            return Err(format!("{rel} exists after the run"));
        }
        if let Some(rel) = &r.real_folder_after
            && let Ok(m) = std::fs::symlink_metadata(project.join(rel))
            && !m.is_dir()
        {
            return Err(format!("{rel} is still not a real folder of vista's ({:?})", m.file_type()));
        }
        Ok(example)
    }

    /// The kept rounds of `class`: sub-case, canonical or not, seed.
    fn kept_rounds(class: &str) -> Vec<(usize, bool, u64)> {
        let mut out = Vec::new();
        for p in super::files(&repo().join("tests/fuzz"), "") {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
            if !name.starts_with(&format!("hostile-{class}-")) {
                continue;
            }
            let Ok(t) = std::fs::read_to_string(&p).map(|t| t.parse::<toml::Table>()) else { continue };
            let Ok(t) = t else { continue };
            let first = t.get("first").and_then(|v| v.as_bool()).unwrap_or(false);
            let subcase = t.get("subcase").and_then(|v| v.as_integer());
            let seed =
                t.get("seed").and_then(|v| v.as_str()).map(|s| u64::from_str_radix(s.trim_start_matches("0x"), 16));
            if let (Some(c), Some(Ok(s))) = (subcase, seed) {
                out.push((c as usize, first, s));
            }
        }
        out
    }

    fn keep_round(class: &str, subcase: usize, first: bool, round_seed: u64, what: &str) -> PathBuf {
        let p = repo().join("tests/fuzz").join(format!("hostile-{class}-{subcase}-{round_seed:016x}"));
        let _ = std::fs::create_dir_all(p.parent().expect("a parent"));
        let text = format!(
            "# A hostile-project round that failed (tests/fuzz.rs, mod hostile), replayed first by every run.\n\
             # {}\nclass = \"{class}\"\nsubcase = {subcase}\nfirst = {first}\nseed = \"{round_seed:#x}\"\n",
            what.replace('\n', " ")
        );
        let _ = std::fs::write(&p, text);
        p
    }

    /// Which round: its sub-case, and whether it is the sub-case's
    /// canonical first one.
    #[derive(Debug, Clone, Copy)]
    struct Shape {
        subcase: usize,
        first: bool,
    }

    /// What a class saw: shown at the end of its test.
    #[derive(Default)]
    struct Tally {
        rounds: usize,
        slowest: Duration,
        peak_rss_kb: u64,
        examples: std::collections::BTreeMap<String, String>,
    }

    /// Runs a class: `subcases` names each sub-case; `make` builds the
    /// round of sub-case `i` in `project` (a fresh copy of the template)
    /// with `outside` (a fresh folder outside it, holding a secret). The
    /// first round of each sub-case is its canonical one (`Shape::first`:
    /// the brief's sizes and depths), the others random.
    fn run_class(class: &str, subcases: &[&str], make: impl Fn(Shape, &mut Rng, &Path, &Path) -> Round) {
        let template = template();
        let mut rng = Rng((seed() ^ super::blake3_ish(class.as_bytes())).wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
        let n = rounds(subcases.len());
        let mut plan: Vec<(usize, bool, u64, bool)> =
            kept_rounds(class).into_iter().map(|(c, first, s)| (c, first, s, true)).collect();
        for i in 0..n {
            let subcase = if i < subcases.len() { i } else { rng.below(subcases.len()) };
            plan.push((subcase, i < subcases.len(), rng.next() | 1, false));
        }
        let mut tally = Tally::default();
        for (subcase, first, round_seed, replayed) in plan {
            if subcase >= subcases.len() {
                continue;
            }
            let project_dir = tempfile::tempdir().expect("a temp dir");
            let project = project_dir.path().join("p");
            copy_tree(template.path(), &project);
            let outside_dir = tempfile::tempdir().expect("a temp dir");
            let outside = outside_dir.path().to_path_buf();
            write(&outside, "secret.txt", format!("{SECRET}\n"));
            let mut r = Rng(round_seed);
            let round = make(Shape { subcase, first }, &mut r, &project, &outside);
            let mut watched = vec![outside.clone()];
            watched.extend(round.also_outside.iter().cloned());
            let before: Vec<_> = watched.iter().flat_map(|p| snapshot(p)).collect();
            let o = run_vista(&project, &round.env, &round.args, HANG);
            let after: Vec<_> = watched.iter().flat_map(|p| snapshot(p)).collect();
            let verdict = judge(&round, &o, &project, HANG).and_then(|ex| match before == after {
                true => Ok(ex),
                false => {
                    let changed: Vec<_> = after
                        .iter()
                        .filter(|a| !before.contains(a))
                        .map(|(p, k)| format!("{} ({k})", p.display()))
                        .collect();
                    Err(format!("changed what lies outside the project: {changed:?}"))
                }
            });
            tally.rounds += 1;
            tally.slowest = tally.slowest.max(o.elapsed);
            tally.peak_rss_kb = tally.peak_rss_kb.max(o.peak_rss_kb);
            match verdict {
                Ok(example) => {
                    let key = format!("{:<12} {}", subcases[subcase], round.what);
                    if let Some(line) = example {
                        tally.examples.entry(subcases[subcase].to_string()).or_insert(format!("{key}\n      {line}"));
                    }
                }
                Err(why) => {
                    let kept = match replayed {
                        true => None,
                        false => Some(keep_round(class, subcase, first, round_seed, &round.what)),
                    };
                    panic!(
                        "hostile {class} / {}: {}\n  vista {} (env {:?}) in {}\n  {why}\n  exit {:?} signal {:?} after {:.2?}, peak RSS {} MiB\n  \
                         stdout: {}\n  stderr: {}\n  reproduce: VISTA_FUZZ_SEED={} VISTA_FUZZ_ITERATIONS={} cargo test -p vista-cli --test fuzz hostile; {}",
                        subcases[subcase],
                        round.what,
                        round.args.join(" "),
                        round.env,
                        project.display(),
                        o.code,
                        o.signal,
                        o.elapsed,
                        o.peak_rss_kb / 1024,
                        tail(&o.stdout),
                        tail(&o.stderr),
                        seed(),
                        iterations(),
                        match kept {
                            Some(k) => format!("kept as {} (replayed first by every run)", k.display()),
                            None => "a kept round, replayed".into(),
                        }
                    );
                }
            }
        }
        eprintln!(
            "hostile {class}: {} rounds from seed {:#x}, slowest run {:.2?}, peak RSS {} MiB; one refusal per sub-case:",
            tally.rounds,
            seed(),
            tally.slowest,
            tally.peak_rss_kb / 1024
        );
        for line in tally.examples.values() {
            eprintln!("  {line}");
        }
    }

    fn tail(s: &str) -> String {
        let lines: Vec<&str> = s.lines().collect();
        lines[lines.len().saturating_sub(12)..].join("\n    ")
    }

    /// A command for `rel`: mostly one of `readers`, else any.
    fn commands(_rel: &str, _hostile: Hostile, readers: &[Cmd], rng: &mut Rng) -> Cmd {
        let ok: Vec<Cmd> = ALL.to_vec();
        // Mostly a command that reads the file (the interesting case).
        let reading: Vec<Cmd> = ok.iter().copied().filter(|c| readers.contains(c)).collect();
        match (rng.below(4), reading.is_empty()) {
            (0, _) | (_, true) => *rng.pick(&ok),
            _ => *rng.pick(&reading),
        }
    }

    /// Either walk up from the project or name it in VISTA_ROOT.
    fn root_env(rng: &mut Rng, project: &Path) -> Vec<(String, String)> {
        match rng.below(2) {
            0 => Vec::new(),
            _ => vec![("VISTA_ROOT".into(), project.display().to_string())],
        }
    }

    /// A link target: absolute, or relative to the link's folder.
    fn link_target(rng: &mut Rng, link: &Path, target: &Path) -> PathBuf {
        if rng.below(2) == 0 {
            return target.to_path_buf();
        }
        let parent = link.parent().expect("a parent");
        std::fs::create_dir_all(parent).expect("a folder");
        let from = parent.canonicalize().expect("a real folder");
        let to = target.canonicalize().unwrap_or_else(|_| target.to_path_buf());
        let common = from.components().zip(to.components()).take_while(|(a, b)| a == b).count();
        let mut rel = PathBuf::new();
        for _ in from.components().skip(common) {
            rel.push("..");
        }
        for c in to.components().skip(common) {
            rel.push(c);
        }
        rel
    }

    /// Class 1: a file or folder vista reads, a symlink out of the project
    /// (to a copy of itself, to a secret, to /etc/passwd) or inside it.
    #[test]
    fn symlinks_out_of_the_project_are_refused_and_inside_it_accepted() {
        let names: Vec<String> = READ_FILES
            .iter()
            .map(|f| f.rel.to_string())
            .chain(READ_FOLDERS.iter().map(|(rel, _, _)| format!("{rel}/")))
            .collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        run_class("symlink", &names, |shape, rng, project, outside| {
            let i = shape.subcase;
            let folder = i >= READ_FILES.len();
            let (rel, readers, how, needles) = match folder {
                false => (READ_FILES[i].rel, READ_FILES[i].readers, READ_FILES[i].how, &[][..]),
                true => {
                    let (rel, readers, needles) = READ_FOLDERS[i - READ_FILES.len()];
                    (rel, readers, How::Guarded, needles)
                }
            };
            let link = project.join(rel);
            let name = link.file_name().expect("a name").to_owned();
            let passwd = Path::new("/etc/passwd");
            // 0: a copy of itself outside (accepted, were the guard gone),
            // 1: a secret, 2: /etc/passwd, 3: a copy inside the project.
            let mut kind = rng.below(4);
            if folder && kind == 1 || kind == 2 && (folder || !passwd.is_file()) {
                kind = 0;
            }
            let mut also_outside = Vec::new();
            let target = match kind {
                0 | 3 => {
                    let base = if kind == 0 { outside.join("copy") } else { project.join("mirror") };
                    let to = base.join(&name);
                    match folder {
                        true => copy_tree(&link, &to),
                        false => {
                            std::fs::create_dir_all(&base).expect("a folder");
                            std::fs::copy(&link, &to).expect("a copy");
                        }
                    }
                    to
                }
                1 => outside.join("secret.txt"),
                _ => {
                    also_outside.push(passwd.to_path_buf());
                    passwd.to_path_buf()
                }
            };
            let target_shown = target.display().to_string();
            let at = link_target(rng, &link, &target);
            symlink(&at, &link);
            let cmd = commands(rel, Hostile::Outside, readers, rng);
            let expect = match (kind, readers.contains(&cmd), how) {
                // bless writes goldens only into real folders, even one
                // that a symlink inside the project leads to.
                (3, _, _) if rel == "golden" && cmd == Cmd::Bless => {
                    Expect::Refused(vec!["golden: is a symlink to".into(), "real folders".into()])
                }
                (3, _, _) => Expect::Accepted,
                // The kernels skipped: only the built-ins are listed.
                (_, false, _) if rel == "kernels" => Expect::AcceptedWithout("fuzz:".into()),
                (_, false, _) => Expect::Accepted,
                (_, true, How::Golden) => Expect::Survives,
                (_, true, _) if folder => Expect::Refused(needles.iter().map(|n| n.to_string()).collect()),
                (_, true, _) => Expect::Refused(vec![rel.to_string(), "outside the project".into()]),
            };
            let mut round = Round::new(format!("{rel} -> {} ({target_shown})", at.display()), cmd, expect);
            round.env = root_env(rng, project);
            round.also_outside = also_outside;
            round
        });
    }

    /// Folders (true) and files vista writes, where a symlink out of the
    /// project is planted.
    const WRITE_TARGETS: &[(&str, bool)] = &[
        ("golden/k", true),
        ("golden/w", true),
        ("target/vista-report/thumbs.d", true),
        ("target/vista-report/a", true),
        ("target/vista-report/b", true),
        ("target/vista-report/a/golden", true),
        ("target/vista-report/index.html", false),
        ("target/vista-report/results.json", false),
        ("target/vista-report/pending.toml", false),
        ("target/vista-report/a/actual.png", false),
        ("target/vista-report/thumbs.d/a.png", false),
        ("golden/k/a.png", false),
        ("golden/k/a.exr", false),
        ("golden/manifest.toml", false),
        ("render.png", false),
    ];

    /// Class 1 (writes): a folder or file vista writes, a symlink to a
    /// folder or file outside the project: vista refuses (goldens) or
    /// writes its own in its place (the report), and what lies outside
    /// stays byte-identical.
    #[test]
    fn symlinks_where_vista_writes_are_refused_or_replaced() {
        let names: Vec<&str> = WRITE_TARGETS.iter().map(|(rel, _)| *rel).collect();
        run_class("write", &names, |shape, rng, project, outside| {
            let (rel, folder) = WRITE_TARGETS[shape.subcase];
            let link = project.join(rel);
            // The cases render other pictures: check fails, bless changes goldens.
            let changed = rng.below(2) == 0;
            if changed {
                write(project, "golden/cases.toml", CASES_CHANGED);
            }
            let target = outside.join("planted");
            match (folder, link.is_dir(), link.is_file()) {
                (true, true, _) => copy_tree(&link, &target),
                (true, _, _) => write(&target, "a.png", SECRET),
                (false, _, true) if rng.below(2) == 0 => {
                    std::fs::copy(&link, &target).expect("a copy");
                }
                (false, _, _) => write(outside, "planted", SECRET),
            }
            let at = link_target(rng, &link, &target);
            symlink(&at, &link);
            let cmd = match rel {
                "render.png" => Cmd::RenderK,
                r if r.starts_with("golden/") => *rng.pick(&[Cmd::Bless, Cmd::Bless, Cmd::Check]),
                _ => Cmd::Check,
            };
            let expect = match (cmd, folder) {
                (Cmd::Bless, true) => Expect::Refused(vec![format!("{rel}: is a symlink to"), "real folders".into()]),
                // A golden file read through the link (a copy, or a secret
                // that does not decode): either way nothing is written there.
                _ if rel.starts_with("golden/") => Expect::Survives,
                (Cmd::Check, _) => Expect::Exit(if changed { 1 } else { 0 }),
                _ => Expect::Accepted,
            };
            let mut round = Round::new(
                format!("{rel} -> {}{}", at.display(), if changed { ", cases changed" } else { "" }),
                cmd,
                expect,
            );
            round.env = root_env(rng, project);
            // Where vista writes this run (thumbnails of passing cases, the
            // folders of failing ones), the planted link must be gone.
            let written = match rel {
                "target/vista-report/thumbs.d" => !changed,
                r => r.starts_with("target/") && changed,
            };
            if folder && written {
                round.real_folder_after = Some(rel.to_string());
            }
            round
        });
    }

    /// Classes 2 and 3: a FIFO (which blocks a reader forever) or a
    /// symlink to a device (`/dev/zero`, `/dev/urandom`, `/dev/null`:
    /// endless or empty) in place of a file vista reads: refused at once
    /// naming the path, without reading it (no hang, no memory blow-up).
    fn unreadable_class(class: &str, hostile: Hostile) {
        let names: Vec<&str> = READ_FILES.iter().map(|f| f.rel).collect();
        run_class(class, &names, |shape, rng, project, _outside| {
            let ReadFile { rel, readers, how } = READ_FILES[shape.subcase];
            let path = project.join(rel);
            let device = *rng.pick(&["/dev/zero", "/dev/urandom", "/dev/null"]);
            let what = match hostile {
                Hostile::Fifo => {
                    mkfifo(&path);
                    format!("{rel}: a FIFO")
                }
                _ => {
                    symlink(Path::new(device), &path);
                    format!("{rel} -> {device}")
                }
            };
            let cmd = commands(rel, hostile, readers, rng);
            let needle = match (hostile, how) {
                (Hostile::Fifo, _) => "is a FIFO; expected a regular file".to_string(),
                (_, How::Golden) => "is a device; expected a regular file".to_string(),
                _ => format!("resolves to {device}, outside the project"),
            };
            let expect = match (readers.contains(&cmd), how) {
                (false, _) => Expect::Accepted,
                // bless replaces an old golden it cannot read by rename:
                // the FIFO or link goes, nothing is read or written through it.
                // (The manifest it must read: that is refused.)
                (true, How::Golden) if cmd == Cmd::Bless && rel != "golden/manifest.toml" => Expect::Accepted,
                (true, _) => Expect::Refused(vec![rel.to_string(), needle]),
            };
            let mut round = Round::new(what, cmd, expect);
            round.env = root_env(rng, project);
            round
        });
    }

    #[test]
    fn fifos_in_place_of_read_files_are_refused_at_once() {
        unreadable_class("fifo", Hostile::Fifo);
    }

    #[test]
    fn devices_in_place_of_read_files_are_refused_unread() {
        unreadable_class("device", Hostile::Device);
    }

    /// PNG chunk CRC (CRC-32, as `zlib.crc32`).
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for b in bytes {
            c ^= u32::from(*b);
            for _ in 0..8 {
                c = if c & 1 == 1 { 0xedb8_8320 ^ (c >> 1) } else { c >> 1 };
            }
        }
        !c
    }

    /// A small PNG whose header says `w` x `h` (its pixels are not there).
    fn png_claiming(w: u32, h: u32, depth: u8) -> Vec<u8> {
        let chunk = |kind: &[u8], data: &[u8]| {
            let mut c = (data.len() as u32).to_be_bytes().to_vec();
            let body = [kind, data].concat();
            c.extend(&body);
            c.extend(crc32(&body).to_be_bytes());
            c
        };
        let mut ihdr = [w.to_be_bytes(), h.to_be_bytes()].concat();
        ihdr.extend([depth, 6, 0, 0, 0]);
        [
            b"\x89PNG\r\n\x1a\n".to_vec(),
            chunk(b"IHDR", &ihdr),
            chunk(b"IDAT", &[0x78, 0x9c, 0x63, 0, 0, 0, 1, 0, 1]),
            chunk(b"IEND", &[]),
        ]
        .concat()
    }

    fn edit(project: &Path, rel: &str, from: &str, to: &str) {
        let text = std::fs::read_to_string(project.join(rel)).expect("a project file");
        assert!(text.contains(from), "{rel} lacks {from:?}");
        write(project, rel, text.replacen(from, to, 1));
    }

    /// Class 4: shapes past the memory budget (`VISTA_MAX_BYTES`, mostly
    /// lowered to 1..200 MiB so that they are refused at once; the default
    /// 4 GiB where the shape passes it too) or the size limits, and
    /// headers that claim more than their file holds: refused before
    /// anything is allocated, never a panic or an out-of-memory kill.
    #[test]
    fn huge_shapes_are_refused_before_allocation() {
        const SUBCASES: &[&str] = &[
            "texture 16384^2",
            "3d texture",
            "buffer length",
            "size > 8192",
            "size > budget",
            "npy overflow",
            "npy tiny file",
            "png header",
            "golden png header",
            "buffer > binding limit",
        ];
        run_class("huge", SUBCASES, |shape, rng, project, _outside| {
            let (i, first) = (shape.subcase, shape.first);
            let low = ((1 + rng.below(200)) as u64) << 20;
            // Sub-cases past the default budget too run under it in their
            // canonical round and at times.
            let default_ok = i == 9 || matches!(i, 0 | 3 | 5 | 6 | 7) && (first || rng.below(3) == 0);
            let budget = if default_ok { 4u64 << 30 } else { low };
            // A device that grants the binding renders it: check would fail on the picture.
            let cmd =
                *rng.pick(if i == 9 { &[Cmd::Bless, Cmd::RenderK] } else { &[Cmd::Check, Cmd::Bless, Cmd::RenderK] });
            let over = format!("above the memory budget of {budget} bytes");
            let mut extra_args: Vec<String> = Vec::new();
            let (what, needles) = match i {
                0 => {
                    let [w, h] = match default_ok || first {
                        true => [16384, 16384],
                        false => [4097 + rng.below(12288), 4097 + rng.below(12288)],
                    };
                    edit(
                        project,
                        "kernels/k.toml",
                        "format = \"rgba32float\"",
                        &format!("format = \"rgba32float\"\nsize = [{w}, {h}]"),
                    );
                    (
                        format!("picture size = [{w}, {h}]"),
                        vec!["resource picture".into(), format!("a {w}x{h}x1 rgba32float texture needs"), over],
                    )
                }
                1 => {
                    let [x, y, z] = match first {
                        true => [512; 3],
                        false => [0; 3].map(|_| *rng.pick(&[512, 1024, 2048, 4096])),
                    };
                    let vol = format!(
                        "[[resource]]\nname = \"vol\"\nkind = \"texture\"\nformat = \"rgba32float\"\ndimension = \"3d\"\nsize = [{x}, {y}, {z}]\n\n[[pass]]"
                    );
                    edit(project, "kernels/k.toml", "[[pass]]", &vol);
                    (
                        format!("3d vol size = [{x}, {y}, {z}]"),
                        vec!["resource vol".into(), format!("a {x}x{y}x{z} rgba32float texture needs"), over],
                    )
                }
                2 => {
                    let n = if first { 268_435_456 } else { (1u64 << 26) + rng.below(3 << 26) as u64 };
                    edit(project, "kernels/k.toml", "file = \"inputs/w.npy\"", &format!("length = {n}"));
                    let needs = format!("{n} elements of 4 bytes needs {} bytes", 4 * n);
                    (format!("weights length = {n}"), vec!["resource weights".into(), needs, over])
                }
                3 => {
                    let [b1, b2, small] =
                        [8193 + rng.below(65536 - 8193), 8193 + rng.below(65536 - 8193), 1 + rng.below(8192)];
                    let (w, h, axis) = match rng.below(3) {
                        _ if first => (16384, 16384, "width"),
                        0 => (b1, small, "width"),
                        1 => (small, b1, "height"),
                        _ => (b1, b2, "width"),
                    };
                    let value = if axis == "width" { w } else { h };
                    let mut needles = vec![format!("{axis}={value} is out of range; allowed: [1, 8192]")];
                    if cmd == Cmd::RenderK {
                        extra_args = vec!["--size".into(), format!("{w}x{h}")];
                    } else {
                        edit(project, "golden/cases.toml", "size = \"8x8\"", &format!("size = \"{w}x{h}\""));
                        needles.push("case 'a'".into());
                    }
                    (format!("size {w}x{h}"), needles)
                }
                4 => {
                    let (w, h) = match first {
                        true => (8192, 8192),
                        false => (4096 + rng.below(4097), 4096 + rng.below(4097)),
                    };
                    if cmd == Cmd::RenderK {
                        extra_args = vec!["--size".into(), format!("{w}x{h}")];
                    } else {
                        edit(project, "golden/cases.toml", "size = \"8x8\"", &format!("size = \"{w}x{h}\""));
                    }
                    (
                        format!("size {w}x{h}"),
                        vec!["resource picture".into(), format!("a {w}x{h}x1 rgba32float texture needs"), over],
                    )
                }
                5 => {
                    let dims: Vec<u64> = (0..3).map(|_| (1u64 << 22) + rng.next() % (1u64 << 40)).collect();
                    let (rel, descr, shape) = match rng.below(2) {
                        _ if first => ("inputs/w.npy", "<f4", vec![1u64 << 32; 3]),
                        0 => ("inputs/w.npy", "<f4", dims),
                        _ => ("inputs/m.npy", "<u4", dims),
                    };
                    write(project, rel, vista_image::npy::encode_npy(descr, &shape, &[0; 16]));
                    (format!("{rel} shape {shape:?}"), vec![rel.into(), "overflows 64-bit byte counts".into()])
                }
                6 => {
                    let (rel, descr, shape) = match rng.below(2) {
                        _ if first => ("inputs/w.npy", "<f4", vec![1u64 << 40]),
                        0 => ("inputs/w.npy", "<f4", vec![(1u64 << 30) + rng.next() % (1u64 << 50)]),
                        _ => ("inputs/m.npy", "<u4", vec![1u64 << (15 + rng.below(10)), 1u64 << (15 + rng.below(10))]),
                    };
                    write(project, rel, vista_image::npy::encode_npy(descr, &shape, &[0; 16]));
                    let shown = format!("{shape:?}");
                    (
                        format!("{rel} shape {shown} in 16 bytes"),
                        vec![rel.into(), format!("16 data bytes for shape {shown} of {descr}")],
                    )
                }
                7 => {
                    let (w, h) = match first {
                        true => (65535, 65535),
                        false => (16385 + rng.below(65536 - 16385), 16385 + rng.below(65536 - 16385)),
                    };
                    let depth = *rng.pick(&[8u8, 16]);
                    write(project, "inputs/t.png", png_claiming(w as u32, h as u32, depth));
                    (
                        format!("inputs/t.png claims {w}x{h}x{depth}"),
                        vec![format!("inputs/t.png is a {w}x{h} PNG"), over],
                    )
                }
                8 => {
                    let (w, h) = (16385 + rng.below(65536 - 16385), 16385 + rng.below(65536 - 16385));
                    write(project, "golden/k/a.png", png_claiming(w as u32, h as u32, 16));
                    (
                        format!("golden/k/a.png claims {w}x{h}"),
                        vec!["golden/k/a.png".into(), "is not a valid PNG".into()],
                    )
                }
                _ => {
                    // Inside the default budget but past lavapipe's 128 MiB
                    // storage binding: the brief's 1 GiB in the canonical
                    // round (about 1 GiB of host memory), 128..256 MiB else.
                    let n = if first { 268_435_456 } else { (1u64 << 25) + 1 + rng.below(1 << 25) as u64 };
                    edit(project, "kernels/k.toml", "file = \"inputs/w.npy\"", &format!("length = {n}"));
                    (format!("weights length = {n}"), vec!["maxStorageBufferBindingSize".into()])
                }
            };
            let expect = match (i, cmd) {
                // A golden is read by check only; bless writes its own.
                (8, Cmd::Check) => Expect::Refused(needles),
                (8, _) => Expect::Accepted,
                (9, _) => Expect::Unsupported(needles[0].clone()),
                _ => Expect::Refused(needles),
            };
            let mut round = Round::new(format!("{what}, VISTA_MAX_BYTES={budget}"), cmd, expect);
            round.args.extend(extra_args);
            round.env = root_env(rng, project);
            if budget != 4u64 << 30 || rng.below(2) == 0 {
                round.env.push(("VISTA_MAX_BYTES".into(), budget.to_string()));
            }
            round
        });
    }

    /// A statement chaining `n` operators (a term per line at times).
    fn long_statement(rng: &mut Rng, n: usize) -> String {
        let op = *rng.pick(&[" + 0.0", " - 0.0", " * 1.0"]);
        let sep = if rng.below(3) == 0 { "\n" } else { "" };
        format!("\nconst TAU: f32 = 6.28{};\n", [sep, op].concat().repeat(n))
    }

    /// An expression nested `n` brackets deep.
    fn nested(rng: &mut Rng, n: usize) -> String {
        let (open, close) = match rng.below(3) {
            0 => ("(".repeat(n), ")".repeat(n)),
            1 => ("(-".repeat(n), ")".repeat(n)),
            _ => ("[(".repeat(n / 2 + 1), ")]".repeat(n / 2 + 1)),
        };
        format!("\nconst DEEP: f32 = {open}6.28{close};\n")
    }

    /// Class 5: an `#include` chain past 64 files, one statement chaining
    /// past 1024 operators, brackets nested past 256, in the kernel, an
    /// included file, an imported module or a WESL module: refused naming
    /// the limit before any parser sees the text, never a stack overflow.
    #[test]
    fn deep_includes_and_expressions_are_refused_not_a_stack_overflow() {
        const SUBCASES: &[&str] = &["include chain", "long statement", "nested brackets", "wesl 50000 terms"];
        const FILES: &[&str] = &[
            "shaders/k.wgsl",
            "shaders/inc/common.wgsl",
            "shaders/lib/util.wgsl",
            "shaders/wl/w.wesl",
            "shaders/wl/util.wesl",
        ];
        run_class("deep", SUBCASES, |shape, rng, project, _outside| {
            let (i, first) = (shape.subcase, shape.first);
            let rel = match i {
                0 => "shaders/k.wgsl",
                3 => "shaders/wl/w.wesl",
                _ => *rng.pick(FILES),
            };
            let (what, needles) = match i {
                0 => {
                    let n = if first { 3000 } else { 66 + rng.below(3000 - 66) };
                    let (open, close) = *rng.pick(&[("\"", "\""), ("<", ">"), ("", ""), ("", ".wgsl")]);
                    let include = |name: &str| format!("#include {open}{name}{close}\n");
                    edit(project, "shaders/k.wgsl", "#include \"common\"\n", &include("d0"));
                    for d in 0..n {
                        let next = if d + 1 < n { format!("d{}", d + 1) } else { "common".to_string() };
                        write(project, &format!("shaders/inc/d{d}.wgsl"), include(&next));
                    }
                    (
                        format!("#include chain {n} deep ({open}d1{close})"),
                        vec!["#include nested 65 deep".to_string(), "allowed: 64".into()],
                    )
                }
                1 | 3 => {
                    let n = match (i, first) {
                        (3, _) => 50_000,
                        (_, true) => 5000,
                        _ => 1025 + rng.below(50_000),
                    };
                    let text = std::fs::read_to_string(project.join(rel)).expect("a shader");
                    write(project, rel, text + &long_statement(rng, n));
                    (
                        format!("{rel}: a statement of {n} operators"),
                        vec![rel.into(), "one statement chains more than 1024 operators; allowed: 1024".into()],
                    )
                }
                _ => {
                    let n = if first { 300 } else { 257 + rng.below(5000) };
                    let text = std::fs::read_to_string(project.join(rel)).expect("a shader");
                    write(project, rel, text + &nested(rng, n));
                    (
                        format!("{rel}: brackets {n} deep"),
                        vec![rel.into(), "brackets nested 257 deep; allowed: 256".into()],
                    )
                }
            };
            let (own, other) =
                if rel.ends_with(".wesl") { (Cmd::RenderW, Cmd::RenderK) } else { (Cmd::RenderK, Cmd::RenderW) };
            let cmd = *rng.pick(&[Cmd::Check, Cmd::Bless, Cmd::List, own, own, other]);
            let expect = if cmd == other { Expect::Accepted } else { Expect::Refused(needles) };
            let mut round = Round::new(what, cmd, expect);
            round.env = root_env(rng, project);
            round
        });
    }

    /// Hostile inputs these classes found vista not handling, each fixed
    /// since: name, what it is, and what vista did then. Each runs as a
    /// fixed round (20 s watchdog) in `once_open_gaps_stay_closed`.
    pub(super) const ONCE_OPEN: &[(&str, &str, &str)] = &[
        (
            "bless-old-golden-fifo",
            "golden/k/a.png a FIFO, vista bless",
            "hangs: bless reads the old golden with std::fs::read (vista-golden bless.rs write_main_image)",
        ),
        (
            "bless-old-golden-device",
            "golden/k/a.exr -> /dev/zero, vista bless",
            "reads /dev/zero until the memory runs out (vista-golden bless.rs write_extra_files)",
        ),
        (
            "check-input-listing-fifo",
            "inputs/w.npy a FIFO, vista check",
            "hangs: the report's input listing reads it with read_npy (vista-golden run.rs), though the render refuses it",
        ),
        (
            "check-input-listing-device",
            "inputs/t.png -> /dev/zero, vista check",
            "reads /dev/zero until the memory runs out (vista-golden run.rs, vista_image::load)",
        ),
        (
            "check-input-listing-outside",
            "inputs/t.png -> a PNG outside the project, vista check",
            "the render refuses it, but the report copies the outside picture into target/vista-report/a/input.photo8.png",
        ),
        (
            "texture-npy-fifo",
            "inputs/m.npy (a texture's .npy) a FIFO, vista render k",
            "hangs: read_texture_npy reads it with read_npy, not through the guard (vista-render graph.rs)",
        ),
        (
            "texture-npy-outside",
            "inputs/m.npy -> a copy outside the project, vista render k",
            "exit 0: the outside file is read and rendered (vista-render graph.rs read_texture_npy)",
        ),
        (
            "png-header-overflow",
            "inputs/t.png whose IHDR claims 2147483647 x 2147483647, vista render k",
            "panics, exit 101: attempt to multiply with overflow at vista-render graph.rs:893 (w * h * 16)",
        ),
        (
            "vista-toml-fifo",
            "vista.toml a FIFO, vista list",
            "exit 0 as if there were no project (walk-up uses is_file); the file is never named",
        ),
        (
            "report-folder-outside",
            "target/vista-report -> a folder outside the project, vista check",
            "writes index.html, results.json, pending.toml and case folders into the outside folder",
        ),
    ];

    /// The round that once reproduced gap `name`, as it ends now.
    fn gap_round(name: &str, project: &Path, outside: &Path) -> Round {
        let refused = |needles: &[&str]| Expect::Refused(needles.iter().map(|n| n.to_string()).collect());
        let what = ONCE_OPEN.iter().find(|g| g.0 == name).map_or(name.to_string(), |g| g.1.to_string());
        let (cmd, expect) = match name {
            "bless-old-golden-fifo" => {
                mkfifo(&project.join("golden/k/a.png"));
                (Cmd::Bless, Expect::Survives)
            }
            "bless-old-golden-device" => {
                symlink(Path::new("/dev/zero"), &project.join("golden/k/a.exr"));
                (Cmd::Bless, Expect::Survives)
            }
            "check-input-listing-fifo" => {
                mkfifo(&project.join("inputs/w.npy"));
                (Cmd::Check, refused(&["inputs/w.npy", "is a FIFO"]))
            }
            "check-input-listing-device" => {
                symlink(Path::new("/dev/zero"), &project.join("inputs/t.png"));
                (Cmd::Check, refused(&["inputs/t.png", "/dev/zero"]))
            }
            "check-input-listing-outside" | "texture-npy-outside" => {
                let rel = if name == "texture-npy-outside" { "inputs/m.npy" } else { "inputs/t.png" };
                let copy = outside.join("copy");
                std::fs::copy(project.join(rel), &copy).expect("a copy");
                symlink(&copy, &project.join(rel));
                match name {
                    "texture-npy-outside" => (Cmd::RenderK, refused(&[rel, "outside the project"])),
                    _ => (Cmd::Check, refused(&[rel, "outside the project"])),
                }
            }
            "texture-npy-fifo" => {
                mkfifo(&project.join("inputs/m.npy"));
                (Cmd::RenderK, refused(&["inputs/m.npy", "is a FIFO"]))
            }
            "png-header-overflow" => {
                write(project, "inputs/t.png", png_claiming(2_147_483_647, 2_147_483_647, 16));
                (Cmd::RenderK, refused(&["inputs/t.png is a 2147483647x2147483647 PNG", "above the memory budget"]))
            }
            "vista-toml-fifo" => {
                mkfifo(&project.join("vista.toml"));
                (Cmd::List, refused(&["vista.toml", "is a FIFO"]))
            }
            "report-folder-outside" => {
                write(outside, "report/index.html", SECRET);
                write(project, "golden/cases.toml", CASES_CHANGED);
                symlink(&outside.join("report"), &project.join("target/vista-report"));
                (Cmd::Check, Expect::Survives)
            }
            other => panic!("no round for gap {other}"),
        };
        let mut round = Round::new(what, cmd, expect);
        if name == "check-input-listing-outside" {
            round.absent_after = Some("target/vista-report/a/input.photo8.png".into());
        }
        round
    }

    /// The gaps once open ([`ONCE_OPEN`]), each run as it ends now it is
    /// fixed (they hung, blew memory up or panicked); fails naming any
    /// that opens again.
    #[test]
    fn once_open_gaps_stay_closed() {
        let template = template();
        let limit = Duration::from_secs(20);
        let mut open = Vec::new();
        for (name, what, then) in ONCE_OPEN {
            let project_dir = tempfile::tempdir().expect("a temp dir");
            let project = project_dir.path().join("p");
            copy_tree(template.path(), &project);
            let outside_dir = tempfile::tempdir().expect("a temp dir");
            let outside = outside_dir.path().to_path_buf();
            write(&outside, "secret.txt", format!("{SECRET}\n"));
            let round = gap_round(name, &project, &outside);
            let before = snapshot(&outside);
            let o = run_vista(&project, &round.env, &round.args, limit);
            let verdict = judge(&round, &o, &project, limit).and_then(|_| match snapshot(&outside) == before {
                true => Ok(()),
                false => Err("changed what lies outside the project".into()),
            });
            if let Err(why) = verdict {
                eprintln!(
                    "gap {name} open again: {what}: {why} (exit {:?}, {:.1?})\n  as it once was: {then}",
                    o.code, o.elapsed
                );
                open.push(*name);
            }
        }
        assert!(open.is_empty(), "{} gaps open again: {}", open.len(), open.join(", "));
    }
}
