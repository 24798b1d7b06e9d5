//! `vista mutate` against this checkout's fbm suite: a known-bad mutant is
//! killed (naming the case that killed it), and a change to a component the
//! goldens never read is killed by the unit test that reads it.

mod common;

use vista_golden::Store;
use vista_mutate::{Planned, mutants};
use vista_render::Renderer;

fn run_one(gpu: &Renderer, file: &str, line_text: &str, before: &str, after: &str) -> vista_mutate::MutantReport {
    let project = common::project();
    let store = Store::of_project(&project, "tests").unwrap();
    let all = store.load_cases().unwrap();
    let cases = vista_golden::select(&all, Some("fbm-*")).unwrap();
    let text = std::fs::read_to_string(project.root().unwrap().join("shaders").join(file)).unwrap();
    // The last line holding the text (pcg3d mixes twice; its final z is the unread one).
    let line = text.lines().collect::<Vec<_>>().iter().rposition(|l| l.contains(line_text)).expect("line in the shader")
        as u32
        + 1;
    let mutant = mutants(file, &text)
        .into_iter()
        .find(|m| m.line == line && m.before == before && m.after == after)
        .unwrap_or_else(|| panic!("no mutant {before} -> {after} on {file}:{line}"));
    let kernel = vista_kernels::find("fbm").unwrap();
    let planned = [Planned { kernel: kernel.clone(), mutant }];
    let judge = vista_mutate::Judge::new(gpu, &project, &store, &cases, &planned).unwrap();
    let mut r = vista_check::mutants(&judge, &planned, 1, &mut |_: &vista_check::Filed| {});
    r.pop().unwrap()
}

fn a_known_bad_mutant_is_killed_by_a_golden_case(gpu: &Renderer) {
    // The display map 0.5 + 0.5 f / A becomes 0.5 - 0.5 f / A: every image inverts.
    let r = run_one(gpu, "fbm.wgsl", "let value = 0.5 + 0.5 * f", "+", "-");
    assert_eq!(r.outcome, "killed", "{r:?}");
    assert_eq!(r.killed_by.as_deref(), Some("fbm-perlin-default"), "{r:?}");
    // Judged by check's own verdict, whose words it carries.
    assert!(r.reason.as_deref().is_some_and(|w| w.contains("is below the threshold 60.0 dB")), "{r:?}");
    assert_eq!(r.cases_run, 1, "stops at the first failure: {r:?}");
}

fn a_change_the_goldens_never_read_is_killed_by_the_unit_test_that_does(gpu: &Renderer) {
    // pcg3d's z component: fbm's value noise reads only .x, so every fbm
    // case passes; shaders/lib/hash.test.wgsl checks all three words.
    let r = run_one(gpu, "lib/hash.wgsl", "v.z += v.x * v.y;", "*", "/");
    assert_eq!(r.outcome, "killed", "{r:?}");
    assert_eq!(r.killed_by.as_deref(), Some("wgsl::hash::pcg3d_of_the_origin"), "{r:?}");
    let reason = r.reason.as_deref().unwrap_or_default();
    assert!(
        reason.contains("hash.test.wgsl:12:5: expectEqU(actual ") && reason.contains("expected 1058359340"),
        "{r:?}"
    );
    assert!(!r.equivalent, "{r:?}");
}

/// The plan mutates only functions fbm's main reaches: fbm2 and the noise,
/// never ridged2 or ridged_max in the same module.
fn only_functions_the_kernel_reaches_are_mutated(_gpu: &Renderer) {
    let project = common::project();
    let files = project.shader_files().unwrap();
    let shaders = vista_render::shader_set(&project).unwrap();
    let fbm = vista_kernels::find("fbm").unwrap();
    let opts =
        vista_mutate::Options { kernel: None, case_glob: None, sample: None, seed: 1, jobs: 1, partition: (1, 1) };
    let plan = vista_mutate::plan(&files, &shaders, std::slice::from_ref(fbm), &opts).unwrap();
    let fractal = files.iter().find(|f| f.rel == "lib/fractal.wgsl").unwrap();
    let fns = vista_mutate::mutants::functions(&fractal.text);
    let body = |name: &str| fns.iter().find(|f| f.name == name).unwrap().body;
    let inside =
        |m: &vista_mutate::Mutant, (a, b): (usize, usize)| m.file == "lib/fractal.wgsl" && a <= m.start && m.end <= b;
    assert!(plan.iter().any(|p| inside(&p.mutant, body("fbm2"))), "fbm2 is not mutated");
    assert!(!plan.iter().any(|p| inside(&p.mutant, body("ridged2")) || inside(&p.mutant, body("ridged_max"))));
    assert!(plan.iter().any(|p| p.mutant.file == "lib/hash.wgsl"), "pcg3d (value noise) is reached");
}

fn main() {
    common::gpu_tests![
        a_known_bad_mutant_is_killed_by_a_golden_case,
        a_change_the_goldens_never_read_is_killed_by_the_unit_test_that_does,
        only_functions_the_kernel_reaches_are_mutated,
    ];
}
