//! Golden harness: every case in `golden/cases.toml` is its own named test
//! (libtest-mimic), so `cargo test fbm` and nextest filter and shard them.
//! After the run it writes `target/vista-report/index.html`.

use std::sync::{Arc, Mutex};

use common::allow_no_gpu;
use libtest_mimic::{Arguments, Failed, Trial};
use vista_golden::{CheckOptions, Store};

mod common;

fn main() {
    let args = Arguments::from_args();
    let project = common::project();
    let store = Store::of_project(&project, "the golden tests").expect("repository root");
    let cases = store.load_cases().unwrap_or_else(|e| panic!("cannot load golden cases: {e}"));
    let manifest = Arc::new(store.manifest().unwrap_or_else(|e| panic!("cannot load manifest: {e}")));
    // One report per implementation (VISTA_BACKEND), so runs do not overwrite each other.
    let report_dir = match std::env::var("VISTA_BACKEND").ok().filter(|b| !b.is_empty() && b != "lavapipe") {
        Some(b) => project.root().expect("repository root").join(format!("target/vista-report-{b}")),
        None => project.report_dir().expect("repository root"),
    };
    let outcomes = Arc::new(Mutex::new(Vec::new()));

    // Listing must work without a device (nextest lists before it runs).
    let missing = if args.list { None } else { common::renderer().err() };
    // A run that will render clears the last report's case folders; one that
    // skips (no adapter) leaves the last report whole.
    if !args.list && missing.is_none() {
        vista_report::clear_case_folders(&report_dir).unwrap_or_else(|e| panic!("cannot clear the report: {e}"));
    }
    let no_gpu = missing.is_some();
    if let Some(e) = &missing {
        if allow_no_gpu() {
            eprintln!("\n!!! VISTA_ALLOW_NO_GPU=1 and no adapter: {e}");
            eprintln!(
                "!!! SKIPPING all {} golden cases: {}\n",
                cases.len(),
                cases.iter().map(|c| c.id.as_str()).collect::<Vec<_>>().join(", ")
            );
        }
    }

    let trials: Vec<Trial> = cases
        .iter()
        .map(|case| {
            let (case, store, manifest, outcomes, report_dir) =
                (case.clone(), store.clone(), manifest.clone(), outcomes.clone(), report_dir.clone());
            let name = format!("golden::{}::{}", case.kernel.name(), case.id);
            Trial::test(name, move || {
                let ctx = common::renderer().map_err(|e| Failed::from(format!("no GPU adapter: {e}")))?;
                // The in-process determinism check (two renders, bit-identical)
                // runs on the bless-time driver; other backends render once.
                let opts = CheckOptions { twice: ctx.backend() == "lavapipe" };
                let o = vista_report::file_case(
                    &report_dir,
                    vista_golden::check_case(ctx, &store, &manifest, &case, &opts),
                );
                let result = if o.passed() { Ok(()) } else { Err(Failed::from(o.explain(&report_dir))) };
                outcomes.lock().expect("outcomes").push(o);
                result
            })
            .with_ignored_flag(no_gpu && allow_no_gpu())
        })
        .collect();

    let conclusion = libtest_mimic::run(&args, trials);
    let outcomes = outcomes.lock().expect("outcomes");
    if !outcomes.is_empty() {
        let r = common::renderer();
        let backend = r.as_ref().map(|c| c.backend().to_string()).unwrap_or_default();
        let run = vista_report::RunSummary {
            command: match backend.as_str() {
                "lavapipe" => "cargo test --test golden".into(),
                b => format!("VISTA_BACKEND={b} cargo test --test golden"),
            },
            adapter: r.map(|c| c.adapter_description()).unwrap_or_default(),
            backend,
            ..Default::default()
        };
        match vista_report::write_report(&report_dir, &run, &outcomes) {
            Ok(index) => eprintln!("vista report: {}", index.display()),
            Err(e) => eprintln!("could not write the vista report: {e}"),
        }
    }
    conclusion.exit();
}
