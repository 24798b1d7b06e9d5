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
