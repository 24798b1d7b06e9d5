//! `vista compare`: metrics of two images, or two `.npy` arrays.

use std::path::Path;

use vista_golden::GoldenError;
use vista_image::metrics;

use crate::input::bad;
use crate::render::parse_crop;

/// Compares `a` with `b` and prints the metrics (or JSON).
pub fn compare(a: &Path, b: &Path, json: bool, hdr: bool, blur: u32, crop: Option<String>) -> Result<i32, GoldenError> {
    let npy = |p: &Path| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    if npy(a) || npy(b) {
        return compare_npy(a, b, json);
    }
    if blur > 64 {
        return Err(bad(format!("--blur {blur} is out of range; allowed: 0 to 64")));
    }
    let (mut ia, mut ib) = (vista_image::load(a)?, vista_image::load(b)?);
    if let Some(c) = crop {
        let (x, y, w, h) = parse_crop(&c, ia.width.min(ib.width), ia.height.min(ib.height))?;
        let cut = |i: &vista_image::Image| i.crop(x, y, w, h).expect("the crop was checked against both sizes");
        (ia, ib) = (cut(&ia), cut(&ib));
    }
    if blur > 0 {
        (ia, ib) = (ia.box_blur(blur), ib.box_blur(blur));
    }
    let m = if hdr { metrics::compare_hdr(&ia, &ib)? } else { metrics::compare(&ia, &ib)? };
    if json {
        // Serialised from the one metrics type, so no metric is left out.
        println!("{}", serde_json::to_string(&m).map_err(|e| bad(format!("JSON encode: {e}")))?);
    } else {
        println!("PSNR       {}", metrics::format_psnr(m.psnr));
        println!("SSIM       {:.6}", m.ssim);
        match m.flip_mean {
            Some(f) => println!("FLIP       {f:.6} (mean LDR-FLIP)"),
            None => println!("FLIP       - (not defined for --hdr)"),
        }
        println!("max abs    {:.6e}", m.max_abs);
        println!("bad pixels {} (> 1/255)", m.bad_pixels);
        println!("NaN/Inf    {}", m.nan);
    }
    Ok(0)
}

/// Refuses an output path whose directory does not exist or is not writable,
/// before any GPU work.
/// `vista compare` of two `.npy` buffers: the same dtype and shape, then
/// max-abs, max-rel, RMSE, the count that differ and the worst elements.
fn compare_npy(a: &Path, b: &Path, json: bool) -> Result<i32, GoldenError> {
    let (na, nb) = (vista_image::npy::read_npy(a)?, vista_image::npy::read_npy(b)?);
    if (na.descr.as_str(), &na.shape) != (nb.descr.as_str(), &nb.shape) {
        return Err(bad(format!(
            "{} is {} {:?} but {} is {} {:?}; compare buffers of one dtype and shape",
            a.display(),
            na.descr,
            na.shape,
            b.display(),
            nb.descr,
            nb.shape
        )));
    }
    let (va, vb) = (
        vista_image::npy::values(&na).map_err(|e| bad(format!("{}: {e}", a.display())))?,
        vista_image::npy::values(&nb).map_err(|e| bad(format!("{}: {e}", b.display())))?,
    );
    let diff: Vec<f64> = va.iter().zip(&vb).map(|(x, y)| (x - y).abs()).collect();
    let max_abs = diff.iter().copied().fold(0.0, f64::max);
    let max_rel = va.iter().zip(&diff).map(|(x, d)| d / x.abs().max(f64::MIN_POSITIVE)).fold(0.0, f64::max);
    let rmse = (diff.iter().map(|d| d * d).sum::<f64>() / diff.len().max(1) as f64).sqrt();
    let differ = va.iter().zip(&vb).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
    let mut worst: Vec<usize> = (0..diff.len()).filter(|i| diff[*i] > 0.0).collect();
    worst.sort_by(|x, y| diff[*y].total_cmp(&diff[*x]));
    worst.truncate(5);
    if json {
        let w: Vec<serde_json::Value> =
            worst.iter().map(|&i| serde_json::json!({ "index": i, "a": va[i], "b": vb[i] })).collect();
        let v = serde_json::json!({
            "values": va.len(), "differ": differ, "max_abs": max_abs, "max_rel": max_rel, "rmse": rmse, "worst": w,
        });
        println!("{v}");
    } else {
        println!("values     {} ({} {:?})", va.len(), na.descr, na.shape);
        println!("differ     {differ}");
        println!("max abs    {max_abs:.6e}");
        println!("max rel    {max_rel:.6e}");
        println!("RMSE       {rmse:.6e}");
        for &i in &worst {
            println!("  [{i}] {} vs {}", va[i], vb[i]);
        }
    }
    Ok(0)
}
