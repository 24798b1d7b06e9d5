//! One case through the pipeline: render it (`vista-render`), read its
//! golden, judge it (`check::judge`, pure), and write its report images
//! (`report`). The only module that calls all three, so neither the
//! verdict nor the report imports the other's work.

use std::path::PathBuf;

use vista_image::Image;
use vista_render::{Renderer, quantize16, render};

use crate::Case;
use crate::check::{GoldenRead, Observed, Outcome, RunInfo, Verdict, judge};
use crate::store::{Manifest, Store, params_hash};

/// Options for checking.
#[derive(Debug, Clone)]
pub struct CheckOptions {
    /// Where expected/actual/diff images go (`target/vista-report`).
    pub report_dir: PathBuf,
    /// Render twice in this process and require bit-identical output.
    pub twice: bool,
}

/// Renders `case`, judges it against its golden and manifest entry, writes
/// its report images, and returns the outcome (errors become `Verdict::Error`).
pub fn check_case(ctx: &Renderer, store: &Store, manifest: &Manifest, case: &Case, opts: &CheckOptions) -> Outcome {
    let shader = case.kernel.shader();
    let run = RunInfo {
        backend: ctx.backend().to_string(),
        adapter: ctx.adapter_description(),
        params_hash: params_hash(case),
        shader_hash: ctx.shader_hash(shader).unwrap_or_else(|e| format!("unavailable: {e}")),
    };
    let entry = manifest.case.get(&case.id);
    let rendered = render(ctx, case.kernel, &case.params, case.width, case.height).map_err(|e| e.to_string());
    let r = match rendered {
        Ok(r) => r,
        Err(e) => return judge(case, entry, run, Err(e)),
    };
    let actual = quantize16(r.display());
    let gathered = (|| -> Result<_, String> {
        let repeat_identical = match opts.twice {
            true => Some(
                render(ctx, case.kernel, &case.params, case.width, case.height)
                    .map_err(|e| e.to_string())?
                    .raw
                    .bit_identical(&r.raw),
            ),
            false => None,
        };
        let files = ctx.shader_file_hashes(shader).map_err(|e| e.to_string())?;
        let path = store.golden_path(case);
        let golden = match path.exists() {
            false => None,
            // Read once: hashed against the manifest, then decoded.
            true => {
                let bytes = std::fs::read(&path)
                    .map_err(|source| vista_image::ImageError::Io { path: path.clone(), source }.to_string())?;
                let hash = crate::short_hash_bytes(&bytes);
                Some((hash, vista_image::decode_png16(&path, &bytes).map_err(|e| e.to_string())))
            }
        };
        Ok((repeat_identical, files, path, golden))
    })();
    let mut out = match &gathered {
        Err(e) => judge(case, entry, run, Err(e.clone())),
        Ok((repeat_identical, files, path, golden)) => {
            let golden_read = match golden {
                None => GoldenRead::Missing { path },
                Some((hash, image)) => {
                    GoldenRead::Present { path, hash, image: image.as_ref().map_err(|e| e.as_str()) }
                }
            };
            let observed = Observed {
                raw: &r.raw,
                actual: &actual,
                repeat_identical: *repeat_identical,
                shader_files: files,
                golden: golden_read,
            };
            judge(case, entry, run, Ok(observed))
        }
    };
    out.gpu_ms = r.stats.gpu_wall.as_secs_f64() * 1e3;
    let expected: Option<&Image> = match &gathered {
        Ok((_, _, _, Some((_, Ok(image))))) => Some(image),
        _ => None,
    };
    if let Err(e) = crate::report::write_case_files(&opts.report_dir, &mut out, &actual, expected) {
        out.verdict = Verdict::Error;
        out.problems.push(e.to_string());
    }
    out
}
