//! cloudmap's invariants on the f64 CPU reference: d in [0, 1); cover = 1
//! gives exactly 0; d never increases when cover grows; consecutive frames
//! (time, time + 1/64) differ by at most the derived bound, which is not
//! vacuous (the measured change reaches a sizeable part of it).

use vista_kernels::ParamSet;
use vista_kernels::cloudmap::{CloudmapKernel, density, frame_change_bound};

fn params(set: &[(&str, &str)]) -> ParamSet {
    let o: Vec<(String, String)> = set.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    CloudmapKernel.resolve(None, &o).unwrap()
}

#[test]
fn density_is_in_unit_interval_and_zero_at_full_cover() {
    for basis in ["value", "perlin"] {
        for s in ["0.9", "0.96", "0.999"] {
            let img = CloudmapKernel.reference(&params(&[("basis", basis), ("sharpness", s)]), 64, 64);
            assert!(img.data.iter().all(|p| (0.0..1.0).contains(&p[0])), "{basis} s={s}");
            assert!(img.data.iter().any(|p| p[0] > 0.01), "{basis} s={s}: no cloud at all");
            let clear =
                CloudmapKernel.reference(&params(&[("basis", basis), ("sharpness", s), ("cover", "1")]), 64, 64);
            assert!(clear.data.iter().all(|p| p[0] == 0.0 && p[1] == 0.0 && p[2] == 0.0), "{basis}: cover 1 not clear");
        }
    }
    assert_eq!(density(0.3, 0.5, 0.96), 0.0);
    assert!((density(0.6, 0.5, 0.96) - (1.0 - 0.96f64.powf(25.5))).abs() < 1e-15);
}

#[test]
fn density_never_increases_with_cover() {
    let covers = ["0", "0.2", "0.4", "0.5", "0.6", "0.8", "1"];
    let imgs: Vec<_> = covers.iter().map(|c| CloudmapKernel.reference(&params(&[("cover", c)]), 48, 48)).collect();
    for (a, b) in imgs.iter().zip(&imgs[1..]) {
        assert!(a.data.iter().zip(&b.data).all(|(x, y)| y[0] <= x[0]), "d rose when cover grew");
    }
}

#[test]
fn consecutive_frames_change_by_at_most_the_derived_bound() {
    for s in [0.9, 0.96, 0.999] {
        let bound = frame_change_bound(s, 1.0 / 64.0);
        let mut worst = 0.0f64;
        for frame in 0..16 {
            let t = |k: i32| format!("{}", k as f64 / 64.0);
            let a = CloudmapKernel.reference(&params(&[("sharpness", &s.to_string()), ("time", &t(frame))]), 48, 48);
            let b =
                CloudmapKernel.reference(&params(&[("sharpness", &s.to_string()), ("time", &t(frame + 1))]), 48, 48);
            worst = worst.max(vista_image::metrics::max_abs(&a, &b));
        }
        eprintln!("sharpness {s}: worst frame-to-frame change {worst:.4}, bound {bound:.4}");
        assert!(worst <= bound, "s={s}: {worst} > bound {bound}");
        assert!(worst > 0.1 * bound, "s={s}: the bound {bound} is vacuous against {worst}");
    }
}
