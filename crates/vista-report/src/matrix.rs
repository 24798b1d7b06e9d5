//! `matrix.html`: every case on every backend, PSNR per cell.

use vista_golden::{Outcome, Verdict};
use vista_image::metrics;

use crate::{html_escape, page, table};

/// One backend's column: its adapter and an outcome per case, or why it
/// could not run.
pub type MatrixColumn = (String, Result<(String, Vec<Outcome>), String>);

/// A cell's text: the PSNR, and the verdict where it is not a pass.
pub fn cell(o: &Outcome) -> String {
    let psnr = o.metrics.map(|m| metrics::format_psnr(m.psnr)).unwrap_or_else(|| "-".into());
    // Judged against a per-backend golden: say which.
    let psnr = match o.golden_file.rsplit_once('@') {
        Some((_, b)) => format!("{psnr} (golden @{})", b.trim_end_matches(".png")),
        None => psnr,
    };
    match o.verdict {
        Verdict::Pass => psnr,
        Verdict::ExpectedFail => format!("{psnr} xfail"),
        _ => format!("{psnr} FAIL"),
    }
}

/// The matrix page: a row per case id, a column per backend.
pub fn matrix_page(ids: &[&str], columns: &[MatrixColumn]) -> String {
    let rows: Vec<Vec<(&str, String)>> = ids
        .iter()
        .enumerate()
        .map(|(i, id)| {
            std::iter::once(("", html_escape(id)))
                .chain(columns.iter().map(|(_, col)| match col {
                    Ok((_, outcomes)) => {
                        let text = cell(&outcomes[i]);
                        (if outcomes[i].passed() { "" } else { "fail" }, html_escape(&text))
                    }
                    Err(_) => ("", "n/a".into()),
                }))
                .collect()
        })
        .collect();
    let legend: String = columns
        .iter()
        .map(|(b, col)| match col {
            Ok((adapter, _)) => format!("<li><b>{}</b>: {}</li>", html_escape(b), html_escape(adapter)),
            Err(why) => format!("<li><b>{}</b>: skipped: {}</li>", html_escape(b), html_escape(why)),
        })
        .collect();
    let head: Vec<&str> = std::iter::once("case").chain(columns.iter().map(|(b, _)| b.as_str())).collect();
    let body = format!(
        "<h1>vista check --matrix</h1><p>PSNR against each golden; the bless-time backend and driver use the \
         same-driver threshold, every other the other-driver one.</p><ul>{legend}</ul>{}",
        table("matrix", &head, &rows)
    );
    page("vista matrix", &body, None)
}
