//! Agreement with scikit-image on committed fixtures.
//!
//! `tests/fixtures/make_ssim_fixture.py` built three reference/actual pairs
//! as 16-bit PNGs and stored scikit-image's PSNR (RGB, data_range=1) and
//! SSIM (Rec. 709 luma, gaussian_weights=True, sigma=1.5,
//! use_sample_covariance=False, data_range=1) in `skimage.json`.

use std::path::PathBuf;

use serde::Deserialize;
use vista_image::{metrics, read_png16};

const TOLERANCE: f64 = 1e-3;

#[derive(Deserialize)]
struct Fixture {
    pairs: Vec<Pair>,
}

#[derive(Deserialize)]
struct Pair {
    name: String,
    reference: String,
    actual: String,
    width: u32,
    height: u32,
    psnr: f64,
    ssim: f64,
    mse: f64,
    max_abs: f64,
}

fn fixture_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

#[test]
fn psnr_and_ssim_match_scikit_image() {
    let dir = fixture_dir();
    let json = std::fs::read_to_string(dir.join("skimage.json")).unwrap();
    let fixture: Fixture = serde_json::from_str(&json).unwrap();
    assert_eq!(fixture.pairs.len(), 3);
    for p in &fixture.pairs {
        let reference = read_png16(&dir.join(&p.reference)).unwrap();
        let actual = read_png16(&dir.join(&p.actual)).unwrap();
        assert_eq!(reference.dimensions(), (p.width, p.height), "{}", p.name);
        let m = metrics::compare(&reference, &actual).unwrap();
        println!(
            "{}: psnr {:.9} vs {:.9} (d {:.2e}), ssim {:.9} vs {:.9} (d {:.2e})",
            p.name,
            m.psnr,
            p.psnr,
            (m.psnr - p.psnr).abs(),
            m.ssim,
            p.ssim,
            (m.ssim - p.ssim).abs()
        );
        assert!((m.psnr - p.psnr).abs() < TOLERANCE, "{}: psnr {} vs {}", p.name, m.psnr, p.psnr);
        assert!((m.ssim - p.ssim).abs() < TOLERANCE, "{}: ssim {} vs {}", p.name, m.ssim, p.ssim);
        assert!((m.mse - p.mse).abs() < 1e-9, "{}: mse {} vs {}", p.name, m.mse, p.mse);
        assert!((m.max_abs - p.max_abs).abs() < 1e-6, "{}: max_abs", p.name);
        // The pairs are far from identical, so a broken metric cannot pass by accident.
        assert!(m.ssim < 0.99 && m.psnr < 40.0, "{}", p.name);
    }
}
