//! `vista check --matrix`: every case on every implementation, one
//! case x backend table (PSNR per cell) in the terminal and in
//! `<report>/matrix.html`.

use std::path::PathBuf;

use vista_golden::{CheckOptions, GoldenError, Outcome, Store, Verdict};
use vista_gpu::{AdapterChoice, Context};
use vista_image::metrics;
use vista_project::Project;
use vista_render::Renderer;

/// The implementations of the matrix, in column order.
const BACKENDS: &[&str] = &["lavapipe", "swiftshader", "browser"];

/// One backend's adapter and an outcome per case, or why it is missing.
type Column = Result<(String, Vec<Outcome>), String>;

fn cell(o: &Outcome) -> String {
    let psnr = o.metrics.map(|m| metrics::format_psnr(m.psnr)).unwrap_or_else(|| "-".into());
    match o.verdict {
        Verdict::Pass => psnr,
        Verdict::ExpectedFail => format!("{psnr} xfail"),
        _ => format!("{psnr} FAIL"),
    }
}

pub fn matrix(
    project: &Project,
    config: &vista::Config,
    glob: Option<&str>,
    report_dir: Option<PathBuf>,
) -> Result<i32, GoldenError> {
    let store = Store::of_project(project, "vista check --matrix")?;
    let cases = store.load_cases()?;
    let picked = vista_golden::select(&cases, glob)?;
    let manifest = store.manifest()?;
    let report_dir = report_dir.unwrap_or_else(|| project.report_dir().expect("a store implies a root"));
    let shaders = vista_render::shader_set(project)?;
    for b in BACKENDS {
        vista_golden::clear_case_folders(&report_dir.join(b))?;
    }
    let mut columns: Vec<(&str, Column)> = Vec::new();
    for &b in BACKENDS {
        let gpu_config = vista_gpu::GpuConfig { adapter: AdapterChoice::of_backend(b)?, ..config.gpu.clone() };
        let ctx = match Context::new(&gpu_config) {
            Ok(c) => c,
            Err(e) => {
                columns.push((b, Err(e.to_string())));
                continue;
            }
        };
        let gpu = Renderer { ctx: &ctx, shaders: shaders.clone(), limits: config.limits };
        let opts = CheckOptions { report_dir: report_dir.join(b), twice: false };
        let outcomes: Vec<Outcome> =
            picked.iter().map(|c| vista_golden::check_case(&gpu, &store, &manifest, c, &opts)).collect();
        columns.push((b, Ok((ctx.adapter_description(), outcomes))));
    }

    let width = picked.iter().map(|c| c.id.len()).max().unwrap_or(4).max(4);
    print!("{:<width$}", "case");
    for (b, _) in &columns {
        print!("  {b:<18}");
    }
    println!();
    let mut failed = 0;
    let mut rows = String::new();
    for (i, case) in picked.iter().enumerate() {
        print!("{:<width$}", case.id);
        rows += &format!("<tr><td>{}</td>", vista_golden::html_escape(&case.id));
        for (_, col) in &columns {
            let text = match col {
                Ok((_, outcomes)) => {
                    if !outcomes[i].passed() {
                        failed += 1;
                    }
                    cell(&outcomes[i])
                }
                Err(_) => "n/a".into(),
            };
            let class = if text.contains("FAIL") { "fail" } else { "" };
            rows += &format!("<td class=\"{class}\">{}</td>", vista_golden::html_escape(&text));
            print!("  {text:<18}");
        }
        rows += "</tr>\n";
        println!();
    }
    let mut legend = String::new();
    let mut missing = 0;
    for (b, col) in &columns {
        match col {
            Ok((adapter, _)) => {
                println!("{b}: {adapter}");
                legend += &format!("<li><b>{b}</b>: {}</li>", vista_golden::html_escape(adapter));
            }
            Err(why) => {
                missing += 1;
                println!("!!! {b}: SKIPPED, all {} cells: {why}", picked.len());
                legend += &format!("<li><b>{b}</b>: skipped: {}</li>", vista_golden::html_escape(why));
            }
        }
    }
    let html = format!(
        "<!doctype html><meta charset=\"utf-8\"><title>vista matrix</title>\
         <style>body{{font-family:sans-serif}} td,th{{border:1px solid #ccc;padding:3px 6px}} \
         table{{border-collapse:collapse}} td.fail{{background:#fcc}}</style>\
         <h1>vista check --matrix</h1><p>PSNR against each golden; the bless-time backend and driver use the \
         same-driver threshold, every other the other-driver one.</p><ul>{legend}</ul>\
         <table><tr><th>case</th>{}</tr>\n{rows}</table>\n",
        columns.iter().map(|(b, _)| format!("<th>{b}</th>")).collect::<String>()
    );
    std::fs::create_dir_all(&report_dir)
        .map_err(|e| GoldenError::Io { path: report_dir.display().to_string(), message: e.to_string() })?;
    let path = report_dir.join("matrix.html");
    vista_image::atomic_write(&path, html.as_bytes())?;
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
