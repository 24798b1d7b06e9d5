//! `vista init [DIR]`: a minimal project (vista.toml, one kernel manifest,
//! its WGSL and one case) that `vista bless` and `vista check` pass right
//! away. Never overwrites: an existing file is refused by name.

use std::path::{Path, PathBuf};

use vista_golden::GoldenError;

const VISTA_TOML: &str = "\
# A vista project: kernels/ (manifests), shaders/ (WGSL) and golden/ (cases
# and goldens) live beside this file. It may stay empty.
";

const MANIFEST: &str = r#"summary = "concentric rings: v = 0.5 + 0.5 cos(2 pi frequency r + phase), colour = v * tint"

[[param]]
name = "frequency"
type = "f32"
range = [1, 64]
default = 8.0
doc = "rings per unit of distance from the centre"

[[param]]
name = "phase"
type = "f32"
range = [0, 6.2832]
default = 0.0
doc = "phase of the cosine, radians"

[[param]]
name = "tint"
type = "vec3"
range = [0, 1]
default = [0.9, 0.6, 0.2]
doc = "colour of the bright rings"

[preset.dense]
frequency = 24.0
doc = "three times as many rings"
"#;

const SHADER: &str = r#"// Concentric rings around the image centre. Written as any compute kernel
// is: vista reads the entry point, workgroup size and bindings from it, and
// packs the uniform by field name from the manifest's params.
struct Params {
    width: u32,
    height: u32,
    frequency: f32,
    phase: f32,
    tint: vec3<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

const TAU: f32 = 6.28318531;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2(f32(params.width), f32(params.height));
    let p = ((vec2<f32>(id.xy) + 0.5) - 0.5 * size) / min(size.x, size.y);
    let v = 0.5 + 0.5 * cos(TAU * params.frequency * length(p) + params.phase);
    textureStore(output, id.xy, vec4(v * params.tint, 1.0));
}
"#;

const CASES: &str = r#"# Each case renders a kernel with a preset and overrides at a size, and
# compares it with golden/<kernel>/<id>.png (written by `vista bless`).
[[case]]
id = "rings-default"
kernel = "rings"
size = "64x64"
doc = "the defaults"

[[case]]
id = "rings-dense"
kernel = "rings"
preset = "dense"
set = { tint = [0.3, 0.7, 1.0] }
size = "64x64"
"#;

/// The files `init` writes, relative to the project directory.
pub const FILES: &[(&str, &str)] = &[
    ("vista.toml", VISTA_TOML),
    ("kernels/rings.toml", MANIFEST),
    ("shaders/rings.wgsl", SHADER),
    ("golden/cases.toml", CASES),
];

/// `vista init DIR`: [`init`], each file written named, then the next step.
pub fn run(dir: &Path) -> std::process::ExitCode {
    match init(dir) {
        Ok(written) => {
            for p in &written {
                println!("wrote {}", p.display());
            }
            println!(
                "next: cd {} && vista bless && vista check   (then edit kernels/rings.toml and \
                 shaders/rings.wgsl, or add your own kernel beside them)",
                dir.display()
            );
            std::process::ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// Writes the project into `dir` (created if missing); refuses, before
/// writing anything, if any of its files exists.
pub fn init(dir: &Path) -> Result<Vec<PathBuf>, GoldenError> {
    if let Some((rel, _)) = FILES.iter().find(|(rel, _)| dir.join(rel).exists()) {
        return Err(GoldenError::BadInput(format!(
            "{} exists; vista init never overwrites: pick an empty directory (vista init DIR)",
            dir.join(rel).display()
        )));
    }
    let mut written = Vec::new();
    for (rel, text) in FILES {
        let path = dir.join(rel);
        let parent = path.parent().expect("a file under the project");
        std::fs::create_dir_all(parent)
            .map_err(|e| GoldenError::Io { path: parent.display().to_string(), message: e.to_string() })?;
        vista_image::atomic_write(&path, text.as_bytes())?;
        written.push(path);
    }
    Ok(written)
}
