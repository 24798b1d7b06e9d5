//! CSV, table and cheapest-point logic on hand-made sweeps (no device).

use vista_image::metrics::Metrics;
use vista_sweep::{Axis, Metric, Point, Sweep, SweepSpec};

fn point(x: &str, y: Option<&str>, psnr: f64, gpu_ms: f64, work: f64) -> Point {
    let metrics = Metrics { psnr, ssim: 0.99, max_abs: 0.01, bad_pixels: 3, nan: 0, mse: 1e-4, flip_mean: Some(0.002) };
    Point { x: x.into(), y: y.map(Into::into), metrics, gpu_ms, work, is_reference: false }
}

fn sweep(y: Option<Axis>, points: Vec<Point>) -> Sweep {
    let spec = SweepSpec {
        kernel: vista_kernels::find("clouds").unwrap().clone(),
        preset: Some("cumulus".into()),
        base: vec![],
        x: Axis { name: "steps".into(), values: vec!["16".into(), "32".into(), "64".into()] },
        y,
        reference: vec![("steps".into(), "512".into())],
        width: 8,
        height: 8,
        target_psnr: 40.0,
        runs: 1,
        metric: Metric::Display,
    };
    Sweep { spec, adapter: "test".into(), reference_ms: 1.0, reference_params: String::new(), points, crashed: vec![] }
}

#[test]
fn cheapest_is_the_least_work_point_reaching_the_target() {
    let s = sweep(
        None,
        vec![
            point("16", None, 35.0, 1.0, 16.0),
            point("32", None, 41.0, 2.0, 32.0),
            point("64", None, 50.0, 4.0, 64.0),
        ],
    );
    assert_eq!(s.cheapest().unwrap().x, "32");
    assert!(s.table().contains("cheapest reaching 40.0 dB: steps=32 (41.00 dB, 2.00 ms)"), "{}", s.table());
}

/// A swept value equal to the reference renders the reference itself (inf
/// dB); it is marked and never picked, however cheap.
#[test]
fn the_reference_itself_is_never_the_cheapest() {
    let mut same = point("2", None, f64::INFINITY, 0.5, 1.0);
    same.is_reference = true;
    let s = sweep(None, vec![point("0.5", None, 9.8, 1.0, 1.0), same.clone()]);
    assert!(s.cheapest().is_none());
    let t = s.table();
    assert!(
        t.contains("(the reference itself)") && t.contains("no swept setting except the reference itself reaches"),
        "{t}"
    );
    let s = sweep(None, vec![point("1", None, 45.0, 2.0, 4.0), same]);
    assert_eq!(s.cheapest().unwrap().x, "1");
}

/// A point whose render crashed is named under the table with its crash
/// and is never the cheapest; the CSV has the measured points only.
#[test]
fn crashed_points_are_listed_apart() {
    let mut s = sweep(None, vec![point("16", None, 45.0, 1.0, 16.0), point("64", None, 50.0, 4.0, 64.0)]);
    s.crashed.push(("steps=32".into(), "the lavapipe driver (x) crashed (signal 11, SIGSEGV) in pass 1".into()));
    let t = s.table();
    assert!(t.contains("\nCRASH steps=32: the lavapipe driver (x) crashed (signal 11, SIGSEGV) in pass 1\n"), "{t}");
    assert_eq!(s.cheapest().unwrap().x, "16");
    assert_eq!(s.csv().lines().count(), 3, "{}", s.csv());
}

#[test]
fn equal_work_falls_back_to_measured_time() {
    let s = sweep(None, vec![point("16", None, 45.0, 3.0, 10.0), point("32", None, 45.0, 2.0, 10.0)]);
    assert_eq!(s.cheapest().unwrap().x, "32");
}

#[test]
fn no_point_reaching_the_target_is_said_plainly() {
    let s = sweep(None, vec![point("16", None, 20.0, 1.0, 16.0)]);
    assert!(s.cheapest().is_none());
    assert!(s.table().contains("no swept setting reaches 40.0 dB"));
}

#[test]
fn csv_has_one_row_per_point_and_writes_inf() {
    let y = Axis { name: "light_steps".into(), values: vec!["2".into()] };
    let s = sweep(
        Some(y),
        vec![point("16", Some("2"), 30.5, 1.25, 48.0), point("512", Some("2"), f64::INFINITY, 9.0, 1536.0)],
    );
    let csv = s.csv();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "steps,light_steps,psnr,ssim,max_abs,bad_pixels,gpu_ms,work_per_pixel,flip_mean");
    assert_eq!(lines[1], "16,2,30.50,0.990000,1.000000e-2,3,1.250,48,0.002000");
    assert!(lines[2].starts_with("512,2,inf,"), "{}", lines[2]);
    assert_eq!(lines.len(), 3);
}

#[test]
fn values_lists_are_checked() {
    assert_eq!(vista_sweep::parse_values("--values", "8, 16,32").unwrap(), ["8", "16", "32"]);
    assert!(vista_sweep::parse_values("--values", "8,,16").unwrap_err().to_string().contains("empty value"));
    let many = (0..65).map(|i| i.to_string()).collect::<Vec<_>>().join(",");
    assert!(vista_sweep::parse_values("--values", &many).unwrap_err().to_string().contains("65 values"));
}

#[test]
fn metric_names_parse_and_bad_ones_are_named() {
    assert_eq!(Metric::parse("linear").unwrap(), Metric::Linear);
    assert_eq!(Metric::parse("display").unwrap(), Metric::Display);
    let e = Metric::parse("log").unwrap_err().to_string();
    assert!(e.contains("log") && e.contains("display|linear"), "{e}");
}
