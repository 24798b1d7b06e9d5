//! `vista check --matrix`: every case on every implementation, one
//! case x backend table (PSNR per cell) in the terminal and in
//! `<report>/matrix.html`, each failing cell's first reason under it, and
//! with `--json F` every cell as JSON.

use std::path::PathBuf;

use vista_check::{Checker, Filed, Run};
use vista_golden::{GoldenError, Outcome, Store};
use vista_project::Project;
use vista_render::Renderer;

/// The implementations of the matrix, in column order.
const BACKENDS: &[&str] = &["lavapipe", "swiftshader", "browser"];

pub fn matrix(
    project: &Project,
    config: &vista::Config,
    glob: Option<&str>,
    report_dir: Option<PathBuf>,
    json: Option<PathBuf>,
) -> Result<i32, GoldenError> {
    if let Some(p) = &json {
        crate::check::check_results_path("--json", p)?;
    }
    let store = Store::of_project(project, "vista check --matrix")?;
    let cases = store.load_cases()?;
    let picked = vista_golden::select(&cases, glob)?;
    let manifest = store.manifest()?;
    let report_dir = report_dir.unwrap_or_else(|| project.report_dir().expect("a store implies a root"));
    let shaders = vista_render::shader_set(project)?;
    for b in BACKENDS {
        vista_report::clear_case_folders(&report_dir.join(b))?;
    }
    let mut columns: Vec<vista_report::MatrixColumn> = Vec::new();
    for &b in BACKENDS {
        let ctx = match vista_render::own_device(&config.gpu, Some(b), None) {
            Ok(c) => c,
            Err(e) => {
                columns.push((b.to_string(), Err(e.to_string())));
                continue;
            }
        };
        let gpu = Renderer::with_shaders(&ctx, shaders.clone(), config.limits, project.root().map(Into::into));
        let dir = report_dir.join(b);
        let checker = Checker {
            ctx: &gpu,
            store: &store,
            manifest: &manifest,
            report_dir: &dir,
            detail: Default::default(),
            coverage: false,
        };
        let summary = vista_report::RunSummary {
            command: crate::check::command_line(),
            backend: b.to_string(),
            adapter: ctx.adapter_description(),
            ..Default::default()
        };
        // Each backend's column is a whole run: its own report in <report>/<backend>/.
        let mut run = Run { checker, summary, results: Default::default(), shared: None };
        let mut errors = |f: &Filed| {
            for e in &f.report_errors {
                println!("error: {} on {b}: its report folder could not be written: {e}", f.outcome.id);
            }
        };
        let ran = run.run(&picked, 1, &mut errors)?;
        let outcomes: Vec<Outcome> = ran.filed.into_iter().map(|f| f.outcome).collect();
        columns.push((b.to_string(), Ok((ctx.adapter_description(), outcomes))));
    }

    let width = picked.iter().map(|c| c.id.len()).max().unwrap_or(4).max(4);
    print!("{:<width$}", "case");
    for (b, _) in &columns {
        print!("  {b:<18}");
    }
    println!();
    let mut failed = 0;
    for (i, case) in picked.iter().enumerate() {
        print!("{:<width$}", case.id);
        for (_, col) in &columns {
            let text = match col {
                Ok((_, outcomes)) => {
                    failed += usize::from(!outcomes[i].passed());
                    vista_report::matrix_cell(&outcomes[i])
                }
                Err(_) => "n/a".into(),
            };
            print!("  {text:<18}");
        }
        println!();
    }
    // Each failing cell's first reason, so the table needs no report to read.
    for (i, case) in picked.iter().enumerate() {
        for (b, col) in &columns {
            if let Ok((_, outcomes)) = col
                && !outcomes[i].passed()
            {
                println!("- FAIL {} on {b}: {}", case.id, vista_report::matrix_reason(&outcomes[i]));
            }
        }
    }
    let mut missing = 0;
    for (b, col) in &columns {
        match col {
            Ok((adapter, _)) => println!("{b}: {adapter}"),
            Err(why) => {
                missing += 1;
                println!("!!! {b}: SKIPPED, all {} cells: {why}", picked.len());
            }
        }
    }
    let ids: Vec<&str> = picked.iter().map(|c| c.id.as_str()).collect();
    let path = vista_report::write_page(&report_dir, "matrix.html", &vista_report::matrix_page(&ids, &columns))?;
    if let Some(p) = &json {
        let text = serde_json::to_string_pretty(&vista_report::matrix_json(&ids, &columns)).expect("JSON of values");
        vista_image::atomic_replace(p, text.as_bytes())?;
    }
    let ran = columns.len() - missing;
    println!("matrix: {} cases x {ran} backends, {failed} failed, {missing} backend(s) skipped", picked.len());
    println!("report: {}", path.display());
    // A column that could not run is a failure unless skips are allowed.
    let skipped_ok = missing == 0 || config.allow_no_gpu;
    if missing > 0 && skipped_ok {
        println!("!!! VISTA_ALLOW_NO_GPU=1: the {missing} skipped backend(s) do not fail the run");
    }
    Ok(if failed == 0 && skipped_ok { 0 } else { 1 })
}
