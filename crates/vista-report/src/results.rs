//! Results CI systems read (SPEC 15): JUnit XML (one testcase per case,
//! the failure text being the terminal block), JSON (per case: metrics,
//! thresholds, verdict, report anchor, golden used) and GitHub Actions
//! `::error` annotations pointing at each failing case in
//! `golden/cases.toml`.

use std::path::Path;
use std::time::Duration;

use quick_junit::{NonSuccessKind, Property, Report, TestCase, TestCaseStatus, TestSuite};
use vista_golden::{GoldenError, Outcome, Verdict};

use crate::report::RunSummary;

/// The JUnit XML of a check: suite `vista`, one testcase per case named
/// `golden::<kernel>::<case>` (classname `golden::<kernel>`); a failure's
/// text is the block `vista check` prints; a missing golden or an error is
/// an error; an expected failure is skipped with its reason.
pub fn junit_xml(run: &RunSummary, outcomes: &[Outcome], report_dir: &Path) -> Result<String, GoldenError> {
    let mut suite = TestSuite::new("vista");
    suite.add_properties([
        Property::new("backend", run.backend.as_str()),
        Property::new("adapter", run.adapter.as_str()),
        Property::new("command", run.command.as_str()),
    ]);
    for o in outcomes {
        let block = o.explain(report_dir);
        let first = o.problems.first().cloned().unwrap_or_default();
        let status = match o.verdict {
            Verdict::Pass => TestCaseStatus::success(),
            Verdict::ExpectedFail => {
                let mut s = TestCaseStatus::skipped();
                s.set_type("expected failure").set_message(o.notes.join("; "));
                s
            }
            Verdict::Fail => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_type("golden mismatch").set_message(first).set_description(block);
                s
            }
            Verdict::Missing | Verdict::Error => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Error);
                let ty = if o.verdict == Verdict::Missing { "missing golden" } else { "error" };
                s.set_type(ty).set_message(first).set_description(block);
                s
            }
        };
        let mut case = TestCase::new(format!("golden::{}::{}", o.kernel, o.id), status);
        case.set_classname(format!("golden::{}", o.kernel)).set_time(Duration::from_secs_f64(o.gpu_ms / 1e3));
        suite.add_test_case(case);
    }
    let mut report = Report::new("vista check");
    report.add_test_suite(suite);
    if !run.unit_tests.is_empty() {
        report.add_test_suite(unit_test_suite(&run.unit_tests));
    }
    report.to_string().map_err(|e| GoldenError::Io { path: "junit".into(), message: e.to_string() })
}

/// The JUnit suite `wgsl`: a testcase per WGSL unit test (classname
/// `wgsl::<file>`), a failure's message its first failed assertion and
/// its text all of them.
fn unit_test_suite(tests: &[crate::UnitTest]) -> TestSuite {
    let mut suite = TestSuite::new("wgsl");
    for t in tests {
        let status = match t.failures.first() {
            None => TestCaseStatus::success(),
            Some(first) => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_type("assertion").set_message(first.as_str()).set_description(t.failures.join("\n"));
                s
            }
        };
        let mut case = TestCase::new(t.id.as_str(), status);
        case.set_classname(t.id.rsplit_once("::").map_or(t.id.as_str(), |(file, _)| file));
        suite.add_test_case(case);
    }
    suite
}

/// The word a verdict is reported as.
pub fn verdict_name(v: Verdict) -> &'static str {
    match v {
        Verdict::Pass => "pass",
        Verdict::Fail => "fail",
        Verdict::Missing => "missing",
        Verdict::Error => "error",
        Verdict::ExpectedFail => "expected_fail",
    }
}

/// The JSON of a check: the run, then per case its verdict, metrics,
/// thresholds, problems and notes, report anchor, golden used and bless
/// command.
pub fn json_results(run: &RunSummary, outcomes: &[Outcome]) -> serde_json::Value {
    let num = |v: f64| if v.is_finite() { serde_json::json!(v) } else { serde_json::json!(v.to_string()) };
    let cases: Vec<serde_json::Value> = outcomes
        .iter()
        .map(|o| {
            serde_json::json!({
                "id": o.id,
                "kernel": o.kernel,
                "verdict": verdict_name(o.verdict),
                "passed": o.passed(),
                "metrics": o.metrics.map(|m| serde_json::json!({
                    "psnr": num(m.psnr),
                    "ssim": num(m.ssim),
                    "flip_mean": m.flip_mean,
                    "max_abs": num(m.max_abs),
                    "bad_pixels": m.bad_pixels,
                    "nan": m.nan,
                })),
                "thresholds": {
                    "psnr": o.psnr_threshold,
                    "same_driver": o.same_driver,
                    "min_ssim": o.min_ssim,
                    "max_flip": o.max_flip,
                },
                "problems": o.problems,
                "notes": o.notes,
                "changed_files": o.changed_files,
                "report_anchor": format!("index.html#{}", crate::report::anchor(&o.id)),
                "golden": o.golden.as_ref().map(|g| serde_json::json!({
                    "path": (o.files.expected8.is_some() || o.files.thumb.is_some()).then(|| format!("golden/{}", o.golden_file)),
                    "backend": g.backend,
                    "adapter": g.adapter,
                    "date": g.date,
                })),
                "gpu_ms": o.gpu_ms,
                "size": [o.width, o.height],
                "bless_command": o.bless_command,
            })
        })
        .collect();
    serde_json::json!({
        "backend": run.backend,
        "adapter": run.adapter,
        "command": run.command,
        "passed": outcomes.iter().filter(|o| o.passed()).count(),
        "failed": outcomes.iter().filter(|o| !o.passed()).count(),
        "unit_tests": run.unit_tests.iter().map(|t| serde_json::json!({
            "test": t.id,
            "passed": t.passed(),
            "failures": t.failures,
        })).collect::<Vec<_>>(),
        "cases": cases,
    })
}

/// [`json_results`] as text: the run's fields one per line, then each
/// case on one line of its own. Pretty-printed, a passing case took 0.9 KB
/// of a long suite's report; on one line it takes 0.6 KB and stays one
/// `grep` away.
pub fn json_text(run: &RunSummary, outcomes: &[Outcome]) -> String {
    one_case_per_line(json_results(run, outcomes))
}

/// The text of a results object whose `cases` array gets one line per case.
fn one_case_per_line(mut value: serde_json::Value) -> String {
    let fields = value.as_object_mut().expect("json_results is an object");
    let cases = fields.remove("cases").unwrap_or_default();
    let mut text = String::from("{\n");
    for (key, v) in fields.iter() {
        text += &format!("  {}: {},\n", serde_json::Value::from(key.as_str()), v);
    }
    text += "  \"cases\": [";
    for (i, case) in cases.as_array().into_iter().flatten().enumerate() {
        text += if i == 0 { "\n    " } else { ",\n    " };
        text += &case.to_string();
    }
    text += "\n  ]\n}\n";
    text
}

/// GitHub Actions annotations, one per failing case, at the line of its
/// `[[case]]` header in `cases_text` (`cases_file` as the repository
/// names it).
pub fn github_annotations(outcomes: &[Outcome], cases_file: &str, cases_text: &str) -> Vec<String> {
    outcomes
        .iter()
        .filter(|o| !o.passed())
        .map(|o| {
            let line = case_line(cases_text, &o.id).map(|l| format!(",line={l}")).unwrap_or_default();
            let what = o.problems.first().map(String::as_str).unwrap_or("failed");
            // Annotation text: newlines and '%' are escaped as GitHub reads them.
            let text = format!("case {}: {what}", o.id).replace('%', "%25").replace('\r', "%0D").replace('\n', "%0A");
            format!("::error file={cases_file}{line},title=vista {}::{text}", o.id)
        })
        .collect()
}

/// The 1-based line of the `[[case]]` header of case `id`.
pub fn case_line(text: &str, id: &str) -> Option<usize> {
    let mut header = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with("[[case]]") {
            header = Some(i + 1);
        } else if let Some(rest) = t.strip_prefix("id")
            && let Some(value) = rest.trim_start().strip_prefix('=')
            && value.trim().trim_matches('"') == id
        {
            return header;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_text_has_one_case_per_line_and_parses_back() {
        let value = serde_json::json!({
            "backend": "lavapipe",
            "passed": 2,
            "cases": [{"id": "a", "metrics": {"psnr": "inf"}}, {"id": "b\\\"c\n", "size": [32, 32]}],
        });
        let text = one_case_per_line(value.clone());
        assert_eq!(serde_json::from_str::<serde_json::Value>(&text).unwrap(), value);
        let case_lines: Vec<&str> = text.lines().filter(|l| l.starts_with("    {")).collect();
        assert_eq!(case_lines.len(), 2, "{text}");
        assert!(case_lines[1].contains(r#""id":"b\\\"c\n""#), "{text}");
        let empty = serde_json::json!({"backend": "x", "cases": []});
        assert_eq!(serde_json::from_str::<serde_json::Value>(&one_case_per_line(empty.clone())).unwrap(), empty);
    }

    /// WGSL unit tests: a JUnit suite `wgsl` (a failure's message its
    /// first failed assertion) and `unit_tests` in the JSON.
    #[test]
    fn unit_tests_are_a_junit_suite_and_a_json_list() {
        let failing = vec!["shaders/a.test.wgsl:3:5: expect(false)".to_string(), "and 2 more".to_string()];
        let run = RunSummary {
            unit_tests: vec![
                crate::UnitTest { id: "wgsl::a::bad".into(), failures: failing.clone(), coverage: None },
                crate::UnitTest { id: "wgsl::a::good".into(), failures: Vec::new(), coverage: None },
            ],
            ..Default::default()
        };
        let xml = junit_xml(&run, &[], Path::new("r")).unwrap();
        let report = Report::deserialize_from_str(&xml).unwrap();
        let suite = report.test_suites.iter().find(|s| s.name.as_str() == "wgsl").expect("a wgsl suite");
        assert_eq!(suite.test_cases.len(), 2);
        let bad = &suite.test_cases[0];
        assert_eq!((bad.name.as_str(), bad.classname.as_deref()), ("wgsl::a::bad", Some("wgsl::a")));
        match &bad.status {
            TestCaseStatus::NonSuccess { kind: NonSuccessKind::Failure, message, description, .. } => {
                assert_eq!(message.as_deref(), Some(failing[0].as_str()));
                assert_eq!(description.as_deref(), Some(failing.join("\n").as_str()));
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(suite.test_cases[1].status, TestCaseStatus::Success { .. }));
        let json = json_results(&run, &[]);
        assert_eq!(
            json["unit_tests"][0],
            serde_json::json!({"test": "wgsl::a::bad", "passed": false, "failures": failing})
        );
        assert_eq!(json["unit_tests"][1]["passed"], true);
        // No unit tests: no wgsl suite.
        let none = junit_xml(&RunSummary::default(), &[], Path::new("r")).unwrap();
        assert!(Report::deserialize_from_str(&none).unwrap().test_suites.iter().all(|s| s.name.as_str() != "wgsl"));
    }

    #[test]
    fn case_line_is_the_header_of_the_case() {
        let text = "# cases\n[[case]]\nid = \"a\"\nkernel = \"k\"\n\n[[case]]\nkernel = \"k\"\nid = \"b\"\n";
        assert_eq!(case_line(text, "a"), Some(2));
        assert_eq!(case_line(text, "b"), Some(6));
        assert_eq!(case_line(text, "c"), None);
    }
}
