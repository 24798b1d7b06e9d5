//! `vista bless`: write goldens from renders, or accept the ones a check
//! left in its report.

use std::path::Path;

use vista::Config;
use vista_golden::{BlessOptions, GoldenError, Store};
use vista_project::Project;
use vista_render::Renderer;

/// Accepts the renders a check left in report folder `dir`.
pub fn from_report(
    project: &Project,
    config: &Config,
    case: Option<String>,
    force: bool,
    dir: &Path,
) -> Result<i32, GoldenError> {
    let store = Store::of_project(project, "vista bless")?;
    if config.in_ci && !force {
        return Err(GoldenError::Refused(
            "CI=true: refusing to bless goldens in CI; bless locally from the CI report, or pass --force".into(),
        ));
    }
    let shaders = vista_render::shader_set(project)?;
    let files_now = |shader: &str| -> Result<std::collections::BTreeMap<String, String>, String> {
        shaders.file_hashes(shader).map_err(|e| e.to_string())
    };
    let summary = vista_golden::pending::bless_from_report(&store, dir, case.as_deref(), &files_now)?;
    println!("{:<40} {:<10} PSNR against the golden it replaces", "case", "status");
    for r in &summary.rows {
        println!("{:<40} {:<10} {}", r.id, r.status, r.psnr_vs_previous);
    }
    let n = summary.rows.len();
    println!(
        "accepted {n} render{} from {} as golden{}",
        if n == 1 { "" } else { "s" },
        dir.display(),
        if n == 1 { "" } else { "s" }
    );
    Ok(0)
}

/// Renders the selected cases and writes their goldens.
pub fn bless(project: &Project, config: &Config, opts: BlessOptions) -> Result<i32, GoldenError> {
    let store = Store::of_project(project, "vista bless")?;
    let ctx = &Renderer::shared(&config.gpu, project, config.limits)?;
    let summary = vista_golden::bless(ctx, &store, &opts)?;
    println!("{:<40} {:<10} PSNR new vs old", "case", "status");
    for r in &summary.rows {
        println!("{:<40} {:<10} {}", r.id, r.status, r.psnr_vs_previous);
    }
    for w in &summary.warnings {
        println!("warning: {w}");
    }
    for o in &summary.orphans {
        println!("{} golden with no case: {}", if summary.pruned { "deleted" } else { "orphaned" }, o.display());
    }
    let n = summary.rows.len();
    println!("blessed {n} case{} on {}", if n == 1 { "" } else { "s" }, ctx.adapter_description());
    Ok(0)
}
