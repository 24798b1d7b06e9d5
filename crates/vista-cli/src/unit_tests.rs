//! `vista test [FILTER]`: the project's WGSL unit tests (`@test` functions
//! in `shaders/**/*.test.wgsl` or `.test.wesl`), each file one run on the engine; a line
//! per test, a failing assertion at the user's file:line with its values.

use vista::Config;
use vista_golden::GoldenError;
use vista_project::Project;
use vista_render::Renderer;
use vista_wgsl_test::TestResult;

/// The line(s) `vista test` prints for one test.
fn print_result(r: &TestResult) {
    match r.passed() {
        true => println!("ok     {}", r.id),
        false => r.explain().iter().for_each(|line| println!("FAIL   {}: {line}", r.id)),
    }
}

/// The project's test files (`*.test.wgsl`, `*.test.wesl` under `shaders/`) holding a
/// test `filter` picks (a file runs whole), and whether `id` is shown.
fn picked_files(project: &Project, filter: Option<&str>) -> Result<(Vec<(String, String)>, usize), GoldenError> {
    let files = vista_wgsl_test::test_files(project)?;
    let all = files.len();
    let wanted = |id: &str| filter.is_none_or(|f| id.contains(f));
    let picked = files
        .into_iter()
        .filter(|(rel, text)| match vista_wgsl_test::list(rel, text) {
            Ok(ids) => ids.iter().any(|id| wanted(id)),
            Err(_) => wanted(&vista_wgsl_test::test_id(rel, "*")),
        })
        .collect();
    Ok((picked, all))
}

/// Every picked test file run on `base`, the results `filter` picks.
fn run_all(
    base: &Renderer,
    sources: &vista_render::Sources,
    files: &[(String, String)],
    filter: Option<&str>,
    bless: bool,
) -> Vec<TestResult> {
    let wanted = |id: &str| filter.is_none_or(|f| id.contains(f));
    files
        .iter()
        .flat_map(|(rel, text)| vista_wgsl_test::run_file_with(base, sources, rel, text, bless))
        .filter(|r| wanted(&r.id))
        .collect()
}

pub fn test(
    project: &Project,
    config: &Config,
    filter: Option<&str>,
    matrix: bool,
    bless: bool,
    coverage: bool,
) -> Result<i32, GoldenError> {
    if bless && config.in_ci {
        return Err(GoldenError::Refused(
            "CI=true: refusing to bless snapshot goldens in CI; bless locally after looking at the render".into(),
        ));
    }
    let (picked, all) = picked_files(project, filter)?;
    if picked.is_empty() {
        match filter {
            Some(f) => println!("no WGSL test matches {f} (of {all} test files under shaders/)"),
            None => println!("no WGSL tests: write @test functions in shaders/**/*.test.wgsl (or .test.wesl)"),
        }
        return Ok(0);
    }
    let sources = vista_render::Sources::of(project)?;
    if matrix {
        return test_matrix(project, config, &sources, &picked, filter);
    }
    let base = Renderer::shared(&config.gpu, project, config.limits)?;
    let results = run_all(&base, &sources, &picked, filter, bless);
    results.iter().for_each(print_result);
    let failed = results.iter().filter(|r| !r.passed()).count();
    println!(
        "{} passed, {failed} failed ({} on {})",
        results.len() - failed,
        base.adapter_description(),
        base.backend()
    );
    if coverage {
        cover(project, &base, &sources, &picked)?;
    }
    Ok(if failed == 0 { 0 } else { 1 })
}

/// `vista test --coverage`: each picked file's tests run again with
/// coverage counters, the hits summed into `<report dir>/wgsl-tests/`
/// (`lcov.info` and the coverage pages), and the summary line.
fn cover(
    project: &Project,
    base: &Renderer,
    sources: &vista_render::Sources,
    files: &[(String, String)],
) -> Result<(), GoldenError> {
    let mut total = vista_coverage::Counts::default();
    for (rel, text) in files {
        match vista_wgsl_test::cover_file(base, sources, rel, text) {
            Ok(counts) => total.merge(&counts),
            Err(why) => println!("coverage: {rel} not measured: {why}"),
        }
    }
    let Some(dir) = project.report_dir().map(|d| d.join("wgsl-tests")) else { return Ok(()) };
    let text = sources.shader_set().text_reader();
    vista_report::write_coverage(&dir, &total, &|file| text.read(file).map(|(t, _)| t))?;
    let lcov = dir.join(vista_check::LCOV_FILE);
    vista_image::atomic_write(&lcov, total.lcov("wgsl-tests").as_bytes())?;
    println!("coverage: {}: {}", vista_report::coverage_line(&total), lcov.display());
    Ok(())
}

/// `vista test --matrix`: every test on lavapipe, SwiftShader and the
/// browser, one test x backend table, each failure under it.
fn test_matrix(
    project: &Project,
    config: &Config,
    sources: &vista_render::Sources,
    files: &[(String, String)],
    filter: Option<&str>,
) -> Result<i32, GoldenError> {
    const BACKENDS: &[&str] = &["lavapipe", "swiftshader", "browser"];
    let mut columns: Vec<(&str, Result<Vec<TestResult>, String>)> = Vec::new();
    for &b in BACKENDS {
        let column = vista_render::own_device(&config.gpu, Some(b), None).map_err(|e| e.to_string()).map(|ctx| {
            let gpu = Renderer::with_shaders(&ctx, sources.shader_set(), config.limits, project.root().map(Into::into));
            run_all(&gpu, sources, files, filter, false)
        });
        columns.push((b, column));
    }
    let ids: Vec<String> = columns
        .iter()
        .find_map(|(_, c)| c.as_ref().ok())
        .map_or_else(Vec::new, |rs| rs.iter().map(|r| r.id.clone()).collect());
    let width = ids.iter().map(String::len).max().unwrap_or(4).max(4);
    println!("{:<width$}  {}", "test", BACKENDS.iter().map(|b| format!("{b:<12}")).collect::<String>());
    let mut failed = 0;
    for (i, id) in ids.iter().enumerate() {
        let cells: String = columns
            .iter()
            .map(|(_, c)| {
                let cell = match c {
                    Ok(rs) if rs[i].passed() => "ok",
                    Ok(_) => {
                        failed += 1;
                        "FAIL"
                    }
                    Err(_) => "n/a",
                };
                format!("{cell:<12}")
            })
            .collect();
        println!("{id:<width$}  {cells}");
    }
    for (b, c) in &columns {
        for r in c.iter().flatten().filter(|r| !r.passed()) {
            println!("- FAIL {} on {b}: {}", r.id, r.explain().first().map_or("", String::as_str));
        }
    }
    let skipped: Vec<String> =
        columns.iter().filter_map(|(b, c)| c.as_ref().err().map(|e| format!("{b}: {e}"))).collect();
    for s in &skipped {
        println!("!!! SKIPPED {s}");
    }
    println!(
        "matrix: {} tests x {} backends, {failed} failed, {} backend(s) skipped",
        ids.len(),
        columns.len() - skipped.len(),
        skipped.len()
    );
    let skipped_ok = skipped.is_empty() || config.allow_no_gpu;
    Ok(if failed == 0 && skipped_ok { 0 } else { 1 })
}
