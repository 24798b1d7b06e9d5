//! Diff heat maps for reports.

use crate::Image;

/// Colour for pixels whose difference is NaN/Inf or that `actual` lacks; the
/// colormap never produces pure green, so these stand out.
const INVALID: [f32; 4] = [0.0, 1.0, 0.0, 1.0];

/// Smallest default scale, so differences of one 8-bit step or less are
/// still visible instead of being stretched from noise.
const MIN_SCALE: f32 = 1.0 / 255.0;

/// Colormap stops: black → blue → magenta → yellow → white (monotonic in
/// brightness). The report's viewer draws its heat maps and legend with the
/// same stops.
pub const STOPS: [[f32; 3]; 5] = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]];

/// Visualises where and how much `actual` differs from `reference`.
///
/// Each pixel's error is the max absolute RGB difference; it is divided by
/// `scale` (the difference that maps to white), clamped to `[0, 1]` and
/// mapped through the colormap above. The default scale (also used when
/// `scale` is not a positive finite number) is the largest finite difference
/// in the image, but at least 1/255. Pixels with a non-finite difference are
/// pure green. The output has the reference's size; if `actual` is smaller,
/// the pixels it lacks are green too. Alpha is always 1.
pub fn diff_heatmap(reference: &Image, actual: &Image, scale: Option<f32>) -> Image {
    let diffs = pixel_diffs(reference, actual);
    let scale = match scale {
        Some(s) if s.is_finite() && s > 0.0 => s,
        _ => default_scale(&diffs),
    };
    paint(reference, &diffs, |d| d / scale)
}

/// Colours each difference at `position(d)` on the colormap; invalid pixels green.
fn paint(reference: &Image, diffs: &[Option<f32>], position: impl Fn(f32) -> f32) -> Image {
    let data = diffs.iter().map(|d| d.map_or(INVALID, |d| colormap(position(d)))).collect();
    Image { width: reference.width, height: reference.height, data }
}

/// The difference that maps to black on the log scale: half a 16-bit step,
/// so one step (1/65535) is already visible.
pub const LOG_FLOOR: f32 = 0.5 / 65535.0;

/// Position of a difference on the fixed log scale shared by every case:
/// 0 for no difference, then log10(d / LOG_FLOOR) / log10(1 / LOG_FLOOR),
/// so one 16-bit step is 0.06, 1/255 is 0.53 and 1 is 1.
pub fn log_position(d: f32) -> f32 {
    if d <= 0.0 { 0.0 } else { ((d / LOG_FLOOR).log10() / (1.0 / LOG_FLOOR).log10()).clamp(0.0, 1.0) }
}

/// [`diff_heatmap`] on the fixed log scale of [`log_position`]: the same
/// colour means the same difference in every case of a report.
pub fn diff_heatmap_log(reference: &Image, actual: &Image) -> Image {
    paint(reference, &pixel_diffs(reference, actual), log_position)
}

/// One row of [`diff_heatmap_log`] of two images of one size, appended to
/// `out`: the report paints its heat maps a row at a time, as it writes
/// them.
pub fn diff_heatmap_log_row(reference: &[[f32; 4]], actual: &[[f32; 4]], out: &mut Vec<[f32; 4]>) {
    out.extend(
        reference.iter().zip(actual).map(|(&r, &a)| max_rgb_diff(r, a).map_or(INVALID, |d| colormap(log_position(d)))),
    );
}

/// Per reference pixel: `Some(max RGB |diff|)`, or `None` when non-finite or
/// outside `actual`.
fn pixel_diffs(reference: &Image, actual: &Image) -> Vec<Option<f32>> {
    let mut out = Vec::with_capacity(reference.data.len());
    for y in 0..reference.height {
        for x in 0..reference.width {
            let inside = x < actual.width && y < actual.height;
            out.push(inside.then(|| max_rgb_diff(reference.get(x, y), actual.get(x, y))).flatten());
        }
    }
    out
}

fn max_rgb_diff(a: [f32; 4], b: [f32; 4]) -> Option<f32> {
    let mut m = 0.0f32;
    for c in 0..3 {
        if a[c].to_bits() == b[c].to_bits() {
            continue;
        }
        let d = (a[c] - b[c]).abs();
        if !d.is_finite() {
            return None;
        }
        m = m.max(d);
    }
    Some(m)
}

fn default_scale(diffs: &[Option<f32>]) -> f32 {
    diffs.iter().flatten().fold(MIN_SCALE, |m, &d| m.max(d))
}

/// Piecewise-linear interpolation between [`STOPS`] for `t` in `[0, 1]`.
fn colormap(t: f32) -> [f32; 4] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let segments = (STOPS.len() - 1) as f32;
    let pos = t * segments;
    let i = (pos.floor() as usize).min(STOPS.len() - 2);
    let f = pos - i as f32;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let lerp = |c: usize| a[c] + (b[c] - a[c]) * f;
    [lerp(0), lerp(1), lerp(2), 1.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colormap_endpoints_and_stops() {
        assert_eq!(colormap(0.0), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(colormap(0.25), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(colormap(0.5), [1.0, 0.0, 1.0, 1.0]);
        assert_eq!(colormap(0.75), [1.0, 1.0, 0.0, 1.0]);
        assert_eq!(colormap(1.0), [1.0, 1.0, 1.0, 1.0]);
        assert_eq!(colormap(7.0), [1.0, 1.0, 1.0, 1.0]);
    }

    #[test]
    fn log_scale_positions() {
        assert_eq!(log_position(0.0), 0.0);
        assert!((log_position(1.0 / 65535.0) - 0.0588).abs() < 1e-3, "{}", log_position(1.0 / 65535.0));
        assert!((log_position(1.0 / 255.0) - 0.5298).abs() < 1e-3, "{}", log_position(1.0 / 255.0));
        assert_eq!(log_position(1.0), 1.0);
        let a = Image::from_fn(2, 1, |_, _| [0.5, 0.5, 0.5, 1.0]);
        let b = Image::from_fn(2, 1, |x, _| [0.5 + x as f32 / 255.0, 0.5, 0.5, 1.0]);
        let h = diff_heatmap_log(&a, &b);
        assert_eq!(h.get(0, 0), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(h.get(1, 0), colormap(log_position(1.0 / 255.0)));
    }

    #[test]
    fn a_heat_map_row_is_that_row_of_the_whole_map() {
        let a = Image::from_fn(7, 3, |x, y| [x as f32 / 7.0, y as f32 / 3.0, 0.5, 1.0]);
        let mut b = Image::from_fn(7, 3, |x, y| [x as f32 / 7.0 + (x * y) as f32 * 1e-3, y as f32 / 3.0, 0.5, 1.0]);
        b.set(2, 1, [f32::NAN, 0.0, 0.0, 1.0]);
        let whole = diff_heatmap_log(&a, &b);
        for y in 0..3usize {
            let mut row = Vec::new();
            diff_heatmap_log_row(&a.data[y * 7..][..7], &b.data[y * 7..][..7], &mut row);
            assert_eq!(row, whole.data[y * 7..][..7], "row {y}");
        }
        let mut row = Vec::new();
        diff_heatmap_log_row(&a.data[7..14], &b.data[7..14], &mut row);
        assert_eq!(row[2], INVALID, "a NaN difference is green");
    }

    #[test]
    fn colormap_never_pure_green() {
        for i in 0..=1000 {
            let c = colormap(i as f32 / 1000.0);
            assert!(!(c[0] == 0.0 && c[1] > 0.0 && c[2] == 0.0), "{c:?}");
        }
    }
}
