//! `mutants.html`: the mutation score per kernel and the survivors.

use vista_mutate::Report;

use crate::{html_escape, page, table};

/// The mutation page of a report.
pub fn mutation_page(r: &Report) -> String {
    let pct = |s: Option<f64>| s.map_or("-".into(), |v| format!("{:.1}%", 100.0 * v));
    let kernels: Vec<Vec<(&str, String)>> = r
        .kernels
        .iter()
        .map(|(k, s)| {
            vec![
                ("", html_escape(k)),
                ("", s.killed.to_string()),
                ("", s.survived.to_string()),
                ("", s.not_covered.to_string()),
                ("", s.equivalent.to_string()),
                ("", s.argued.to_string()),
                ("", s.timeout.to_string()),
                ("", s.stillborn.to_string()),
                ("", format!("<b>{}</b>", pct(s.score))),
            ]
        })
        .collect();
    let survivors: Vec<Vec<(&str, String)>> = r
        .mutants
        .iter()
        .filter(|m| m.outcome == "survived" || m.outcome == "not covered")
        .map(|m| {
            let after = if m.mutant.after.is_empty() { "(removed)" } else { &m.mutant.after };
            vec![
                ("", html_escape(&m.kernel)),
                ("", format!("<code>{}:{}:{}</code>", html_escape(&m.mutant.file), m.mutant.line, m.mutant.col)),
                ("", html_escape(&m.mutant.operator)),
                (
                    "",
                    format!(
                        "<code>{}</code> &rarr; <code>{}</code>",
                        html_escape(&m.mutant.before),
                        html_escape(after)
                    ),
                ),
                ("", m.cases_run.to_string()),
                (
                    "",
                    match (m.outcome.as_str(), m.equivalent) {
                        ("not covered", _) => "not covered: no case executes the line".into(),
                        (_, true) => "equivalent?".into(),
                        _ => String::new(),
                    },
                ),
            ]
        })
        .collect();
    let body = format!(
        "<h1>vista mutate</h1><p>seed {}, sample {}, partitions {}: overall score <b>{}</b> \
         (killed / (killed + survived + not covered); argued and <code>equivalent?</code> survivors left out).</p>{}\
         <h2>Survivors</h2>{}",
        r.seed,
        r.sample.map_or("all".to_string(), |s| s.to_string()),
        html_escape(&r.partitions.join(", ")),
        pct(r.score),
        table(
            "",
            &["kernel", "killed", "survived", "not covered", "equivalent?", "argued", "timeout", "stillborn", "score"],
            &kernels
        ),
        table("", &["kernel", "place", "operator", "change", "detectors run", ""], &survivors),
    );
    page("vista mutate", &body, None)
}
