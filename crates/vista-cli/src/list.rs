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

/// `vista list --layout`: for each kernel and each shader its passes
/// compose, every buffer binding with each leaf's offset, path and type;
/// 2 where a kernel's WGSL does not compose.
pub fn layouts(project: &Project) -> Result<i32, GoldenError> {
    let kernels = registry(project)?;
    let shaders = vista_render::shader_set(project)?;
    let mut bad = 0;
    for k in kernels.kernels() {
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
            for b in vista_manifest::leaves::buffer_layouts(&module) {
                println!(
                    "    @group({}) @binding({}) var<{}> {}: {} bytes",
                    b.group, b.binding, b.space, b.name, b.size
                );
                for l in &b.leaves {
                    println!("      {:<24} {:<32} {}", vista_manifest::leaves::offset_text(l), l.path, l.ty);
                }
            }
        }
        println!();
    }
    Ok(if bad == 0 { 0 } else { 2 })
}
