//! `vista render` of a pass graph (SPEC 14 part 2): every output written,
//! the first to `-o`, the others beside it as `<stem>.<output>.<ext>`
//! (textures: the PNG view or, for `-o x.exr`, raw EXR; buffers: `.npy`).

use std::path::{Path, PathBuf};

use vista_golden::GoldenError;
use vista_image::Image;
use vista_kernels::Kernel;
use vista_render::{OutputValue, Plan, Renderer};

/// The file output `name` goes to, given `-o out` (the first output: `out`).
pub fn output_path(out: &Path, first: bool, name: &str, buffer: bool) -> PathBuf {
    let ext = match (buffer, out.extension().and_then(|e| e.to_str())) {
        (true, _) => "npy".to_string(),
        // Beside a buffer's `-o x.npy`, a texture gets its PNG view.
        (false, Some(e)) if e.eq_ignore_ascii_case("npy") => "png".to_string(),
        (false, e) => e.unwrap_or("png").to_string(),
    };
    if first {
        return out.to_path_buf();
    }
    let stem = out.file_stem().and_then(|s| s.to_str()).unwrap_or("out");
    // A level or layer ("bloom@3") as bloom-3: no @ in a file name.
    out.with_file_name(format!("{stem}.{}.{ext}", name.replace('@', "-")))
}

/// Renders a kernel and writes its outputs, the first through `frame`
/// (`--crop`, `--zoom`); exit 1 on NaN or unwritten texels in any output.
/// `shape` describes the first output where it is a texture.
pub fn render(
    ctx: &Renderer,
    k: &Kernel,
    plan: &Plan,
    out: &Path,
    shape: Option<String>,
    frame: impl Fn(Image) -> Image,
) -> Result<i32, GoldenError> {
    let r = vista_render::run(ctx, plan)?;
    let mut code = 0;
    for (i, o) in r.outputs.iter().enumerate() {
        let is_buffer = matches!(o.value, OutputValue::Buffer { .. });
        let path = output_path(out, i == 0, &o.name, is_buffer);
        match &o.value {
            OutputValue::Texture { raw, .. } => {
                let raw_values = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
                let img = if raw_values { Image::clone(raw) } else { o.display().expect("a texture") };
                vista_image::save(&path, &if i == 0 { frame(img) } else { img })?;
            }
            OutputValue::Buffer { .. } => {
                let (descr, shape) = o.npy().expect("a buffer");
                vista_image::npy::write_npy(&path, &descr, &shape, o.buffer_body().expect("a buffer"))?;
            }
        }
        if r.outputs.len() > 1 {
            eprintln!("  output {} -> {}", o.name, path.display());
        }
    }
    // The checks check and bless make of every output (unwritten texels,
    // NaN/Inf in textures and float buffers), from the one guard.
    for problem in vista_golden::output_guards(&r.outputs) {
        eprintln!("error: kernel {}: {problem}", k.name());
        code = 1;
    }
    let passes: Vec<String> = r.pass_times.iter().map(|t| format!("{:.1}", t.as_secs_f64() * 1e3)).collect();
    let passes = match passes.len() {
        1 => String::new(),
        n => format!(" ({n} passes: {} ms)", passes.join(" + ")),
    };
    eprintln!(
        "rendered {}{}{passes} on {} in {:.1} ms -> {}",
        k.name(),
        shape.map(|s| format!(" {s}")).unwrap_or_default(),
        ctx.adapter_description(),
        r.stats.gpu_wall.as_secs_f64() * 1e3,
        out.display()
    );
    Ok(code)
}
