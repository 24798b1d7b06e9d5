//! `curve.svg` / `curve.png`: PSNR against the swept value with GPU time on
//! a second axis, or a PSNR heat map for two-parameter sweeps.
//!
//! Text needs a TrueType font; plotters' `ab_glyph` backend is pure Rust, so
//! the font file is looked up at run time (`VISTA_FONT`, then common system
//! paths) instead of linking fontconfig/freetype.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::Sweep;

/// Why the plots could not be drawn or written: no usable font, a drawing
/// or encoding failure, or a failed write.
#[derive(Debug)]
pub struct PlotError(pub String);

impl std::fmt::Display for PlotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

fn err(e: impl std::fmt::Debug) -> PlotError {
    PlotError(format!("drawing failed: {e:?}"))
}

const FONT_PATHS: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// The font file plots use: the configured one (`VISTA_FONT`, read at the
/// edge), else the first common system path that exists.
pub fn find_font(configured: Option<&Path>) -> Option<PathBuf> {
    if let Some(p) = configured {
        return Some(p.to_path_buf());
    }
    FONT_PATHS.iter().map(PathBuf::from).find(|p| p.is_file())
}

/// Registers the font as "sans-serif" once per process.
fn ensure_font(configured: Option<&Path>) -> Result<(), PlotError> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        let path = find_font(configured).ok_or_else(|| {
            "no TrueType font found for plot text; install one (`apt-get install fonts-dejavu-core`, \
             which ci/curves.sh does) or set VISTA_FONT=/path/to/font.ttf"
                .to_string()
        })?;
        let bytes = std::fs::read(&path).map_err(|e| format!("cannot read font {}: {e}", path.display()))?;
        // plotters keeps fonts for the whole process and wants 'static
        // bytes: a static holds them (read once, as DONE runs once).
        static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
        let bytes: &'static [u8] = BYTES.get_or_init(|| bytes);
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
            .map_err(|_| format!("{} is not a usable TrueType font (VISTA_FONT)", path.display()))
    })
    .clone()
    .map_err(PlotError)
}

const SIZE: (u32, u32) = (900, 560);
/// Plotted stand-in for +inf PSNR (bit-identical to the reference).
const PSNR_CAP: f64 = 120.0;

fn psnr_of(p: &crate::Point) -> f64 {
    p.metrics.psnr.min(PSNR_CAP)
}

/// Draws both files and writes each atomically. Returns their paths.
pub fn write_plots(sweep: &Sweep, dir: &Path, font: Option<&Path>) -> Result<Vec<PathBuf>, PlotError> {
    ensure_font(font)?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw(sweep, &root)?;
        root.present().map_err(err)?;
    }
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        draw(sweep, &root)?;
        root.present().map_err(err)?;
    }
    let mut png = Vec::new();
    {
        use image::ImageEncoder;
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(&rgb, SIZE.0, SIZE.1, image::ExtendedColorType::Rgb8)
            .map_err(|e| PlotError(format!("PNG encoding failed: {e}")))?;
    }
    let (svg_path, png_path) = (dir.join("curve.svg"), dir.join("curve.png"));
    vista_image::atomic_write(&svg_path, svg.as_bytes()).map_err(|e| PlotError(e.to_string()))?;
    vista_image::atomic_write(&png_path, &png).map_err(|e| PlotError(e.to_string()))?;
    Ok(vec![svg_path, png_path])
}

fn draw<DB: DrawingBackend>(sweep: &Sweep, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    if sweep.spec.y.is_some() { heat_map(sweep, root) } else { curve(sweep, root) }
}

fn title(sweep: &Sweep) -> String {
    let s = &sweep.spec;
    let what = match &s.y {
        Some(y) => format!("{} x {}", s.x.name, y.name),
        None => s.x.name.clone(),
    };
    format!("{} {}x{}: PSNR vs {what}", s.kernel.name(), s.width, s.height)
}

/// Numeric x positions; log2 when all values are positive and span >= 8x.
fn x_positions(sweep: &Sweep) -> (Vec<f64>, bool) {
    let xs: Vec<f64> = sweep.points.iter().map(|p| p.x.parse::<f64>().unwrap_or(f64::NAN)).collect();
    let (lo, hi) = xs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let log = lo > 0.0 && hi / lo >= 8.0;
    (if log { xs.iter().map(|v| v.log2()).collect() } else { xs }, log)
}

fn padded(lo: f64, hi: f64) -> std::ops::Range<f64> {
    let pad = ((hi - lo) * 0.05).max(1e-3);
    (lo - pad)..(hi + pad)
}

fn curve<DB: DrawingBackend>(sweep: &Sweep, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
    let (xs, log) = x_positions(sweep);
    let psnr: Vec<f64> = sweep.points.iter().map(psnr_of).collect();
    let ms: Vec<f64> = sweep.points.iter().map(|p| p.gpu_ms).collect();
    let target = sweep.spec.target_psnr;
    let x_range =
        padded(xs.iter().cloned().fold(f64::INFINITY, f64::min), xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max));
    let y_lo = psnr.iter().cloned().fold(target, f64::min).min(target) - 3.0;
    let y_hi = psnr.iter().cloned().fold(target, f64::max) + 3.0;
    let t_hi = ms.iter().cloned().fold(0.0, f64::max) * 1.1 + 1e-3;

    let mut chart = ChartBuilder::on(root)
        .caption(title(sweep), ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(56)
        .right_y_label_area_size(64)
        .build_cartesian_2d(x_range.clone(), y_lo.max(0.0)..y_hi)
        .map_err(err)?
        .set_secondary_coord(x_range.clone(), 0.0..t_hi);
    let fmt_x = move |v: &f64| {
        if log {
            // Label powers of two only; in-between ticks stay as grid lines.
            if (v - v.round()).abs() > 1e-6 {
                return String::new();
            }
            return format!("{}", 2f64.powf(v.round()));
        }
        if (v - v.round()).abs() < 1e-6 { format!("{}", v.round()) } else { format!("{v:.3}") }
    };
    chart
        .configure_mesh()
        .x_desc(format!("{}{}", sweep.spec.x.name, if log { " (log scale)" } else { "" }))
        .y_desc("PSNR vs reference (dB)")
        .x_label_formatter(&fmt_x)
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    chart.configure_secondary_axes().y_desc("GPU time (ms)").label_style(("sans-serif", 14)).draw().map_err(err)?;

    let blue = RGBColor(31, 119, 180);
    let orange = RGBColor(230, 120, 20);
    chart
        .draw_series(LineSeries::new(
            vec![(x_range.start, target), (x_range.end, target)],
            BLACK.mix(0.45).stroke_width(1),
        ))
        .map_err(err)?
        .label(format!("target {target:.0} dB"))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.45)));
    let pts: Vec<(f64, f64)> = xs.iter().cloned().zip(psnr.iter().cloned()).collect();
    chart
        .draw_series(LineSeries::new(pts.clone(), blue.stroke_width(2)))
        .map_err(err)?
        .label("PSNR (left)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
    chart.draw_series(pts.iter().map(|&c| Circle::new(c, 4, blue.filled()))).map_err(err)?;
    let tpts: Vec<(f64, f64)> = xs.iter().cloned().zip(ms.iter().cloned()).collect();
    chart
        .draw_secondary_series(LineSeries::new(tpts.clone(), orange.stroke_width(2)))
        .map_err(err)?
        .label("GPU time (right)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], orange.stroke_width(2)));
    chart.draw_secondary_series(tpts.iter().map(|&c| TriangleMarker::new(c, 5, orange.filled()))).map_err(err)?;
    if let Some(best) = sweep.cheapest() {
        let i = sweep.points.iter().position(|p| std::ptr::eq(p, best)).unwrap_or(0);
        chart
            .draw_series(std::iter::once(Circle::new((xs[i], psnr[i]), 9, BLACK.stroke_width(2))))
            .map_err(err)?
            .label(format!("cheapest >= target: {}", best.x))
            .legend(|(x, y)| Circle::new((x + 10, y), 5, BLACK.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    Ok(())
}

fn fmt_ms(ms: f64) -> String {
    if ms < 10.0 { format!("{ms:.1}") } else { format!("{ms:.0}") }
}

/// Five-stop dark-blue -> yellow ramp (perceptually ordered, viridis-like).
fn ramp(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 5] = [(68, 1, 84), (59, 82, 139), (33, 145, 140), (94, 201, 98), (253, 231, 37)];
    let t = t.clamp(0.0, 1.0) * 4.0;
    let i = (t.floor() as usize).min(3);
    let f = t - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let l = |x: u8, y: u8| (x as f64 + (y as f64 - x as f64) * f).round() as u8;
    RGBColor(l(a.0, b.0), l(a.1, b.1), l(a.2, b.2))
}

fn heat_map<DB: DrawingBackend>(sweep: &Sweep, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
    let s = &sweep.spec;
    let y_axis = s.y.as_ref().expect("heat map needs --param2");
    let (nx, ny) = (s.x.values.len() as i32, y_axis.values.len() as i32);
    let psnr: Vec<f64> = sweep.points.iter().map(psnr_of).collect();
    let lo = psnr.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = psnr.iter().cloned().fold(f64::NEG_INFINITY, f64::max).max(lo + 1e-6);
    let best = sweep.cheapest().map(|b| (b.x.clone(), b.y.clone()));

    let mut chart = ChartBuilder::on(root)
        .caption(
            format!("{} (cells: PSNR dB / GPU ms; bold: >= {:.0} dB)", title(sweep), s.target_psnr),
            ("sans-serif", 18),
        )
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(64)
        // `a..b` segmented has b - a + 1 segments: 0..n-1 gives exactly n cells.
        .build_cartesian_2d((0..nx - 1).into_segmented(), (0..ny - 1).into_segmented())
        .map_err(err)?;
    let xs = s.x.values.clone();
    let ys = y_axis.values.clone();
    let label = |vals: &Vec<String>, v: &SegmentValue<i32>| match v {
        SegmentValue::CenterOf(i) => vals.get(*i as usize).cloned().unwrap_or_default(),
        _ => String::new(),
    };
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(&s.x.name)
        .y_desc(&y_axis.name)
        .x_labels(nx as usize)
        .y_labels(ny as usize)
        .x_label_formatter(&|v| label(&xs, v))
        .y_label_formatter(&|v| label(&ys, v))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for (k, p) in sweep.points.iter().enumerate() {
        let (i, j) = (k as i32 % nx, k as i32 / nx);
        let t = (psnr[k] - lo) / (hi - lo);
        let fill = ramp(t);
        let cell = [
            (SegmentValue::Exact(i), SegmentValue::Exact(j)),
            (SegmentValue::Exact(i + 1), SegmentValue::Exact(j + 1)),
        ];
        chart.draw_series(std::iter::once(Rectangle::new(cell.clone(), fill.filled()))).map_err(err)?;
        let reached = p.metrics.psnr >= s.target_psnr;
        let is_best = best.as_ref().is_some_and(|(bx, by)| *bx == p.x && *by == p.y);
        if is_best {
            chart.draw_series(std::iter::once(Rectangle::new(cell, RED.stroke_width(4)))).map_err(err)?;
        }
        let text_color = if t > 0.6 { BLACK } else { WHITE };
        let style = TextStyle::from(("sans-serif", if reached { 15 } else { 13 }).into_font().style(if reached {
            FontStyle::Bold
        } else {
            FontStyle::Normal
        }))
        .color(&text_color)
        .pos(Pos::new(HPos::Center, VPos::Center));
        let psnr_text = if p.metrics.psnr.is_infinite() { "inf".to_string() } else { format!("{:.1}", p.metrics.psnr) };
        chart
            .draw_series(std::iter::once(Text::new(
                format!("{psnr_text} / {}", fmt_ms(p.gpu_ms)),
                (SegmentValue::CenterOf(i), SegmentValue::CenterOf(j)),
                style,
            )))
            .map_err(err)?;
    }
    Ok(())
}
