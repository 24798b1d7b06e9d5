//! `target/vista-report/index.html`: one row per case with expected, actual
//! and diff thumbnails, metrics and thresholds, failures first.
//! Self-contained: images live beside it and are linked relatively.

use std::path::{Path, PathBuf};

use vista_image::metrics::format_psnr;

use crate::check::{Outcome, Verdict};

/// Text escaped for HTML element content and attribute values.
pub fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn img(path: &Option<String>) -> String {
    match path {
        Some(p) => format!("<a href=\"{0}\"><img src=\"{0}\" width=\"128\"></a>", html_escape(p)),
        None => "<span class=\"none\">none</span>".into(),
    }
}

/// The empty file that marks a case folder as written by vista.
pub const CASE_MARKER: &str = ".vista-case";

/// Clears the case folders an earlier run left in `dir`, so a filtered run's
/// report shows only its own cases. Only folders holding vista's marker are
/// removed: a `--report-dir` pointed anywhere else loses nothing.
pub fn clear_case_folders(dir: &Path) -> Result<(), crate::GoldenError> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Ok(()) };
    for e in entries.flatten() {
        if e.path().is_dir() && e.path().join(CASE_MARKER).is_file() {
            std::fs::remove_dir_all(e.path()).map_err(|err| crate::GoldenError::Io {
                path: e.path().display().to_string(),
                message: err.to_string(),
            })?;
        }
    }
    Ok(())
}

/// The one bless command for every failing case (globset alternation).
pub fn bless_all_command(failed: &[&str]) -> Option<String> {
    match failed {
        [] => None,
        [one] => Some(format!("vista bless --case '{one}'")),
        many => Some(format!("vista bless --case '{{{}}}'", many.join(","))),
    }
}

/// Writes the report (atomically) and returns the index path.
pub fn write_report(dir: &Path, adapter: &str, outcomes: &[Outcome]) -> Result<PathBuf, crate::GoldenError> {
    let mut sorted: Vec<&Outcome> = outcomes.iter().collect();
    sorted.sort_by_key(|o| (o.passed(), o.id.clone()));
    let failed = sorted.iter().filter(|o| !o.passed()).count();
    let mut rows = String::new();
    for o in &sorted {
        let class = match o.verdict {
            Verdict::Pass => "pass",
            _ => "fail",
        };
        let (psnr, ssim, max_abs, bad, nan) = match &o.metrics {
            Some(m) => (
                format_psnr(m.psnr),
                format!("{:.5}", m.ssim),
                format!("{:.2e}", m.max_abs),
                m.bad_pixels.to_string(),
                m.nan.to_string(),
            ),
            None => ("-".into(), "-".into(), "-".into(), "-".into(), "-".into()),
        };
        let threshold = format!(
            "PSNR &ge; {:.1} dB ({} driver){}",
            o.psnr_threshold,
            if o.same_driver { "same" } else { "other" },
            o.min_ssim.map(|t| format!("<br>SSIM &ge; {t}")).unwrap_or_default()
        );
        let msgs: String = o
            .problems
            .iter()
            .map(|p| format!("<div class=\"problem\">{}</div>", html_escape(p)))
            .chain(o.notes.iter().map(|n| format!("<div class=\"note\">{}</div>", html_escape(n))))
            .collect();
        rows += &format!(
            "<tr class=\"{class}\"><td><b>{id}</b><br>{kernel}<br>{verdict:?}<br>{gpu:.1} ms</td><td>{e}</td><td>{a}</td><td>{d}</td>\
             <td>{psnr}</td><td>{ssim}</td><td>{max_abs}</td><td>{bad}</td><td>{nan}</td><td>{threshold}</td><td>{msgs}</td></tr>\n",
            id = html_escape(&o.id),
            kernel = html_escape(&o.kernel),
            verdict = o.verdict,
            gpu = o.gpu_ms,
            e = img(&o.files.expected),
            a = img(&o.files.actual),
            d = img(&o.files.diff),
        );
    }
    // The other pages of the same folder, when a run wrote them.
    let others: String = [("matrix.html", "case x backend matrix"), ("mutants.html", "mutation score")]
        .iter()
        .filter(|(f, _)| dir.join(f).exists())
        .map(|(f, what)| format!(" <a href=\"{f}\">{what}</a>"))
        .collect();
    let html = format!(
        "<!doctype html><meta charset=\"utf-8\"><title>vista report</title>\n<style>\
         body{{font-family:sans-serif;margin:1em}} table{{border-collapse:collapse}} td,th{{border:1px solid #ccc;padding:4px;vertical-align:top;font-size:13px}}\
         tr.fail{{background:#fee}} .problem{{color:#b00}} .note{{color:#555}} img{{image-rendering:pixelated}}</style>\n\
         <h1>vista report</h1><p>{n} cases, {failed} failing. Adapter: {adapter}. Written {date}.{others}</p>\n\
         <table><tr><th>case</th><th>expected</th><th>actual</th><th>diff</th><th>PSNR</th><th>SSIM</th><th>max abs</th>\
         <th>bad px</th><th>NaN/Inf</th><th>threshold</th><th>details</th></tr>\n{rows}</table>\n",
        n = sorted.len(),
        adapter = html_escape(adapter),
        date = crate::now_utc(),
    );
    std::fs::create_dir_all(dir)
        .map_err(|e| crate::GoldenError::Io { path: dir.display().to_string(), message: e.to_string() })?;
    let index = dir.join("index.html");
    vista_image::atomic_write(&index, html.as_bytes())?;
    Ok(index)
}
