//! The coverage pages of a `check --coverage` run: `coverage/index.html`
//! (each file's lines and branch arms reached) and one page per file, its
//! source with each line's hit count, the lines no case reached and the
//! arms never taken marked.

use std::fmt::Write;
use std::path::Path;

use vista_coverage::Counts;
use vista_golden::GoldenError;

use crate::{html_escape, page};

/// The folder of the coverage pages, under the report folder.
pub const COVERAGE_DIR: &str = "coverage";

/// The page of `file` (a project-relative path), relative to the report
/// folder.
pub fn coverage_page(file: &str) -> String {
    let name: String =
        file.chars().map(|c| if c.is_ascii_alphanumeric() || matches!(c, '.' | '-') { c } else { '_' }).collect();
    format!("{COVERAGE_DIR}/{name}.html")
}

/// Lines hit of found, arms taken of found.
fn file_totals(counts: &Counts, file: &str) -> (usize, usize, usize, usize) {
    let lines = counts.lines(file);
    let arms = counts.arms(file);
    (lines.len(), lines.iter().filter(|l| l.1 > 0).count(), arms.len(), arms.iter().filter(|a| a.3 > 0).count())
}

fn percent(hit: usize, found: usize) -> String {
    match found {
        0 => "-".into(),
        _ => format!("{:.1}%", 100.0 * hit as f64 / found as f64),
    }
}

/// The summary line: lines and arms reached over every file, as
/// `94.1% of lines, 93.3% of branches in 2 files (16 of 17 lines, 14 of 15
/// branch arms)`.
pub fn coverage_line(counts: &Counts) -> String {
    let (lf, lh, bf, bh) = counts.totals();
    format!(
        "{} of lines, {} of branches in {} files ({lh} of {lf} lines, {bh} of {bf} branch arms)",
        percent(lh, lf),
        percent(bh, bf),
        counts.files().len()
    )
}

/// Writes `coverage/index.html` and a page per file of `counts`, each
/// file's text from `source` (a file it cannot read gets its counts
/// without text). Returns the index page's path relative to the folder.
pub fn write_coverage(
    dir: &Path,
    counts: &Counts,
    source: &dyn Fn(&str) -> Option<String>,
) -> Result<String, GoldenError> {
    let folder = dir.join(COVERAGE_DIR);
    std::fs::create_dir_all(&folder)
        .map_err(|e| GoldenError::Io { path: folder.display().to_string(), message: e.to_string() })?;
    let mut rows = String::new();
    for file in counts.files() {
        let (lf, lh, bf, bh) = file_totals(counts, &file);
        let href = coverage_page(&file);
        let _ = write!(
            rows,
            "<tr><td class=\"id\"><a href=\"{}\">{}</a></td><td>{lh} / {lf}</td><td class=\"{}\">{}</td>\
             <td>{bh} / {bf}</td><td class=\"{}\">{}</td></tr>",
            html_escape(href.trim_start_matches("coverage/")),
            html_escape(&file),
            if lh < lf { "bad" } else { "ok" },
            percent(lh, lf),
            if bh < bf { "bad" } else { "ok" },
            percent(bh, bf),
        );
        let html = file_page(&file, counts, source(&file).as_deref());
        vista_image::atomic_replace(&dir.join(&href), html.as_bytes())?;
    }
    let body = format!(
        "<header><h1>WGSL coverage</h1><p class=\"counts\">{}.</p><p>Lines and branch arms the cases' coverage run \
         executed (<code class=\"cmd\">vista check --coverage</code>); <a href=\"../lcov.info\">lcov.info</a> holds \
         the same counts for genhtml or a coverage service. <a href=\"../index.html\">The report</a>.</p></header>\n\
         <section><table class=\"coverage\"><tr><th>file</th><th>lines</th><th></th><th>branch arms</th><th></th></tr>\
         {rows}</table></section>",
        html_escape(&coverage_line(counts))
    );
    let index = format!("{COVERAGE_DIR}/index.html");
    vista_image::atomic_replace(&dir.join(&index), page("vista coverage", &body, None).as_bytes())?;
    Ok(index)
}

/// One file's page: each line with its hits (blank: no statement there, or
/// not measured), a line no case reached marked, and its arms.
fn file_page(file: &str, counts: &Counts, text: Option<&str>) -> String {
    let lines: std::collections::BTreeMap<u32, u64> = counts.lines(file).into_iter().collect();
    let mut arms: std::collections::BTreeMap<u32, Vec<(u32, u32, u64)>> = Default::default();
    for (line, col, arm, hits) in counts.arms(file) {
        arms.entry(line).or_default().push((col, arm, hits));
    }
    let mut out = String::new();
    let text_lines: Vec<&str> = text.map(|t| t.lines().collect()).unwrap_or_default();
    let last = lines.keys().chain(arms.keys()).max().copied().unwrap_or(0).max(text_lines.len() as u32);
    for n in 1..=last {
        let hits = lines.get(&n);
        let cls = match hits {
            Some(0) => "miss",
            Some(_) => "hit",
            None => "none",
        };
        let arm_note: String = arms
            .get(&n)
            .map(|a| {
                let never: Vec<String> =
                    a.iter().filter(|x| x.2 == 0).map(|(col, arm, _)| format!("col {col} arm {arm}")).collect();
                match never.is_empty() {
                    true => format!(" <span class=\"arms\">{} arms taken</span>", a.len()),
                    false => format!(
                        " <span class=\"arms bad\">{} of {} arms taken; never: {}</span>",
                        a.len() - never.len(),
                        a.len(),
                        never.join(", ")
                    ),
                }
            })
            .unwrap_or_default();
        let _ = writeln!(
            out,
            "<tr class=\"{cls}\"><td class=\"n\">{n}</td><td class=\"hits\">{}</td><td><code>{}</code>{arm_note}</td></tr>",
            hits.map_or(String::new(), |h| h.to_string()),
            html_escape(text_lines.get(n as usize - 1).copied().unwrap_or(""))
        );
    }
    let (lf, lh, bf, bh) = file_totals(counts, file);
    let missing = match text {
        Some(_) => String::new(),
        None => "<p class=\"note\">The file's text could not be read for this page.</p>".into(),
    };
    let body = format!(
        "<header><h1>{file}</h1><p class=\"counts\">{lh} of {lf} lines ({lp}), {bh} of {bf} branch arms ({bp}). \
         <a href=\"index.html\">Every file</a>.</p><p>Hits per line over every case; a red line ran in no case; a blank \
         count: no statement there, or not measured (a function only a vertex stage calls, on a device whose vertex stage cannot write storage). For <code>&amp;&amp;</code> \
         and <code>||</code>, arm 0 is the right-hand side evaluated, arm 1 the short cut.</p>{missing}</header>\n\
         <section><table class=\"source\">{out}</table></section>",
        file = html_escape(file),
        lp = percent(lh, lf),
        bp = percent(bh, bf),
    );
    page(&format!("coverage: {file}"), &body, None)
}
