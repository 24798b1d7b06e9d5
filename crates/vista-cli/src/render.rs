//! `vista render`: one kernel at one setting into a PNG, EXR or `.npy`, and
//! the output-path checks every writing command shares.

use std::path::{Path, PathBuf};

use vista::Config;
use vista_golden::GoldenError;
use vista_project::Project;
use vista_render::Renderer;

use crate::graph_render;
use crate::input::{bad, parse_sets, registry};

/// The `render` command's arguments.
pub struct Args {
    pub kernel: String,
    pub preset: Option<String>,
    pub set: Vec<String>,
    pub size: String,
    pub crop: Option<String>,
    pub zoom: u32,
    pub out: std::path::PathBuf,
}

/// Renders `a.kernel` as asked; 1 where the output holds NaN/Inf or
/// unwritten texels.
pub fn render(project: &Project, config: &Config, a: Args) -> Result<i32, GoldenError> {
    let Args { kernel, preset, set, size, crop, zoom, out } = a;
    let k = registry(project)?.find(&kernel).cloned().map_err(bad)?;
    let p = k.resolve(preset.as_deref(), &parse_sets(&set)?).map_err(bad)?;
    let (w, h) = vista_kernels::parse_size(&size).map_err(bad)?;
    if !(1..=16).contains(&zoom) {
        return Err(bad(format!("--zoom {zoom} is out of range; allowed: 1 to 16")));
    }
    let shaders = vista_render::shader_set(project)?;
    // Every check that needs no device (bindings, input files) before one is made.
    let plan = vista_render::plan(&shaders, project.root(), &k, &p, &[], w, h, &config.limits)?;
    check_output_path(&k, &plan, &out)?;
    // --crop and --zoom apply to the first output, a texture whose layers
    // and slices are stacked top to bottom.
    let rect = match (plan.main_texture(), crop.as_deref()) {
        (None, _) if crop.is_some() || zoom > 1 => {
            return Err(bad(format!(
                "--crop and --zoom apply to a texture; kernel {kernel}'s first output, {}, is a buffer",
                plan.outputs[0].name
            )));
        }
        (Some(t), Some(c)) => Some(parse_crop(c, t.width, t.height * t.layers)?),
        _ => None,
    };
    let ctx = &Renderer::shared_with_shaders(&config.gpu, shaders, config.limits, project.root().map(Into::into))?;
    let shape = plan.main_texture().map(|t| match t.dimension {
        vista_texel::Dimension::D2 if t.layers == 1 && (t.width, t.height) == (w, h) => format!("{w}x{h}"),
        d => format!(
            "{}x{}x{} ({} output, stacked {}x{})",
            t.width,
            t.height,
            t.layers,
            d.name(),
            t.width,
            t.height * t.layers
        ),
    });
    let frame = |img: vista_image::Image| {
        let img = match rect {
            Some((x, y, cw, ch)) => img.crop(x, y, cw, ch).expect("the crop was checked against the size"),
            None => img,
        };
        if zoom > 1 { img.zoom(zoom) } else { img }
    };
    graph_render::render(ctx, &k, &plan, &out, shape, frame)
}

/// `-o`'s extension fits the kernel's first output: `.png` or `.exr` for a
/// texture, `.npy` for a buffer; and its folder is writable.
fn check_output_path(k: &vista_kernels::Kernel, plan: &vista_render::Plan, out: &Path) -> Result<(), GoldenError> {
    let first_is_buffer =
        matches!(plan.outputs.first().map(|o| &o.kind), Some(vista_render::PlannedKind::Buffer { .. }));
    let ext = out.extension().and_then(|e| e.to_str()).unwrap_or_default().to_ascii_lowercase();
    let want: &[&str] = if first_is_buffer { &["npy"] } else { &["png", "exr"] };
    if !want.contains(&ext.as_str()) {
        return Err(bad(format!(
            "output {} must end in .{} (kernel {}'s first output, {}, is a {})",
            out.display(),
            want.join(" or ."),
            k.name(),
            plan.outputs[0].name,
            if first_is_buffer { "buffer" } else { "texture" }
        )));
    }
    check_parent_writable(out)
}

/// `X,Y,W,H` inside a `width` x `height` frame.
pub fn parse_crop(text: &str, width: u32, height: u32) -> Result<(u32, u32, u32, u32), GoldenError> {
    let allowed = format!("X,Y,W,H in pixels with W, H >= 1, X + W <= {width} and Y + H <= {height} (the image)");
    let v: Vec<u32> = text
        .split(',')
        .map(|s| s.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad(format!("--crop {text} is not valid; expected {allowed}")))?;
    match v[..] {
        [x, y, w, h]
            if w >= 1 && h >= 1 && x as u64 + w as u64 <= width as u64 && y as u64 + h as u64 <= height as u64 =>
        {
            Ok((x, y, w, h))
        }
        _ => Err(bad(format!("--crop {text} does not fit; expected {allowed}"))),
    }
}

/// The directory a file will be written into exists, is one, and is writable.
pub fn check_parent_writable(file: &Path) -> Result<(), GoldenError> {
    let dir = match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if dir.exists() && !dir.is_dir() {
        return Err(bad(format!("output directory {} is not a directory (it is a file)", dir.display())));
    }
    if !dir.is_dir() {
        return Err(bad(format!("output directory {} does not exist", dir.display())));
    }
    probe_writable(&dir)
}

/// Creates the output directory of a sweep if needed and checks it is writable.
pub fn check_output_dir(dir: &Path) -> Result<(), GoldenError> {
    if dir.exists() && !dir.is_dir() {
        return Err(bad(format!("--out {} exists and is not a directory", dir.display())));
    }
    std::fs::create_dir_all(dir).map_err(|e| bad(format!("cannot create output directory {}: {e}", dir.display())))?;
    probe_writable(dir)
}

fn probe_writable(dir: &Path) -> Result<(), GoldenError> {
    let probe = dir.join(format!(".vista-write-probe-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| bad(format!("output directory {} is not writable: {e}", dir.display())))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}
