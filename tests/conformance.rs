//! vista's host layer against the WGSL and WebGPU specs (SPEC 18): every
//! probe of `tests/conformance/` (a vista project of its own) runs on
//! lavapipe, SwiftShader and headless Chromium, and its output's 32-bit
//! words must equal `tests/conformance/expected.toml`, which
//! `expected.py` derives from the specs (never from vista, never blessed).
//! A backend that differs from the spec in a known way is named there as a
//! `[[difference]]`, never hidden by a looser comparison. One test per
//! backend and probe (`conformance::<backend>::<kernel>[::<set>]`);
//! `tests/shaders.rs` checks that the table is what the script writes.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::allow_no_gpu;
use libtest_mimic::{Arguments, Trial};
use vista_gpu::Context;
use vista_render::OutputValue;

mod common;

const BACKENDS: [&str; 3] = ["lavapipe", "swiftshader", "browser"];

fn suite() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/conformance")
}

#[derive(serde::Deserialize)]
struct Table {
    probe: Vec<Probe>,
    #[serde(default)]
    difference: Vec<Difference>,
}

#[derive(serde::Deserialize, Clone)]
struct Probe {
    kernel: String,
    set: toml::Table,
    /// Read back in order: a buffer's 32-bit words, a texture's f32 bits
    /// (r, g, b, a per texel, rows top to bottom).
    outputs: Vec<String>,
    why: String,
    words: Vec<u32>,
}

/// A documented way a backend differs from the spec on one probe: its
/// words are expected as listed instead.
#[derive(serde::Deserialize, Clone)]
struct Difference {
    backend: String,
    kernel: String,
    #[serde(default)]
    set: toml::Table,
    words: Vec<u32>,
    reason: String,
}

fn table() -> Table {
    let path = suite().join("expected.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The backend's context, made once per process.
fn context(backend: usize) -> Result<&'static Context, String> {
    static CONTEXTS: [OnceLock<Result<Context, String>>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    CONTEXTS[backend].get_or_init(|| common::backend_context(BACKENDS[backend])).as_ref().map_err(Clone::clone)
}

fn set_pairs(set: &toml::Table) -> Vec<(String, String)> {
    set.iter().map(|(k, v)| (k.clone(), v.to_string())).collect()
}

fn set_label(set: &toml::Table) -> String {
    set.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(",")
}

/// Renders one probe on one backend; its output's words.
fn words_of(backend: usize, probe: &Probe) -> Result<Vec<u32>, String> {
    let out = common::render_in_project(context(backend)?, &suite(), &probe.kernel, &set_pairs(&probe.set), (8, 8))?;
    let mut words = Vec::new();
    for name in &probe.outputs {
        let output = out
            .outputs
            .iter()
            .find(|o| &o.name == name)
            .ok_or_else(|| format!("{}: no output {name}", probe.kernel))?;
        match &output.value {
            OutputValue::Buffer { bytes, .. } => {
                words.extend(bytes.chunks_exact(4).map(|w| u32::from_le_bytes(w.try_into().expect("4 bytes"))))
            }
            OutputValue::Texture { raw, .. } => words.extend(raw.data.iter().flatten().map(|v| v.to_bits())),
        }
    }
    Ok(words)
}

fn check(backend: usize, probe: &Probe, differences: &[Difference]) -> Result<(), String> {
    let known =
        differences.iter().find(|d| d.backend == BACKENDS[backend] && d.kernel == probe.kernel && d.set == probe.set);
    let want = known.map_or(&probe.words, |d| &d.words);
    let got = words_of(backend, probe)?;
    if &got == want {
        return Ok(());
    }
    let first = got.iter().zip(want).position(|(a, b)| a != b).unwrap_or(got.len().min(want.len()));
    Err(format!(
        "{} {} on {}: word {first} is {:?}, the spec says {:?}\n  got  {got:?}\n  want {want:?}\n  ({})",
        probe.kernel,
        set_label(&probe.set),
        BACKENDS[backend],
        got.get(first),
        want.get(first),
        known.map_or(probe.why.as_str(), |d| d.reason.as_str()),
    ))
}

fn main() {
    let args = Arguments::from_args();
    let table = table();
    let missing: Vec<String> = if args.list { Vec::new() } else { (0..3).filter_map(|b| context(b).err()).collect() };
    let skip = !missing.is_empty() && allow_no_gpu();
    if skip {
        eprintln!("\n!!! VISTA_ALLOW_NO_GPU=1 and a backend is missing: {}", missing.join("; "));
        eprintln!("!!! SKIPPED {} conformance probes (reported ignored)\n", table.probe.len() * 3);
    }
    let mut trials = Vec::new();
    for (b, backend) in BACKENDS.iter().enumerate() {
        for probe in &table.probe {
            let (probe, differences) = (probe.clone(), table.difference.clone());
            let label = set_label(&probe.set);
            let name = match label.is_empty() {
                true => format!("conformance::{backend}::{}", probe.kernel),
                false => format!("conformance::{backend}::{}::{label}", probe.kernel),
            };
            trials.push(
                Trial::test(name, move || check(b, &probe, &differences).map_err(Into::into)).with_ignored_flag(skip),
            );
        }
    }
    libtest_mimic::run(&args, trials).exit()
}
