//! cloudmap on the GPU: against its f64 CPU reference (every channel within
//! 1e-4) and its invariants (cover = 1 is exactly clear, d never increases
//! with cover, frames 1/64 apart within the derived bound).

mod common;

use vista_kernels::ParamSet;
use vista_kernels::cloudmap::{CloudmapKernel, frame_change_bound};

fn params(preset: &str, set: &[(&str, &str)]) -> ParamSet {
    common::params(&CloudmapKernel, Some(preset), set)
}

fn gpu_matches_f64_reference_on_every_preset(ctx: &vista_render::Renderer) {
    let (w, h) = (128, 96);
    let mut settings: Vec<(String, ParamSet)> =
        CloudmapKernel.presets().iter().map(|p| (p.name.to_string(), params(&p.name, &[]))).collect();
    settings.push((
        "seed 9, sharpness 0.9, time 7.3".into(),
        params("default", &[("seed", "9"), ("sharpness", "0.9"), ("time", "7.3")]),
    ));
    for (name, p) in settings {
        let gpu = vista_render::render(ctx, &CloudmapKernel, &p, w, h).unwrap().raw;
        let cpu = CloudmapKernel.reference(&p, w, h);
        let err = vista_image::metrics::max_abs(&gpu, &cpu);
        eprintln!("cloudmap {name}: max |gpu - cpu| over RGBA = {err:.2e}");
        assert!(err <= 1e-4, "cloudmap {name}: max abs {err} > 1e-4");
    }
}

fn gpu_invariants_cover_and_frames(ctx: &vista_render::Renderer) {
    let render =
        |set: &[(&str, &str)]| vista_render::render(ctx, &CloudmapKernel, &params("default", set), 64, 64).unwrap().raw;
    for basis in ["value", "perlin"] {
        let clear = render(&[("basis", basis), ("cover", "1")]);
        assert!(clear.data.iter().all(|p| p[..3] == [0.0; 3]), "{basis}: cover 1 is not exactly clear");
    }
    let covers = ["0", "0.25", "0.5", "0.75", "1"];
    let imgs: Vec<_> = covers.iter().map(|c| render(&[("cover", c)])).collect();
    for (a, b) in imgs.iter().zip(&imgs[1..]) {
        assert!(a.data.iter().zip(&b.data).all(|(x, y)| y[0] <= x[0]), "d rose when cover grew");
    }
    assert!(imgs[0].data.iter().all(|p| (0.0..1.0).contains(&p[0])));
    let bound = frame_change_bound(0.96, 1.0 / 64.0);
    for frame in [0, 17, 40] {
        let t = |k: i32| format!("{}", k as f64 / 64.0);
        let d = vista_image::metrics::max_abs(&render(&[("time", &t(frame))]), &render(&[("time", &t(frame + 1))]));
        assert!(d <= bound, "frame {frame}: change {d} > bound {bound}");
        assert!(d > 0.0, "frame {frame}: time does not animate");
    }
}

fn main() {
    common::gpu_tests![gpu_matches_f64_reference_on_every_preset, gpu_invariants_cover_and_frames,];
}
