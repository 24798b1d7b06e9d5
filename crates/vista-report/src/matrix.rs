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

/// Why a cell did not pass, in one line: its first problem (an expected
/// failure: its note).
pub fn matrix_reason(o: &Outcome) -> String {
    let first = o.problems.first().or_else(|| o.notes.first()).map(String::as_str).unwrap_or("failed");
    first.lines().next().unwrap_or(first).to_string()
}

/// Every cell of the matrix as JSON: the backends (adapter, or why one was
/// skipped) and per case and backend the verdict, PSNR and reason.
pub fn matrix_json(ids: &[&str], columns: &[MatrixColumn]) -> serde_json::Value {
    let backends: Vec<serde_json::Value> = columns
        .iter()
        .map(|(b, col)| match col {
            Ok((adapter, _)) => serde_json::json!({ "backend": b, "adapter": adapter }),
            Err(why) => serde_json::json!({ "backend": b, "skipped": why }),
        })
        .collect();
    let mut cells = Vec::new();
    for (i, id) in ids.iter().enumerate() {
        for (b, col) in columns {
            let Ok((_, outcomes)) = col else { continue };
            let o = &outcomes[i];
            cells.push(serde_json::json!({
                "case": id,
                "backend": b,
                "verdict": format!("{:?}", o.verdict).to_lowercase(),
                "passed": o.passed(),
                "psnr": o.metrics.map(|m| m.psnr).filter(|p| p.is_finite()),
                "golden": o.golden_file,
                "reason": (!o.passed() || o.verdict == Verdict::ExpectedFail).then(|| matrix_reason(o)),
            }));
        }
    }
    serde_json::json!({ "cases": ids, "backends": backends, "cells": cells })
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
    let reasons: String = ids
        .iter()
        .enumerate()
        .flat_map(|(i, id)| {
            columns.iter().filter_map(move |(b, col)| match col {
                Ok((_, outcomes)) if !outcomes[i].passed() => Some(format!(
                    "<li><b>{}</b> on {}: {}</li>",
                    html_escape(id),
                    html_escape(b),
                    html_escape(&matrix_reason(&outcomes[i]))
                )),
                _ => None,
            })
        })
        .collect();
    let reasons = match reasons.is_empty() {
        true => String::new(),
        false => format!("<h2>Why each failing cell failed</h2><ul class=\"reasons\">{reasons}</ul>"),
    };
    let body = format!(
        "<h1>vista check --matrix</h1><p>PSNR against each golden; the bless-time backend and driver use the \
         same-driver threshold, every other the other-driver one.</p><ul>{legend}</ul>{}{reasons}",
        table("matrix", &head, &rows)
    );
    page("vista matrix", &body, None)
}
