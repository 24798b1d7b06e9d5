//! `vista mutate` (SPEC 12): how much of a kernel's WGSL the suite really
//! checks. Every single-token mutant ([`mutants`]) of the kernel file and
//! the lib modules in its import closure is composed in memory (the
//! project's files are never written, not even to a temporary copy) and run
//! against the kernel's golden cases, each checked by
//! `vista_golden::check_case` (what `vista check` runs on a case: the
//! backend's own golden where it has one, every metric, threshold and
//! guard), and the
//! kernel's GPU-vs-CPU agreement settings at the bounds the agreement tests
//! use (`vista_golden::agreement`), stopping at the first failure.
//!
//! Before a case runs, the mutant's shaders for it are composed and
//! written back by naga: a case whose shaders all come out as the
//! unmutated program (the mutant lies in code the case's defs leave out)
//! is not run, its render being the unmutated one. [`Judge::goldens_only`]
//! makes the golden cases the only detector.
//!
//! Outcomes: killed (naming what killed it), survived, timeout (the GPU
//! watchdog fired), stillborn (naga or the pipeline rejects the mutant; not
//! counted). A survivor bit-identical to the unmutated render on every case
//! is flagged `equivalent?` and left out of the score (SPEC 12): it is
//! truly equivalent or in code no case reaches, which the list says apart.
//! Score = killed / (killed + survived - equivalent?).

#![deny(missing_docs)]

use std::collections::BTreeMap;
use std::sync::Arc;

use rand::seq::SliceRandom;
use rand_pcg::Pcg32;
use vista_golden::agreement::{self, Setting, SettingError};
use vista_golden::{Case, CheckOptions, GoldenError, Manifest, Store, Verdict};
use vista_kernels::Kernel;
use vista_project::{Project, SourceFile};
use vista_render::{Renderer, ShaderSet};

pub mod mutants;
pub use mutants::{Mutant, mutants};

/// What happened to one mutant.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MutantReport {
    /// The kernel whose suite ran it.
    pub kernel: String,
    /// Where and what.
    #[serde(flatten)]
    pub mutant: Mutant,
    /// killed | survived | not covered (a survivor on a line no case of
    /// its kernel executes) | timeout | stillborn | argued.
    pub outcome: String,
    /// The case id, `cpu-reference`, or the unit test (`wgsl::<file>::<fn>`)
    /// that killed it.
    pub killed_by: Option<String>,
    /// What the killer saw: the first problem of the case's verdict, or the
    /// agreement setting and its figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// A survivor whose raw output is bit-identical to the unmutated render
    /// on every case: truly equivalent, or code no case reaches.
    #[serde(rename = "equivalent?")]
    pub equivalent: bool,
    /// Detectors run before the verdict (cases, then the CPU check).
    pub cases_run: usize,
    /// For `argued` mutants: why no output can differ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub argument: Option<String>,
}

/// A survivor argued equivalent in the project's list (`--equivalent
/// FILE`, TOML `[[mutant]]` tables): excluded from the score, listed apart.
/// It matches by kernel, file, line, column and replacement, so an edit that
/// moves the code makes the mutant count as a survivor again.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Argued {
    /// The kernel whose suite ran it.
    pub kernel: String,
    /// Shader file, relative to `shaders/`.
    pub file: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column.
    pub col: u32,
    /// The replacement text (empty for a dropped statement).
    pub after: String,
    /// One line: why no output can differ.
    pub why: String,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ArguedFile {
    #[serde(default)]
    mutant: Vec<Argued>,
}

/// Parses an `--equivalent` list; errors name line and column.
pub fn parse_argued(text: &str) -> Result<Vec<Argued>, String> {
    let f: ArguedFile = toml::from_str(text).map_err(|e| vista_project::one_line_toml_error(text, &e))?;
    if let Some(a) = f.mutant.iter().find(|a| a.why.trim().is_empty()) {
        return Err(format!("{}:{}:{}: an argued equivalent needs a why", a.file, a.line, a.col));
    }
    Ok(f.mutant)
}

/// Marks survivors that `argued` names as `argued` (with the argument);
/// returns the entries that matched no survivor (stale arguments).
pub fn apply_argued(mutants: &mut [MutantReport], argued: &[Argued]) -> Vec<Argued> {
    let mut unused = Vec::new();
    for a in argued {
        let hit = mutants.iter_mut().find(|m| {
            m.outcome == "survived"
                && (m.kernel.as_str(), m.mutant.file.as_str(), m.mutant.line, m.mutant.col, m.mutant.after.as_str())
                    == (a.kernel.as_str(), a.file.as_str(), a.line, a.col, a.after.as_str())
        });
        match hit {
            Some(m) => {
                m.outcome = "argued".into();
                m.argument = Some(a.why.clone());
            }
            None => unused.push(a.clone()),
        }
    }
    unused
}

/// Counts and score of one kernel (or all).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Score {
    /// Mutants killed.
    pub killed: usize,
    /// Mutants that survived every detector.
    pub survived: usize,
    /// Survivors flagged `equivalent?`.
    pub equivalent: usize,
    /// Mutants the watchdog stopped.
    pub timeout: usize,
    /// Mutants naga or the pipeline rejected (not counted).
    pub stillborn: usize,
    /// Survivors argued equivalent in the project's list (not counted).
    #[serde(default)]
    pub argued: usize,
    /// Survivors on a line no case of the kernel executes (counted as
    /// survivors in the score: the suite cannot see them).
    #[serde(default)]
    pub not_covered: usize,
    /// killed / (killed + survived + not covered - equivalent?); None
    /// without any.
    pub score: Option<f64>,
}

/// A whole run (or a merge of partitions).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Report {
    /// The sampling seed.
    pub seed: u64,
    /// Mutants per kernel (None: all).
    pub sample: Option<usize>,
    /// Partitions this report holds (`1/1` for a whole run).
    pub partitions: Vec<String>,
    /// killed / (killed + survived - equivalent?) over every kernel.
    pub score: Option<f64>,
    /// Per kernel.
    pub kernels: BTreeMap<String, Score>,
    /// Every mutant run, in plan order.
    pub mutants: Vec<MutantReport>,
}

impl Report {
    /// A report from mutant results, scores computed.
    pub fn new(seed: u64, sample: Option<usize>, partitions: Vec<String>, mutants: Vec<MutantReport>) -> Report {
        let mut kernels: BTreeMap<String, Score> = BTreeMap::new();
        let mut all = Score::default();
        for m in &mutants {
            for s in [kernels.entry(m.kernel.clone()).or_default(), &mut all] {
                match m.outcome.as_str() {
                    "killed" => s.killed += 1,
                    "survived" => {
                        s.survived += 1;
                        s.equivalent += m.equivalent as usize;
                    }
                    "not covered" => s.not_covered += 1,
                    "timeout" => s.timeout += 1,
                    "argued" => s.argued += 1,
                    _ => s.stillborn += 1,
                }
            }
        }
        let finish = |s: &mut Score| {
            // `equivalent?` survivors are listed, not scored (SPEC 12).
            let n = s.killed + s.survived + s.not_covered - s.equivalent;
            s.score = (n > 0).then(|| s.killed as f64 / n as f64);
        };
        kernels.values_mut().for_each(finish);
        finish(&mut all);
        Report { seed, sample, partitions, score: all.score, kernels, mutants }
    }

    /// Joins partition reports of one plan into one report. Refuses reports
    /// of different seeds or samples, and a partition given twice.
    pub fn merge(parts: Vec<Report>) -> Result<Report, String> {
        let first = parts.first().ok_or("nothing to merge")?;
        let (seed, sample) = (first.seed, first.sample);
        let mut partitions = Vec::new();
        let mut mutants = Vec::new();
        for p in parts {
            if (p.seed, p.sample) != (seed, sample) {
                return Err(format!(
                    "reports of different runs: seed {} sample {:?} vs seed {seed} sample {sample:?}",
                    p.seed, p.sample
                ));
            }
            for part in &p.partitions {
                if partitions.contains(part) {
                    return Err(format!("partition {part} given twice"));
                }
            }
            partitions.extend(p.partitions);
            mutants.extend(p.mutants);
        }
        mutants.sort_by(|a, b| {
            (&a.kernel, &a.mutant.file, a.mutant.line, a.mutant.col, &a.mutant.operator, &a.mutant.after).cmp(&(
                &b.kernel,
                &b.mutant.file,
                b.mutant.line,
                b.mutant.col,
                &b.mutant.operator,
                &b.mutant.after,
            ))
        });
        partitions.sort();
        Ok(Report::new(seed, sample, partitions, mutants))
    }
}

impl Report {}

/// What to run.
#[derive(Debug, Clone)]
pub struct Options {
    /// Only this kernel.
    pub kernel: Option<String>,
    /// Only the cases matching this glob (and their kernels).
    pub case_glob: Option<String>,
    /// Mutants per kernel, sampled with `seed` (None: all).
    pub sample: Option<usize>,
    /// Sampling seed.
    pub seed: u64,
    /// Worker threads sharing the device.
    pub jobs: usize,
    /// This run's slice of the plan: (k, n), 1 <= k <= n.
    pub partition: (usize, usize),
}

/// Parses nextest's partition syntax: `k/n` or `count:k/n`.
pub fn parse_partition(text: &str) -> Result<(usize, usize), String> {
    let bad = || format!("--partition {text} is not valid; expected k/n or count:k/n with 1 <= k <= n");
    let body = text.strip_prefix("count:").unwrap_or(text);
    let (k, n) = body.split_once('/').ok_or_else(bad)?;
    let (k, n): (usize, usize) = (k.parse().map_err(|_| bad())?, n.parse().map_err(|_| bad())?);
    if k == 0 || n == 0 || k > n {
        return Err(bad());
    }
    Ok((k, n))
}

/// One planned mutant.
#[derive(Debug, Clone)]
pub struct Planned {
    /// Whose suite runs it.
    pub kernel: Arc<Kernel>,
    /// The change.
    pub mutant: Mutant,
}

/// The WGSL files the project's `[source]` tables name outside `shaders/`
/// (include folders, joined files, WESL packages), by path under the root.
pub fn outside_files(project: &Project) -> Result<Vec<SourceFile>, GoldenError> {
    let mut out: Vec<SourceFile> = Vec::new();
    for p in vista_render::paths_outside_shaders(project)? {
        for f in project.files_under(&p, &["wgsl", "wesl"])? {
            if !out.iter().any(|o| o.rel == f.rel) {
                out.push(f);
            }
        }
    }
    Ok(out)
}

/// The deterministic plan: per kernel (sorted by name), every mutant of its
/// import closure in source order, shuffled by `seed` and cut to `sample`;
/// then this partition's slice (every n-th from the k-th). Only functions
/// the kernel's entry points (each pass's, a draw's vertex entry too) reach (by name, through calls, across the closure)
/// are mutated: a function it never calls cannot change its output, so its
/// mutants would only be `equivalent?` noise.
pub fn plan(
    files: &[SourceFile],
    shaders: &ShaderSet,
    kernels: &[Arc<Kernel>],
    opts: &Options,
) -> Result<Vec<Planned>, GoldenError> {
    let mut kernels = kernels.to_vec();
    kernels.sort_by(|a, b| a.name().cmp(b.name()));
    let mut all = Vec::new();
    for k in kernels {
        // Every file any pass reaches, and every pass's entry point as a root.
        let mut closure: Vec<&SourceFile> = Vec::new();
        for shader in k.shader_units() {
            for rel in shaders.import_closure(&shader)? {
                let f = files.iter().find(|f| f.rel == rel).expect("the closure names files of the set");
                if !closure.iter().any(|c| c.rel == f.rel) {
                    closure.push(f);
                }
            }
        }
        // A draw's vertex entry is a root too.
        let roots: Vec<(&str, &str)> = k.graph().passes.iter().flat_map(|p| p.entries(k.shader())).collect();
        let fns: Vec<(&str, mutants::Function)> = closure
            .iter()
            .flat_map(|f| mutants::functions(&f.text).into_iter().map(move |g| (f.rel.as_str(), g)))
            .collect();
        let mut reached: Vec<bool> =
            fns.iter().map(|(rel, g)| roots.iter().any(|(file, entry)| rel == file && g.name == *entry)).collect();
        let mut work: Vec<String> =
            fns.iter().zip(&reached).filter(|(_, r)| **r).flat_map(|((_, g), _)| g.calls.clone()).collect();
        while let Some(name) = work.pop() {
            for (i, (_, g)) in fns.iter().enumerate() {
                if !reached[i] && g.name == name {
                    reached[i] = true;
                    work.extend(g.calls.iter().cloned());
                }
            }
        }
        let live = |m: &Mutant| {
            fns.iter()
                .zip(&reached)
                .any(|((rel, g), r)| *r && *rel == m.file && g.body.0 <= m.start && m.end <= g.body.1)
        };
        let mut list = Vec::new();
        for f in &closure {
            list.extend(mutants(&f.rel, &f.text).into_iter().filter(|m| live(m)));
        }
        let name_hash = k.name().bytes().fold(0u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64));
        list.shuffle(&mut Pcg32::new(opts.seed ^ name_hash, 0x0a02_bdbf_7bb3_c0a7));
        if let Some(n) = opts.sample {
            list.truncate(n);
        }
        all.extend(list.into_iter().map(|mutant| Planned { kernel: k.clone(), mutant }));
    }
    let (k, n) = opts.partition;
    Ok(all.into_iter().enumerate().filter(|(i, _)| i % n == k - 1).map(|(_, p)| p).collect())
}

/// One golden case as the unmutated kernel renders it: the case, the
/// unmutated raw output's hash, and each shader its passes compose with
/// its unmutated program ([`ShaderSet::program`]; none where it could not
/// be planned or written here).
struct CaseBaseline<'a> {
    case: &'a Case,
    raw_hash: String,
    programs: Option<Vec<(String, String)>>,
}

/// What an unmutated kernel looks like to its detectors: its golden cases
/// and, for a built-in kernel with a CPU reference, its agreement settings
/// (the unmutated GPU render's hash of each).
struct Baseline<'a> {
    cases: Vec<CaseBaseline<'a>>,
    settings: Vec<(&'static Setting, String)>,
}

/// A mutant's case is checked once: its verdict is the first render's, and
/// the unmutated render was already shown deterministic by bless.
const ONCE: CheckOptions = CheckOptions { twice: false, images_of_passing: false };

/// The unmutated kernel through the same detectors a mutant meets. Every
/// case must have a readable golden and pass, and every agreement setting
/// hold its bound: otherwise the suite itself fails and no mutant's
/// verdict would mean anything, so that is an error, not a skip.
fn baseline<'a>(
    gpu: &Renderer,
    store: &Store,
    manifest: &Manifest,
    kernel: &Kernel,
    cases: &[&'a Case],
) -> Result<Baseline<'a>, GoldenError> {
    let mut out = Vec::new();
    for c in cases.iter().filter(|c| c.kernel.name() == kernel.name()) {
        let checked = vista_golden::check_case(gpu, store, manifest, c, &ONCE);
        let o = &checked.outcome;
        if o.verdict == Verdict::Missing {
            let (path, _) = store.golden_for(c, gpu.backend());
            return Err(GoldenError::BadInput(format!(
                "case {}: golden {} cannot be read (it does not exist); mutation testing judges every case like \
                 vista check, so bless it first: {}",
                c.id,
                path.display(),
                c.bless_command()
            )));
        }
        if !o.passed() {
            return Err(GoldenError::BadInput(format!(
                "case {} fails before any mutation ({}); fix or bless it before mutating",
                c.id,
                o.problems.join("; ")
            )));
        }
        out.push(CaseBaseline {
            case: c,
            raw_hash: checked.raw_hash.unwrap_or_default(),
            programs: programs_of(gpu, c),
        });
    }
    let mut settings = Vec::new();
    if kernel.has_reference() {
        for s in agreement::settings().iter().filter(|s| s.kernel == kernel.name()) {
            let j = agreement::judge_setting(gpu, s).map_err(|e| GoldenError::BadInput(e.to_string()))?;
            if let Some(broken) = j.broken {
                return Err(GoldenError::BadInput(format!(
                    "the unmutated kernel breaks its GPU-vs-CPU bound on {}: {broken}",
                    gpu.backend()
                )));
            }
            settings.push((s, j.gpu_hash));
        }
    }
    Ok(Baseline { cases: out, settings })
}

/// The shaders (with their defs) the passes of `c`'s plan compose, each
/// with its program.
fn programs_of(gpu: &Renderer, c: &Case) -> Option<Vec<(String, String)>> {
    let plan = vista_render::plan(
        &gpu.shaders,
        gpu.root.as_deref(),
        &c.kernel,
        &c.params,
        &c.inputs,
        c.width,
        c.height,
        &gpu.limits,
    )
    .ok()?;
    let mut names: Vec<String> = plan
        .passes
        .iter()
        .flat_map(|p| std::iter::once(p.shader.clone()).chain(p.raster.as_ref().and_then(|r| r.vertex_shader.clone())))
        .collect();
    names.sort();
    names.dedup();
    names.into_iter().map(|n| gpu.shaders.program(&n).ok().map(|p| (n, p))).collect()
}

/// Whether the mutant composes each shader of a case to its unmutated
/// program (`programs`, the baseline's): the mutant lies in code those
/// shaders' defs leave out, so the case's render is the unmutated one and
/// need not run. `written`: the mutant's programs, each written once.
fn same_programs(
    mutated: &ShaderSet,
    programs: Option<&Vec<(String, String)>>,
    written: &mut BTreeMap<String, Option<String>>,
) -> bool {
    programs.is_some_and(|programs| {
        programs.iter().all(|(n, unmutated)| {
            let mine = written.entry(n.clone()).or_insert_with(|| mutated.program(n).ok());
            mine.as_ref() == Some(unmutated)
        })
    })
}

/// Runs one mutant against the detectors; the first failure kills it.
/// `goldens_only`: the golden cases are the only detector.
fn judge(
    gpu: &Renderer,
    store: &Store,
    manifest: &Manifest,
    kernel: &Kernel,
    base: &Baseline,
    m: &Mutant,
    goldens_only: bool,
) -> MutantReport {
    let report = |outcome: &str, killed_by: Option<(String, String)>, equivalent: bool, cases_run: usize| {
        let (killed_by, reason) = killed_by.unzip();
        MutantReport {
            kernel: kernel.name().to_string(),
            mutant: m.clone(),
            outcome: outcome.to_string(),
            killed_by,
            reason,
            equivalent,
            cases_run,
            argument: None,
        }
    };
    let failed = |timed_out: bool| if timed_out { "timeout" } else { "stillborn" };
    let mut identical = true;
    let mut run = 0;
    let mut written = BTreeMap::new();
    for b in &base.cases {
        let c = b.case;
        if same_programs(&gpu.shaders, b.programs.as_ref(), &mut written) {
            continue;
        }
        run += 1;
        let checked = vista_golden::check_case(gpu, store, manifest, c, &ONCE);
        // A render that failed is the mutant's failure to run, not a kill.
        let Some(raw_hash) = &checked.raw_hash else {
            return report(failed(checked.timed_out), None, false, run);
        };
        identical &= *raw_hash == b.raw_hash;
        let o = &checked.outcome;
        if !o.passed() {
            let why = o.problems.first().cloned().unwrap_or_default();
            return report("killed", Some((c.id.clone(), why)), false, run);
        }
    }
    let settings = if goldens_only { &[][..] } else { &base.settings[..] };
    if run == 0 && settings.is_empty() {
        let mut r = report("survived", None, true, 0);
        r.reason = Some("every case composes the unmutated program: the mutant lies in code its defs leave out".into());
        return r;
    }
    for (s, hash) in settings {
        run += 1;
        match agreement::judge_setting(gpu, s) {
            Ok(j) => {
                identical &= j.gpu_hash == *hash;
                if let Some(broken) = j.broken {
                    return report("killed", Some(("cpu-reference".into(), broken)), false, run);
                }
            }
            Err(SettingError::Render { source, .. }) => return report(failed(source.is_timeout()), None, false, run),
            Err(SettingError::Unjudgeable(why)) => {
                return report("killed", Some(("cpu-reference".into(), why)), false, run);
            }
        }
    }
    report("survived", None, identical, run)
}

/// What judging a plan's mutants needs, read once: the device, the
/// unmutated shaders and limits (`base`; its context's watchdog should be
/// short: a mutant can loop for ever), each mutant's file as the project
/// has it, and each planned kernel's [`Baseline`]. The project's files are
/// only read. vista-check's run loop judges each mutant with
/// [`Judge::judge`].
pub struct Judge<'a> {
    base: &'a Renderer<'a>,
    store: &'a Store,
    manifest: Manifest,
    sources: vista_render::Sources,
    texts: BTreeMap<String, String>,
    baselines: BTreeMap<String, Baseline<'a>>,
    /// The project's WGSL unit test files: a detector after the goldens.
    unit_tests: Vec<UnitTestFile>,
    /// Each kernel's lines and arms its cases execute (a coverage run of
    /// every case); none where a run could not measure them.
    coverage: BTreeMap<String, Option<vista_coverage::Counts>>,
    /// The golden cases are the only detector ([`Judge::goldens_only`]).
    goldens_only: bool,
}

/// A WGSL unit test file (`*.test.wgsl`, `*.test.wesl`) and the files its tests reach.
struct UnitTestFile {
    /// Its path under shaders/.
    rel: String,
    text: String,
    /// Every file its composition reads (itself and the modules it
    /// imports); `None` where they cannot be listed: it runs for every mutant.
    reaches: Option<std::collections::BTreeSet<String>>,
}

impl<'a> Judge<'a> {
    /// Reads the project's shaders and checks every planned kernel's
    /// unmutated baseline (an error if the suite itself fails).
    pub fn new(
        base: &'a Renderer<'a>,
        project: &Project,
        store: &'a Store,
        cases: &[&'a Case],
        planned: &[Planned],
    ) -> Result<Judge<'a>, GoldenError> {
        let sources = vista_render::Sources::of(project)?;
        // Each mutant's file as the project has it (under shaders/, or
        // outside it where a [source] reaches).
        let mut texts: BTreeMap<String, String> =
            project.shader_files()?.into_iter().map(|f| (f.rel, f.text)).collect();
        texts.extend(outside_files(project)?.into_iter().map(|f| (f.rel, f.text)));
        let manifest = store.manifest()?;
        let mut baselines = BTreeMap::new();
        let mut coverage = BTreeMap::new();
        for p in planned {
            if !baselines.contains_key(p.kernel.name()) {
                let b = baseline(base, store, &manifest, &p.kernel, cases)?;
                coverage.insert(p.kernel.name().to_string(), covered(base, &b));
                baselines.insert(p.kernel.name().to_string(), b);
            }
        }
        let shaders = sources.shader_set();
        let unit_tests: Vec<UnitTestFile> = texts
            .iter()
            .filter(|(rel, _)| vista_wgsl_test::is_test_file(rel))
            .map(|(rel, text)| UnitTestFile {
                rel: rel.clone(),
                text: text.clone(),
                reaches: shaders.file_hashes(rel).ok().map(|files| files.into_keys().collect()),
            })
            .collect();
        // As with the goldens: a unit test failing unmutated would kill
        // every mutant, so the suite must pass first.
        for UnitTestFile { rel, text, .. } in &unit_tests {
            for r in vista_wgsl_test::run_file(base, &sources, rel, text) {
                if !r.passed() {
                    return Err(GoldenError::BadInput(format!(
                        "unit test {} fails before any mutation ({}); fix it before mutating (vista test)",
                        r.id,
                        r.explain().join("; ")
                    )));
                }
            }
        }
        Ok(Judge { base, store, manifest, sources, texts, baselines, unit_tests, coverage, goldens_only: false })
    }

    /// This judge with the golden cases as the only detector (no CPU
    /// reference, no unit tests): what the goldens check by themselves.
    pub fn goldens_only(mut self, on: bool) -> Self {
        self.goldens_only = on;
        self
    }

    /// One planned mutant judged: its file mutated in memory, then every
    /// detector of its kernel until one kills it.
    pub fn judge(&self, p: &Planned) -> MutantReport {
        let m = &p.mutant;
        let text = self.texts.get(&m.file).map(|t| m.apply(t)).unwrap_or_default();
        let gpu = Renderer {
            ctx: self.base.ctx,
            worker: self.base.worker.clone(),
            edits: vec![(m.file.clone(), text.clone())],
            shaders: self.sources.with_file("mutant", &m.file, text),
            limits: self.base.limits,
            root: self.base.root.clone(),
        };
        let base = &self.baselines[p.kernel.name()];
        let mut report = judge(&gpu, self.store, &self.manifest, &p.kernel, base, m, self.goldens_only);
        if report.outcome == "survived" && !self.goldens_only {
            // The unit tests that read the mutated file, after the goldens:
            // the first failing test kills it (the others cannot see it).
            let reading = self.unit_tests.iter().filter(|u| u.reaches.as_ref().is_none_or(|r| r.contains(&m.file)));
            for UnitTestFile { rel, text, .. } in reading {
                let results = vista_wgsl_test::run_file(&gpu, &self.sources, rel, text);
                report.cases_run += results.len();
                if let Some(r) = results.iter().find(|r| !r.passed()) {
                    report.outcome = "killed".into();
                    report.killed_by = Some(r.id.clone());
                    report.reason = r.explain().into_iter().next();
                    report.equivalent = false;
                    break;
                }
            }
        }
        if report.outcome == "survived" && self.unrun(p.kernel.name(), m) {
            report.outcome = "not covered".into();
            report.equivalent = false;
        }
        report
    }

    /// Whether `m`'s line is measured and no case of `kernel` executes it.
    fn unrun(&self, kernel: &str, m: &Mutant) -> bool {
        let Some(Some(counts)) = self.coverage.get(kernel) else { return false };
        // A file under shaders/ is reported by its project path.
        let lines = [format!("shaders/{}", m.file), m.file.clone()]
            .into_iter()
            .map(|f| counts.lines(&f))
            .find(|l| !l.is_empty())
            .unwrap_or_default();
        lines.iter().any(|&(line, hits)| line == m.line && hits == 0)
    }
}

/// The lines the baseline's cases execute, summed; none if a case's
/// coverage run failed or could not be measured.
fn covered(gpu: &Renderer, b: &Baseline) -> Option<vista_coverage::Counts> {
    let mut total = vista_coverage::Counts::default();
    for c in &b.cases {
        let run = vista_golden::cover_case(gpu, c.case).ok()?;
        if !run.not_measured.is_empty() {
            return None;
        }
        total.merge(&run.counts);
    }
    Some(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn survivor(line: u32) -> MutantReport {
        MutantReport {
            kernel: "fbm".into(),
            mutant: Mutant {
                file: "fbm.wgsl".into(),
                line,
                col: 29,
                operator: "&& ||".into(),
                before: "||".into(),
                after: "&&".into(),
                start: 0,
                end: 0,
            },
            outcome: "survived".into(),
            killed_by: None,
            reason: None,
            equivalent: true,
            cases_run: 3,
            argument: None,
        }
    }

    #[test]
    fn argued_equivalents_leave_the_score_and_stale_ones_are_reported() {
        let list = parse_argued(
            "[[mutant]]\nkernel = \"fbm\"\nfile = \"fbm.wgsl\"\nline = 25\ncol = 29\nafter = \"&&\"\nwhy = \"guard\"\n\
             [[mutant]]\nkernel = \"fbm\"\nfile = \"fbm.wgsl\"\nline = 99\ncol = 1\nafter = \"&&\"\nwhy = \"moved\"\n",
        )
        .unwrap();
        let mut m = vec![survivor(25), survivor(26), survivor(27)];
        m[1].equivalent = false;
        let stale = apply_argued(&mut m, &list);
        assert_eq!(stale.len(), 1);
        assert_eq!(stale[0].line, 99);
        assert_eq!((m[0].outcome.as_str(), m[0].argument.as_deref()), ("argued", Some("guard")));
        let r = Report::new(1, None, vec!["1/1".into()], m);
        let s = &r.kernels["fbm"];
        // One survivor counts, the `equivalent?` one is listed but not scored.
        assert_eq!((s.survived, s.equivalent, s.argued, s.score), (2, 1, 1, Some(0.0)));
        let mut killed = survivor(28);
        (killed.outcome, killed.equivalent) = ("killed".into(), false);
        let r = Report::new(1, None, vec!["1/1".into()], vec![killed, survivor(29)]);
        assert_eq!(r.score, Some(1.0));
        assert!(
            parse_argued("[[mutant]]\nkernel = \"fbm\"\nfile = \"f\"\nline = 1\ncol = 1\nafter = \"x\"\nwhy = \" \"\n")
                .is_err()
        );
        assert!(parse_argued("[[mutant]]\nkernal = 1\n").unwrap_err().contains("line 2"));
    }
}
