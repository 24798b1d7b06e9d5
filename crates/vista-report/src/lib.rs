//! vista's reports, written from verdicts: the review page
//! (`target/vista-report/index.html` with each case's images and viewer
//! data), the case x backend matrix (`matrix.html`) and the mutation page
//! (`mutants.html`). Every page is made by the one HTML writer, [`page`].
//!
//! Not for: rendering or judging. Callers render (`vista-render`) and judge
//! (`vista-golden`), then hand the outcomes and images here.
#![deny(missing_docs)]

mod coverage;
mod matrix;
mod mutation;
mod report;
mod results;

pub use coverage::{COVERAGE_DIR, coverage_line, coverage_page, write_coverage};
pub use matrix::{MatrixColumn, cell as matrix_cell, matrix_json, matrix_page, matrix_reason};
pub use mutation::mutation_page;
pub use report::{
    CASE_MARKER, Detail, RunSummary, THUMB_EDGE, THUMBS_DIR, UnitTest, clear_case_folders, file_case, href,
    prune_thumbs, view_js, write_case_files, write_index, write_report,
};
pub use results::{case_line, github_annotations, json_results, json_text, junit_xml, verdict_name};

/// The stylesheet every page carries inline (a copied report folder opens
/// offline, and a page from `file://` may not load another origin's CSS).
const STYLE: &str = include_str!("report.css");

/// Text escaped for HTML element content and attribute values.
pub fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The one HTML writer: a page titled `title` (escaped here) around
/// `body` (HTML), with the shared stylesheet and an optional script.
pub fn page(title: &str, body: &str, script: Option<&str>) -> String {
    let script = script.map(|s| format!("<script>{s}</script>\n")).unwrap_or_default();
    format!(
        "<!doctype html><html lang=\"en\"><meta charset=\"utf-8\"><title>{}</title>\n<style>{STYLE}</style>\n\
         {body}\n{script}</html>\n",
        html_escape(title)
    )
}

/// A table of already-made cell HTML: a header row, then one row per item;
/// a cell is `(class, html)` (class "" for none).
pub fn table(class: &str, head: &[&str], rows: &[Vec<(&str, String)>]) -> String {
    let mut t = format!("<table class=\"{class}\"><tr>");
    for h in head {
        t += &format!("<th>{h}</th>");
    }
    t += "</tr>\n";
    for r in rows {
        t += "<tr>";
        for (cls, html) in r {
            match *cls {
                "" => t += &format!("<td>{html}</td>"),
                c => t += &format!("<td class=\"{c}\">{html}</td>"),
            }
        }
        t += "</tr>\n";
    }
    t + "</table>"
}

/// Writes a page atomically into `dir` (created if needed); returns its path.
pub fn write_page(
    dir: &std::path::Path,
    name: &str,
    html: &str,
) -> Result<std::path::PathBuf, vista_golden::GoldenError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| vista_golden::GoldenError::Io { path: dir.display().to_string(), message: e.to_string() })?;
    let path = dir.join(name);
    vista_image::atomic_replace(&path, html.as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_page_is_one_escaped_shell_with_the_shared_style() {
        let p = page("a <b> & \"c\"", "<p>x</p>", Some("let y = 1;"));
        assert!(p.starts_with("<!doctype html>"), "{p}");
        assert!(p.contains("<title>a &lt;b&gt; &amp; &quot;c&quot;</title>"), "{p}");
        assert!(p.contains(STYLE) && p.contains("<p>x</p>") && p.contains("<script>let y = 1;</script>"), "{p}");
        let t = table("t", &["h"], &[vec![("fail", "1".into()), ("", "2".into())]]);
        assert_eq!(t, "<table class=\"t\"><tr><th>h</th></tr>\n<tr><td class=\"fail\">1</td><td>2</td></tr>\n</table>");
    }
}
