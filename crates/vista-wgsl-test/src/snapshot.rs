//! `@fragment @snapshot` tests: the fragment entry drawn full-screen into
//! a W x H rgba8unorm image, judged against `golden/wgsl/<file stem>/<fn>.png`
//! (every texel within one 8-bit step, the rounding two implementations
//! may differ by), or written there when blessing.

use std::path::{Path, PathBuf};

use vista_render::{OutputValue, Renderer};

use crate::rewrite::Snapshot;

/// Where snapshot `name` of test file `rel` keeps its golden, relative to
/// the project root.
pub fn golden_path(rel: &str, name: &str) -> String {
    format!("golden/wgsl/{}/{name}.png", crate::rewrite::stem(rel))
}

/// The manifest drawing `snap` of file `rel`.
fn manifest(rel: &str, snap: &Snapshot) -> String {
    let (w, h) = snap.size;
    format!(
        "summary = \"snapshot {name} of {rel}\"\nshader = \"{rel}\"\n\n[[resource]]\nname = \"snapshot\"\n\
         kind = \"texture\"\nformat = \"rgba8unorm\"\nsize = [{w}, {h}]\n\n[[pass]]\nkind = \"render\"\n\
         fragment = \"{name}\"\ntargets = [{{ resource = \"snapshot\", clear = [0.0, 0.0, 0.0, 1.0] }}]\n\n\
         [[output]]\nresource = \"snapshot\"\n",
        name = snap.name
    )
}

/// Draws `snap` and judges it against its golden, or (`bless`) writes
/// the golden; the error is the test's failure, one line.
pub fn judge(gpu: &Renderer, rel: &str, snap: &Snapshot, bless: bool) -> Result<(), String> {
    let root: PathBuf = gpu.root.clone().ok_or("a snapshot test needs a project root to keep its golden")?;
    let name = format!("wgsl-snapshot-{}-{}", rel.replace(['/', '.'], "-"), snap.name);
    let kernel = vista_manifest::Kernel::from_manifest(&name, rel, &manifest(rel, snap)).map_err(|e| e.to_string())?;
    let params = kernel.resolve(None, &[]).map_err(|e| e.to_string())?;
    let (w, h) = snap.size;
    let rendered = vista_render::render_with(gpu, &kernel, &params, &[], w, h)
        .map_err(|e| e.to_string().lines().next().unwrap_or_default().to_string())?;
    let Some(OutputValue::Texture { raw, .. }) = rendered.outputs.first().map(|o| &o.value) else {
        return Err("the snapshot did not come back".into());
    };
    let rel_golden = golden_path(rel, &snap.name);
    let path = root.join(&rel_golden);
    if bless {
        return write_golden(&root, &path, raw);
    }
    let bytes = match vista_project::guard::read_bytes(&root, &path, 256 << 20) {
        Ok(b) => b,
        Err(_) if !path.exists() => {
            return Err(format!("no golden {rel_golden}: look at the render, then vista test --bless"));
        }
        Err(e) => return Err(format!("{rel_golden}: {}", e.message)),
    };
    let golden = vista_image::decode_png16(&path, &bytes).map_err(|e| format!("{rel_golden}: {e}"))?;
    if (golden.width, golden.height) != (raw.width, raw.height) {
        return Err(format!(
            "{rel_golden} is {}x{}, the snapshot {}x{}; bless it again after checking the render",
            golden.width, golden.height, raw.width, raw.height
        ));
    }
    // One 8-bit step is what two implementations' rounding may differ by.
    let step = 1.0 / 255.0;
    let (mut off, mut worst, mut first) = (0usize, 0.0f32, None);
    for (i, (a, b)) in raw.data.iter().zip(&golden.data).enumerate() {
        let d = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
        worst = worst.max(d);
        if d > 1.5 * step {
            off += 1;
            first.get_or_insert((i as u32 % raw.width, i as u32 / raw.width));
        }
    }
    match first {
        None => Ok(()),
        Some((x, y)) => Err(format!(
            "differs from {rel_golden}: {off} of {} texels by more than one 8-bit step (max {worst:.4}, first at \
             {x},{y}; PSNR {:.1} dB)",
            raw.data.len(),
            vista_image::metrics::psnr(raw, &golden)
        )),
    }
}

/// The snapshot as its golden: a 16-bit PNG (the 8-bit values exactly),
/// written atomically under a real `golden/wgsl/<stem>/` folder.
fn write_golden(root: &Path, path: &Path, img: &vista_image::Image) -> Result<(), String> {
    let dir = path.parent().ok_or("a golden path has a folder")?;
    // Checked for symlinks on the way, then made.
    vista_image::real_dir_under(root, dir).map_err(|e| e.to_string())?;
    let bytes = vista_image::encode_png16(path, img).map_err(|e| e.to_string())?;
    vista_image::atomic_write(path, &bytes).map_err(|e| e.to_string())
}
