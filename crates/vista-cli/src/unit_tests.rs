//! `vista test [FILTER]`: the project's WGSL unit tests (`@test` functions
//! in `shaders/**/*.test.wgsl`), each file one run on the engine; a line
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

pub fn test(project: &Project, config: &Config, filter: Option<&str>) -> Result<i32, GoldenError> {
    let files: Vec<(String, String)> = project
        .shader_files()?
        .into_iter()
        .filter(|f| f.rel.ends_with(".test.wgsl"))
        .map(|f| (f.rel, f.text))
        .collect();
    let wanted = |id: &str| filter.is_none_or(|f| id.contains(f));
    // A file runs whole (one submission); only the tests the filter picks are shown.
    let picked: Vec<&(String, String)> = files
        .iter()
        .filter(|(rel, text)| match vista_wgsl_test::list(rel, text) {
            Ok(ids) => ids.iter().any(|id| wanted(id)),
            Err(_) => wanted(&vista_wgsl_test::test_id(rel, "*")),
        })
        .collect();
    if picked.is_empty() {
        match filter {
            Some(f) => println!("no WGSL test matches {f} (of {} test files under shaders/)", files.len()),
            None => println!("no WGSL tests: write @test functions in shaders/**/*.test.wgsl"),
        }
        return Ok(0);
    }
    let base = Renderer::shared(&config.gpu, project, config.limits)?;
    let sources = vista_render::Sources::of(project)?;
    let (mut passed, mut failed) = (0, 0);
    for (rel, text) in picked {
        for r in vista_wgsl_test::run_file(&base, &sources, rel, text).into_iter().filter(|r| wanted(&r.id)) {
            print_result(&r);
            if r.passed() {
                passed += 1;
            } else {
                failed += 1;
            }
        }
    }
    println!("{passed} passed, {failed} failed ({} on {})", base.adapter_description(), base.backend());
    Ok(if failed == 0 { 0 } else { 1 })
}
