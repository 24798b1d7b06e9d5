//! `vista mutate`: glue over vista-mutate (plan, progress bar, summary, JSON).

use std::path::PathBuf;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use vista_golden::{GoldenError, Store};
use vista_mutate::{Options, Report};
use vista_project::Project;

use crate::input::bad;

/// A mutant may loop for ever; the watchdog ends it as a timeout.
const MUTANT_TIMEOUT: Duration = Duration::from_secs(20);

/// `vista mutate`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Only this kernel's mutants (against its golden cases).
    #[arg(long, conflicts_with = "case")]
    pub kernel: Option<String>,
    /// The kernels of the cases whose id matches this glob, against those cases.
    #[arg(long = "case", value_name = "GLOB")]
    pub case: Option<String>,
    /// Mutants per kernel, sampled with --seed (default: all).
    #[arg(long)]
    pub sample: Option<usize>,
    /// The sampling seed: the same seed, the same mutants.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads sharing the device.
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
    /// A deterministic slice of the mutants, nextest's syntax: k/n or count:k/n.
    #[arg(long)]
    pub partition: Option<String>,
    /// Write the report as JSON (score, mutants[] with file, line, col, operator, before, after, outcome, killed_by).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Join partition reports (JSON files) into one score and report instead of running.
    #[arg(long, num_args = 1.., value_name = "JSON")]
    pub merge: Vec<PathBuf>,
    /// Survivors argued equivalent (TOML [[mutant]] kernel, file, line, col, after, why):
    /// excluded from the score and listed apart.
    #[arg(long, value_name = "TOML")]
    pub equivalent: Option<PathBuf>,
    /// Judge by the golden cases alone (no CPU reference, no WGSL unit
    /// tests): what the goldens check by themselves.
    #[arg(long)]
    pub goldens_only: bool,
}

/// The argued-equivalent list, if one was given.
fn argued(path: Option<&PathBuf>) -> Result<Vec<vista_mutate::Argued>, GoldenError> {
    let Some(path) = path else { return Ok(Vec::new()) };
    let text =
        std::fs::read_to_string(path).map_err(|e| bad(format!("--equivalent {}: cannot read: {e}", path.display())))?;
    vista_mutate::parse_argued(&text).map_err(|e| bad(format!("--equivalent {}: {e}", path.display())))
}

pub fn mutate(project: &Project, config: &vista::Config, a: Args) -> Result<i32, GoldenError> {
    let argued = argued(a.equivalent.as_ref())?;
    if !a.merge.is_empty() {
        let mut parts = Vec::new();
        for path in &a.merge {
            let text = std::fs::read_to_string(path)
                .map_err(|e| bad(format!("--merge {}: cannot read: {e}", path.display())))?;
            let r: Report = serde_json::from_str(&text)
                .map_err(|e| bad(format!("--merge {}: not a vista mutate report: {e}", path.display())))?;
            parts.push(r);
        }
        let mut report = Report::merge(parts).map_err(|e| bad(format!("--merge: {e}")))?;
        if !argued.is_empty() {
            let mut m = report.mutants.clone();
            m.iter_mut().filter(|m| m.outcome == "argued").for_each(|m| m.outcome = "survived".into());
            warn_unused(&vista_mutate::apply_argued(&mut m, &argued));
            report = Report::new(report.seed, report.sample, report.partitions.clone(), m);
        }
        return finish(project, &report, a.json.as_ref());
    }
    if !(1..=64).contains(&a.jobs) {
        return Err(bad(format!("--jobs {} is out of range; allowed: [1, 64]", a.jobs)));
    }
    if a.sample == Some(0) {
        return Err(bad("--sample 0 runs nothing; allowed: 1 or more"));
    }
    let partition = match &a.partition {
        Some(p) => vista_mutate::parse_partition(p).map_err(bad)?,
        None => (1, 1),
    };
    let store = Store::of_project(project, "vista mutate")?;
    let all_cases = store.load_cases()?;
    let cases = vista_golden::select(&all_cases, a.case.as_deref())?;
    let kernels: Vec<std::sync::Arc<vista_kernels::Kernel>> = match &a.kernel {
        Some(name) => vec![store.kernels.find(name).cloned().map_err(bad)?],
        None => {
            let mut ks: Vec<_> = cases.iter().map(|c| c.kernel.clone()).collect();
            ks.sort_by(|a, b| a.name().cmp(b.name()));
            ks.dedup_by(|a, b| a.name() == b.name());
            ks
        }
    };
    if let Some(k) = kernels.iter().find(|k| !cases.iter().any(|c| c.kernel.name() == k.name())) {
        return Err(bad(format!("kernel {} has no golden case selected; mutants need cases to run against", k.name())));
    }
    // The project's WGSL, and what its [source] tables reach outside shaders/.
    let mut files = project.shader_files()?;
    files.extend(vista_mutate::outside_files(project)?);
    let shaders = vista_render::shader_set(project)?;
    let opts = Options {
        kernel: a.kernel.clone(),
        case_glob: a.case.clone(),
        sample: a.sample,
        seed: a.seed,
        jobs: a.jobs,
        partition,
    };
    let planned = vista_mutate::plan(&files, &shaders, &kernels, &opts)?;
    eprintln!(
        "vista mutate: {} mutants of {} kernel(s) (seed {}, sample {}, partition {}/{}){}",
        planned.len(),
        kernels.len(),
        a.seed,
        a.sample.map_or("all".to_string(), |s| s.to_string()),
        partition.0,
        partition.1,
        if a.goldens_only { "; judged by the golden cases alone" } else { "" }
    );
    let ctx = vista_render::own_device(&config.gpu, None, Some(MUTANT_TIMEOUT))?;
    let bar = ProgressBar::new(planned.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} mutants, {elapsed} elapsed, ETA {eta}")
            .expect("valid template"),
    );
    let base =
        vista_render::Renderer::with_shaders(&ctx, shaders.clone(), config.limits, project.root().map(Into::into));
    let judge = vista_mutate::Judge::new(&base, project, &store, &cases, &planned)?.goldens_only(a.goldens_only);
    let mut results = vista_check::mutants(&judge, &planned, a.jobs, &mut Progress(&bar));
    bar.finish_and_clear();
    let unused = vista_mutate::apply_argued(&mut results, &argued);
    // A partition holds only part of the survivors: its unmatched arguments say nothing.
    if a.partition.is_none() {
        warn_unused(&unused);
    }
    let report = Report::new(a.seed, a.sample, vec![format!("{}/{}", partition.0, partition.1)], results);
    finish(project, &report, a.json.as_ref())
}

/// The progress bar, moved on as each mutant is judged.
struct Progress<'a>(&'a ProgressBar);

impl vista_check::Reporter for Progress<'_> {
    fn mutant(&mut self, done: usize, _total: usize, _report: &vista_mutate::MutantReport) {
        self.0.set_position(done as u64);
    }
}

/// Arguments that matched no survivor: the code moved, or a case kills it now.
fn warn_unused(unused: &[vista_mutate::Argued]) {
    for u in unused {
        println!(
            "note: argued equivalent {}:{}:{} -> {} ({}) matches no survivor any more",
            u.file, u.line, u.col, u.after, u.kernel
        );
    }
}

fn pct(s: Option<f64>) -> String {
    s.map_or("-".into(), |v| format!("{:.1}%", 100.0 * v))
}

fn finish(project: &Project, report: &Report, json: Option<&PathBuf>) -> Result<i32, GoldenError> {
    println!(
        "{:<14} {:>7} {:>8} {:>12} {:>12} {:>7} {:>8} {:>10}  score",
        "kernel", "killed", "survived", "not covered", "equivalent?", "argued", "timeout", "stillborn"
    );
    for (k, s) in &report.kernels {
        println!(
            "{k:<14} {:>7} {:>8} {:>12} {:>12} {:>7} {:>8} {:>10}  {}",
            s.killed,
            s.survived,
            s.not_covered,
            s.equivalent,
            s.argued,
            s.timeout,
            s.stillborn,
            pct(s.score)
        );
    }
    println!(
        "overall score {} (killed / (killed + survived + not covered); equivalent? and argued survivors listed, not \
         scored)",
        pct(report.score)
    );
    let argued: Vec<_> = report.mutants.iter().filter(|m| m.outcome == "argued").collect();
    if !argued.is_empty() {
        println!("argued equivalent (excluded from the score):");
        for m in argued {
            let why = m.argument.as_deref().unwrap_or("");
            println!(
                "  {}:{}:{}  {} -> {}  {}: {why}",
                m.mutant.file, m.mutant.line, m.mutant.col, m.mutant.before, m.mutant.after, m.kernel
            );
        }
    }
    let unrun: Vec<_> = report.mutants.iter().filter(|m| m.outcome == "not covered").collect();
    if !unrun.is_empty() {
        println!("not covered (no case of the kernel executes the line: add a case that reaches it):");
        for m in unrun {
            let after = if m.mutant.after.is_empty() { "(removed)" } else { &m.mutant.after };
            println!(
                "  {}:{}:{}  {} -> {after}  {}",
                m.mutant.file, m.mutant.line, m.mutant.col, m.mutant.before, m.kernel
            );
        }
    }
    let survivors: Vec<_> = report.mutants.iter().filter(|m| m.outcome == "survived").collect();
    if !survivors.is_empty() {
        println!("survivors:");
        for m in survivors {
            println!(
                "  {}:{}:{}  {} -> {}  ({} cases run){}",
                m.mutant.file,
                m.mutant.line,
                m.mutant.col,
                m.mutant.before,
                if m.mutant.after.is_empty() { "(removed)" } else { &m.mutant.after },
                m.cases_run,
                if m.equivalent { "  equivalent?" } else { "" }
            );
        }
    }
    if let Some(dir) = project.report_dir() {
        let path = vista_report::write_page(&dir, "mutants.html", &vista_report::mutation_page(report))?;
        println!("report: {}", path.display());
    }
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(report).map_err(|e| bad(format!("JSON encode: {e}")))?;
        vista_image::atomic_write(path, text.as_bytes())?;
        println!("json: {}", path.display());
    }
    Ok(0)
}
