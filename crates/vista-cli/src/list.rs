//! `vista list`: every kernel with its params and presets; a broken
//! manifest or WGSL that does not compose is shown and fails the listing.
//! `--layout`: each kernel's buffer bindings, leaf by leaf.

use vista_golden::GoldenError;
use vista_project::Project;

use crate::input::registry;

/// Lists the project's kernels (`names`: `kernel preset` pairs only); 2
/// where one is not usable.
pub fn run(project: &Project, names: bool) -> Result<i32, GoldenError> {
    let kernels = registry(project)?;
    if names {
        for k in kernels.kernels() {
            for p in k.presets() {
                println!("{} {}", k.name(), p.name);
            }
        }
    } else {
        list(&kernels);
    }
    // A broken manifest is shown, and fails the listing, but hides
    // no other kernel.
    for (name, e) in kernels.broken() {
        println!("{name} — broken manifest: {e}\n");
        eprintln!("error: kernel {name} is not usable: {e}");
    }
    // So is a kernel whose WGSL does not compose.
    let shaders = vista_render::shader_set(project)?;
    let mut bad_wgsl = 0;
    for k in kernels.kernels() {
        if let Err(e) = vista_render::composes(&shaders, k) {
            println!("{} — bad — WGSL: {e}\n", k.name());
            eprintln!("error: kernel {} does not compose: {e}", k.name());
            bad_wgsl += 1;
        }
    }
    Ok(if kernels.broken().is_empty() && bad_wgsl == 0 { 0 } else { 2 })
}

fn list(kernels: &vista_kernels::Registry) {
    for k in kernels.kernels() {
        println!("{} — {}", k.name(), k.summary());
        println!("  params:");
        for p in k.params() {
            println!("    {:<22} default {:<14} {:<40} {}", p.name, p.default, p.kind.range_text(), p.doc);
        }
        println!("  presets:");
        for p in k.presets() {
            let set = p.set.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ");
            println!(
                "    {:<22} {}{}",
                p.name,
                p.doc,
                if set.is_empty() { String::new() } else { format!("  [{set}]") }
            );
        }
        println!();
    }
}

/// `vista list --layout [KERNEL]`: for each kernel (or only `only`) and
/// each shader its passes compose, every buffer binding with each leaf's
/// offset, path and type, and for a binding given by leaf path whether
/// each leaf is `set` or left `zero`; 2 where a kernel's WGSL does not
/// compose.
pub fn layouts(project: &Project, only: Option<&str>) -> Result<i32, GoldenError> {
    let kernels = registry(project)?;
    if let Some(name) = only {
        kernels.find(name).map_err(|e| GoldenError::BadInput(e.to_string()))?;
    }
    let shaders = vista_render::shader_set(project)?;
    let mut bad = 0;
    for k in kernels.kernels().iter().filter(|k| only.is_none_or(|n| n == k.name())) {
        println!("{} — {}", k.name(), k.summary());
        let p = k.resolve(None, &[]).map_err(|e| GoldenError::BadInput(e.to_string()))?;
        let mut seen: Vec<String> = Vec::new();
        for i in 0..k.graph().passes.len() {
            let name = k.pass_shader_for(i, &p);
            if seen.contains(&name) {
                continue;
            }
            seen.push(name.clone());
            let module = match shaders.compose(&name) {
                Ok(m) => m,
                Err(e) => {
                    println!("  {name}: does not compose: {}", e.to_string().lines().next().unwrap_or_default());
                    bad += 1;
                    continue;
                }
            };
            println!("  {}:", name.split(['?', '|']).next().unwrap_or(&name));
            let pass = &k.graph().passes[i];
            for b in vista_manifest::leaves::buffer_layouts(&module) {
                // The resource bound to it, if the manifest gives it by leaf path.
                let bound = pass.bind.iter().find(|(v, _)| b.named(v)).map(|(_, l)| l.resource.as_str());
                let given = vista_render::leaf_values::manifest_leaves(project.root(), k, bound.unwrap_or(&b.name))
                    .map_err(GoldenError::BadInput)?;
                println!(
                    "    @group({}) @binding({}) var<{}> {}: {} bytes{}",
                    b.group,
                    b.binding,
                    b.space,
                    b.name,
                    b.size,
                    if given.is_some() { " (given by leaf path; others zero)" } else { "" }
                );
                for l in &b.leaves {
                    let set = match &given {
                        Some(g) if vista_render::leaf_values::is_given(&l.path, g) => "  set",
                        Some(_) => "  zero",
                        None => "",
                    };
                    let line = format!(
                        "      {:<24} {:<32} {:<14}{set}",
                        vista_manifest::leaves::offset_text(l),
                        l.path,
                        l.ty
                    );
                    println!("{}", line.trim_end());
                }
            }
        }
        println!();
    }
    Ok(if bad == 0 { 0 } else { 2 })
}

/// `vista list --coverage`: each kernel's cases run with coverage
/// counters, then per kernel the lines and branch arms none of them
/// reaches (a kernel without cases: every line of its files).
pub fn coverage(project: &Project, config: &vista::Config) -> Result<i32, GoldenError> {
    let kernels = registry(project)?;
    let store = vista_golden::Store::of_project(project, "vista list --coverage")?;
    let cases = store.load_cases()?;
    let gpu = vista_render::Renderer::shared(&config.gpu, project, config.limits)?;
    let covered = gpu.shaders.covered(gpu.ctx.vertex_writes_storage());
    let mut failed = 0;
    for k in kernels.kernels() {
        let mine: Vec<&vista_golden::Case> = cases.iter().filter(|c| c.kernel.name() == k.name()).collect();
        // vista's built-in kernels a project has no case of are not its own.
        if mine.is_empty() && k.origin().starts_with("<built-in>") {
            continue;
        }
        let mut counts = vista_coverage::Counts::default();
        let mut why = Vec::new();
        for c in &mine {
            match vista_golden::cover_case(&gpu, c) {
                Ok(r) => {
                    counts.merge(&r.counts);
                    why.extend(r.not_measured.into_iter().map(|w| format!("{}: {w}", c.id)));
                }
                Err(e) => why.push(format!("{}: the coverage run failed: {e}", c.id)),
            }
        }
        if mine.is_empty() {
            // No case: every measured line of the kernel's files is unreached.
            let p = k.resolve(None, &[]).map_err(|e| GoldenError::BadInput(e.to_string()))?;
            for i in 0..k.graph().passes.len() {
                match covered.coverage(&k.pass_shader_for(i, &p)) {
                    Ok(cov) => counts.merge(&cov.unrun()),
                    Err(e) => why.push(e.to_string().lines().next().unwrap_or_default().to_string()),
                }
            }
        }
        println!("{}: {} by {} case(s)", k.name(), vista_report::coverage_line(&counts), mine.len());
        for file in counts.files() {
            let lines: Vec<u32> = counts.lines(&file).into_iter().filter(|l| l.1 == 0).map(|l| l.0).collect();
            let arms: Vec<String> = counts
                .arms(&file)
                .into_iter()
                .filter(|a| a.3 == 0)
                .map(|(line, col, arm, _)| format!("{line}:{col} arm {arm}"))
                .collect();
            if !lines.is_empty() {
                println!("  {file}: lines not reached: {}", ranges(&lines));
            }
            if !arms.is_empty() {
                println!("  {file}: branch arms never taken: {}", arms.join(", "));
            }
        }
        for w in &why {
            println!("  not measured: {w}");
        }
        failed += usize::from(!why.is_empty());
    }
    Ok(if failed == 0 { 0 } else { 2 })
}

/// `3, 5-7, 9` for lines 3 5 6 7 9.
fn ranges(lines: &[u32]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let mut j = i;
        while j + 1 < lines.len() && lines[j + 1] == lines[j] + 1 {
            j += 1;
        }
        out.push(if i == j { lines[i].to_string() } else { format!("{}-{}", lines[i], lines[j]) });
        i = j + 1;
    }
    out.join(", ")
}
