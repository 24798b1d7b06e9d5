#![deny(missing_docs)]
//! WGSL unit tests (`vista test`): `@test` functions in `*.test.wgsl` and `*.test.wesl`
//! files under `shaders/`, importing what they test as kernels do, with
//! the assertions of `#import wgsl_test` (WESL: `import wgsl_test::...`; `expect`, `expectEq`,
//! `expectNear`, `expectNearV2f`..`V4f`, `expectUlp`; shaders/lib/wgsl_test.wgsl).
//! Each file becomes one kernel: one pass per test (a compute entry of one
//! invocation), one results buffer, rendered on the project's engine like
//! any case ([`run_file`]); a failing assertion comes back with the
//! user's file, line and column and its values ([`Failure`]).
//!
//! Not for: goldens (`vista-golden`) or the run loop and printing (the
//! binary).

mod rewrite;
mod snapshot;

pub use rewrite::{
    Assertion, BUFFER_GROUP, Pattern, Rewritten, Site, Snapshot, TEXTURE_FORMAT, TestBuffer, TestFn, TestSampler,
    TestTexture, entry, fill_entry, rewrite,
};

use vista_render::{OutputValue, Renderer};

/// Failures a test keeps (the count goes on past them).
const KEPT: usize = 16;
/// Words of one kept failure: site, actual x4, expected x4, tolerance.
const RECORD: usize = 10;
/// Words of one test's row.
const ROW: usize = 1 + KEPT * RECORD;

/// One failed assertion, as the user wrote it.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// `file:line:col` of the call.
    pub at: String,
    /// `expectNear(actual 0.0796, expected 0.08, tol 0.0001)`.
    pub what: String,
}

/// One test's result.
#[derive(Debug, Clone, PartialEq)]
pub struct TestResult {
    /// `wgsl::<file stem>::<fn>`.
    pub id: String,
    /// Its failures (at most 16 kept); empty when it passed.
    pub failures: Vec<Failure>,
    /// Failed assertions in all (past those kept).
    pub failed: u32,
    /// Why it could not run (a compile error at the user's line, a hang
    /// the watchdog ended), when it did not.
    pub error: Option<String>,
}

impl TestResult {
    /// Whether every assertion held.
    pub fn passed(&self) -> bool {
        self.failed == 0 && self.error.is_none()
    }

    /// Why it failed, a line per failure: `shaders/<file>:line:col: what`,
    /// or the error that kept it from running.
    pub fn explain(&self) -> Vec<String> {
        if let Some(e) = &self.error {
            return vec![e.clone()];
        }
        let mut lines: Vec<String> = self.failures.iter().map(|f| format!("shaders/{}: {}", f.at, f.what)).collect();
        let more = self.failed as usize - self.failures.len();
        if more > 0 {
            lines.push(format!("and {more} more failed assertion{}", if more == 1 { "" } else { "s" }));
        }
        lines
    }
}

/// Whether `rel` (a path under `shaders/`) names a test file
/// (`*.test.wgsl`, or `*.test.wesl` importing as WESL does).
pub fn is_test_file(rel: &str) -> bool {
    vista_render::is_unit_test_file(rel)
}

/// The project's test files (`*.test.wgsl`, `*.test.wesl` under `shaders/`): each path
/// relative to it and its text, in path order.
pub fn test_files(project: &vista_project::Project) -> Result<Vec<(String, String)>, vista_project::ProjectError> {
    let mut files: Vec<(String, String)> =
        project.shader_files()?.into_iter().filter(|f| is_test_file(&f.rel)).map(|f| (f.rel, f.text)).collect();
    files.sort();
    Ok(files)
}

/// The id of test `name` of file `rel`: `wgsl::<stem>::<name>`.
pub fn test_id(rel: &str, name: &str) -> String {
    format!("wgsl::{}::{name}", rewrite::stem(rel))
}

/// The ids of file `rel`'s tests (`text` its contents), or the error that
/// keeps it from running.
pub fn list(rel: &str, text: &str) -> Result<Vec<String>, String> {
    let r = rewrite(text, wesl(rel))?;
    Ok(r.tests.iter().map(|t| &t.name).chain(r.snapshots.iter().map(|s| &s.name)).map(|n| test_id(rel, n)).collect())
}

/// `text` as a TOML basic string.
fn toml_string(text: &str) -> String {
    let escaped: String = text
        .chars()
        .map(|c| match c {
            '"' | '\\' => format!("\\{c}"),
            c if c.is_control() => format!("\\u{:04X}", c as u32),
            c => c.to_string(),
        })
        .collect();
    format!("\"{escaped}\"")
}

fn wesl(rel: &str) -> bool {
    rel.ends_with(".wesl")
}

/// The manifest of file `rel` rewritten, running the tests `which` (file
/// indexes): one pass each, each with its own zeroed copy of every
/// `@buffer`, the generated textures filled first, the results buffer
/// (a row per test of the file) the output.
fn manifest(rel: &str, rewritten: &Rewritten, which: &[usize]) -> String {
    let mut m = format!(
        "summary = \"the WGSL tests of {rel}\"\nshader = \"{rel}\"\n\n[[resource]]\nname = \"wgsl_test_results\"\n\
         kind = \"buffer\"\nlength = {}\n",
        rewritten.tests.len() * ROW
    );
    for &i in which {
        for b in &rewritten.buffers {
            m.push_str(&format!(
                "\n[[resource]]\nname = \"{}__{i}\"\nkind = \"buffer\"\nlength = {}\n",
                b.name, b.length
            ));
        }
    }
    for t in &rewritten.textures {
        m.push_str(&format!("\n[[resource]]\nname = \"{}\"\nkind = \"texture\"\n", t.name));
        match (&t.pattern, t.size) {
            (Pattern::File(path), _) => m.push_str(&format!("file = {}\n", toml_string(path))),
            (_, Some((w, h))) => m.push_str(&format!("format = \"{TEXTURE_FORMAT}\"\nsize = [{w}, {h}]\n")),
            (_, None) => {}
        }
    }
    for s in &rewritten.samplers {
        let filter = if s.linear { "linear" } else { "nearest" };
        m.push_str(&format!("\n[[resource]]\nname = \"{}\"\nkind = \"sampler\"\nfilter = \"{filter}\"\n", s.name));
    }
    // The generated textures are filled first, a texel per invocation.
    for (n, t) in rewritten.textures.iter().enumerate() {
        if let Some((w, h)) = t.size {
            let (entry, var) = fill_entry(n);
            m.push_str(&format!(
                "\n[[pass]]\nentry = \"{entry}\"\nworkgroups = [{}, {}, 1]\nbind = {{ {var} = \"{}\" }}\n",
                w.div_ceil(8),
                h.div_ceil(8),
                t.name
            ));
        }
    }
    for &i in which {
        let bind: Vec<String> = rewritten.buffers.iter().map(|b| format!("{0} = \"{0}__{i}\"", b.name)).collect();
        m.push_str(&format!("\n[[pass]]\nentry = \"{}\"\nworkgroups = [1, 1, 1]\n", entry(i)));
        if !bind.is_empty() {
            m.push_str(&format!("bind = {{ {} }}\n", bind.join(", ")));
        }
    }
    m.push_str("\n[[output]]\nresource = \"wgsl_test_results\"\n");
    m
}

/// Why a render of tests did not give their rows: the error as one line,
/// and whether the device's watchdog ended it.
struct NotRun {
    error: String,
    timeout: bool,
}

/// Renders tests `which` of the rewritten file `rel` on `gpu`: the results
/// buffer's words.
fn render_tests(gpu: &Renderer, rel: &str, rewritten: &Rewritten, which: &[usize]) -> Result<Vec<u32>, NotRun> {
    let not_run = |error: String| NotRun { error, timeout: false };
    let name = format!("wgsl-test-{}", rel.replace(['/', '.'], "-"));
    let kernel = vista_manifest::Kernel::from_manifest(&name, rel, &manifest(rel, rewritten, which))
        .map_err(|e| not_run(e.to_string()))?;
    let params = kernel.resolve(None, &[]).map_err(|e| not_run(e.to_string()))?;
    let rendered = vista_render::render_with(gpu, &kernel, &params, &[], 1, 1)
        .map_err(|e| NotRun { error: one_line(&e.to_string()), timeout: e.is_timeout() })?;
    match rendered.outputs.first().map(|o| &o.value) {
        Some(OutputValue::Buffer { bytes, .. }) => {
            Ok(bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect())
        }
        _ => Err(not_run("the results buffer did not come back".into())),
    }
}

/// `base` with file `rel` replaced by its rewrite (the base's own edits,
/// a mutant under test, stay).
fn with_rewrite<'a>(
    base: &Renderer<'a>,
    sources: &vista_render::Sources,
    rel: &str,
    rewritten: &Rewritten,
) -> Renderer<'a> {
    let mut edits = base.edits.clone();
    edits.push((rel.to_string(), rewritten.text.clone()));
    Renderer {
        ctx: base.ctx,
        worker: base.worker.clone(),
        shaders: sources.with_files("wgsl tests", &edits),
        edits,
        limits: base.limits,
        root: base.root.clone(),
    }
}

/// Runs the tests of file `rel` (`text` as the project has it) on `base`'s
/// engine, its file replaced by the rewrite in memory: every test's
/// result, in file order. A file that does not rewrite, compose or run
/// fails each of its tests with that error (one result named `*` if none
/// could be found). When the watchdog ends the file's run (a test that
/// hangs), each test runs again alone, so that only the one that hangs
/// fails for it.
pub fn run_file(base: &Renderer, sources: &vista_render::Sources, rel: &str, text: &str) -> Vec<TestResult> {
    run_file_with(base, sources, rel, text, false)
}

/// [`run_file`], and with `bless` each `@snapshot`'s render becomes its
/// golden (`golden/wgsl/<file stem>/<fn>.png`) instead of being judged.
pub fn run_file_with(
    base: &Renderer,
    sources: &vista_render::Sources,
    rel: &str,
    text: &str,
    bless: bool,
) -> Vec<TestResult> {
    let rewritten = match rewrite(text, wesl(rel)) {
        Ok(r) => r,
        Err(e) => return vec![broken(&test_id(rel, "*"), format!("{rel}:{e}"))],
    };
    let ids: Vec<String> = rewritten.tests.iter().map(|t| test_id(rel, &t.name)).collect();
    let gpu = with_rewrite(base, sources, rel, &rewritten);
    let row_of = |words: &[u32], i: usize, id: &str| {
        let row = &words[i * ROW..(i + 1) * ROW];
        let failures = row[1..]
            .chunks_exact(RECORD)
            .take((row[0] as usize).min(KEPT))
            .map(|r| failure(rel, &rewritten.sites, r))
            .collect();
        TestResult { id: id.to_string(), failures, failed: row[0], error: None }
    };
    let all: Vec<usize> = (0..ids.len()).collect();
    // A file of snapshots only has no test pass to render.
    let rendered = (!ids.is_empty()).then(|| render_tests(&gpu, rel, &rewritten, &all));
    let mut results: Vec<TestResult> = match rendered {
        None => Vec::new(),
        Some(Ok(words)) => ids.iter().enumerate().map(|(i, id)| row_of(&words, i, id)).collect(),
        Some(Err(e)) if e.timeout && ids.len() > 1 => ids
            .iter()
            .enumerate()
            .map(|(i, id)| match render_tests(&gpu, rel, &rewritten, &[i]) {
                Ok(words) => row_of(&words, i, id),
                Err(e) => broken(id, e.error),
            })
            .collect(),
        Some(Err(e)) => ids.iter().map(|id| broken(id, e.error.clone())).collect(),
    };
    for snap in &rewritten.snapshots {
        let id = test_id(rel, &snap.name);
        let result = match crate::snapshot::judge(&gpu, rel, snap, bless) {
            Ok(()) => TestResult { id, failures: Vec::new(), failed: 0, error: None },
            Err(e) => broken(&id, e),
        };
        results.push(result);
    }
    results
}

/// The WGSL lines and branch arms the tests of file `rel` execute: its
/// test pass run again with coverage counters (vista-render's `cover`), on
/// the rewrite, whose lines are the file's own. `@snapshot` draws are not
/// counted. An error names why the file could not be measured.
pub fn cover_file(
    base: &Renderer,
    sources: &vista_render::Sources,
    rel: &str,
    text: &str,
) -> Result<vista_coverage::Counts, String> {
    let rewritten = rewrite(text, wesl(rel)).map_err(|e| format!("{rel}:{e}"))?;
    if rewritten.tests.is_empty() {
        return Ok(vista_coverage::Counts::default());
    }
    let gpu = with_rewrite(base, sources, rel, &rewritten);
    let all: Vec<usize> = (0..rewritten.tests.len()).collect();
    let name = format!("wgsl-test-{}", rel.replace(['/', '.'], "-"));
    let kernel = vista_manifest::Kernel::from_manifest(&name, rel, &manifest(rel, &rewritten, &all))
        .map_err(|e| e.to_string())?;
    let params = kernel.resolve(None, &[]).map_err(|e| e.to_string())?;
    let run = vista_render::cover_with(&gpu, &kernel, &params, &[], 1, 1).map_err(|e| one_line(&e.to_string()))?;
    if !run.not_measured.is_empty() {
        return Err(run.not_measured.join("; "));
    }
    // The entries appended after the user's last line are vista's.
    let mut counts = run.counts;
    counts.keep_lines(&format!("shaders/{rel}"), text.lines().count() as u32);
    Ok(counts)
}

/// A compile error on one line: `path:line: message` (the column is the
/// rewritten line's, so it is left out), else the error's first line.
fn one_line(text: &str) -> String {
    match vista_render::compose_error_parts(text) {
        (Some(at), message) => {
            let at = at.rsplit_once(':').map_or(at, |(file_line, _col)| file_line);
            format!("{at}: {message}")
        }
        (None, _) => text.lines().next().unwrap_or_default().to_string(),
    }
}

fn broken(id: &str, error: String) -> TestResult {
    TestResult { id: id.to_string(), failures: Vec::new(), failed: 0, error: Some(error) }
}

/// A failure record (site, actual x4, expected x4, tolerance) as the user
/// reads it.
fn failure(rel: &str, sites: &[Site], r: &[u32]) -> Failure {
    let Some(site) = (r[0] as usize).checked_sub(1).and_then(|s| sites.get(s)) else {
        return Failure { at: rel.to_string(), what: format!("an assertion at unknown site {}", r[0]) };
    };
    let f = |w: u32| format_f32(f32::from_bits(w));
    let floats = |ws: &[u32], n: u8| match n {
        1 => f(ws[0]),
        n => format!("({})", ws[..n as usize].iter().map(|&w| f(w)).collect::<Vec<_>>().join(", ")),
    };
    let name = site.assertion.name();
    let what = match site.assertion {
        Assertion::Expect => format!("{name}(false)"),
        Assertion::Eq => format!("{name}(actual {}, expected {})", r[1] as i32, r[5] as i32),
        Assertion::EqU => format!("{name}(actual {}, expected {})", r[1], r[5]),
        Assertion::Near(n) => {
            format!("{name}(actual {}, expected {}, tol {})", floats(&r[1..5], n), floats(&r[5..9], n), f(r[9]))
        }
        Assertion::Ulp => format!("{name}(actual {}, expected {}, ulps {})", f(r[1]), f(r[5]), r[9]),
    };
    Failure { at: format!("{rel}:{}:{}", site.line, site.col), what }
}

/// An f32 as short as it reads back exactly.
fn format_f32(v: f32) -> String {
    let text = format!("{v}");
    match text.len() > 12 {
        true => format!("{v:e}"),
        false => text,
    }
}
