//! SSIM on single-channel f64 images, matching scikit-image's
//! `structural_similarity(gaussian_weights=True, sigma=1.5,
//! use_sample_covariance=False, data_range=1.0)`.

/// Gaussian sigma and the radius scipy derives from it (`int(3.5 * 1.5 + 0.5)`).
const SIGMA: f64 = 1.5;
const RADIUS: usize = 5;
const WIN: usize = 2 * RADIUS + 1;
/// Stabilisers for dynamic range L = 1: (0.01 L)^2 and (0.03 L)^2.
const C1: f64 = 0.01 * 0.01;
const C2: f64 = 0.03 * 0.03;

/// Local moments under the window: E[x], E[y], E[x²], E[y²], E[xy].
type Moments = [f64; 5];

/// Fills one row (its index, then the row) of a single-channel image.
pub(crate) type Rows<'a> = &'a (dyn Fn(usize, &mut [f64]) + Sync);

/// Mean SSIM of two `w x h` single-channel images given a row at a time,
/// each band making the rows it reads (whole f64 planes of a 2048 x 2048
/// image pair were 64 MiB).
///
/// The map is averaged over pixels whose whole 11x11 window lies inside the
/// image (a 5-pixel border is cropped, exactly like scikit-image), so the
/// border mode of the filter never matters. Images narrower or shorter than
/// 11 pixels have no such pixel; they fall back to one global window with
/// uniform weights over the whole image (gathered whole). An empty image
/// scores 1.
pub(crate) fn ssim_rows(x: Rows<'_>, y: Rows<'_>, w: usize, h: usize) -> f64 {
    if w >= WIN && h >= WIN {
        return windowed_ssim(x, y, w, h, crate::threads_for(w * h));
    }
    let whole = |rows: Rows<'_>| {
        let mut plane = vec![0.0; w * h];
        for (r, row) in plane.chunks_exact_mut(w.max(1)).enumerate() {
            rows(r, row);
        }
        plane
    };
    global_ssim(&whole(x), &whole(y))
}

/// Normalised 11-tap Gaussian, as `scipy.ndimage.gaussian_filter` builds it.
fn gaussian_kernel() -> [f64; WIN] {
    let mut k = [0.0; WIN];
    for (i, v) in k.iter_mut().enumerate() {
        let d = i as f64 - RADIUS as f64;
        *v = (-0.5 * d * d / (SIGMA * SIGMA)).exp();
    }
    let sum: f64 = k.iter().sum();
    k.map(|v| v / sum)
}

/// Output rows of the SSIM map per band: the map is made band by band, so
/// its memory is a few rows of the image, not five filtered planes of it
/// (at 2048 x 2048 those were 170 MB).
const BAND: usize = 64;

fn windowed_ssim(x: Rows<'_>, y: Rows<'_>, w: usize, h: usize, threads: usize) -> f64 {
    let k = gaussian_kernel();
    let oh = h - 2 * RADIUS;
    let bands: Vec<(usize, usize)> = (0..oh).step_by(BAND).map(|r0| (r0, (r0 + BAND).min(oh))).collect();
    let band = |&(r0, r1): &(usize, usize)| band_values(x, y, w, &k, r0, r1);
    // Summed in row-major order whatever the threads, as one running sum.
    let mut total = 0.0;
    let threads = threads.min(bands.len()).max(1);
    crate::threads::in_groups(&bands, threads, band, |values| {
        for v in values {
            total += v;
        }
    });
    total / (oh * (w - 2 * RADIUS)) as f64
}

/// The SSIM map's values on output rows `r0..r1` (row-major): the separable
/// Gaussian of the five moment planes over input rows `r0..r1 + 10`, each
/// pass adding its taps in the same order as a whole-image filter would, so
/// every value is bit for bit the whole image's.
fn band_values(x: Rows<'_>, y: Rows<'_>, w: usize, k: &[f64; WIN], r0: usize, r1: usize) -> Vec<f64> {
    let ow = w - 2 * RADIUS;
    let rows_in = r1 - r0 + 2 * RADIUS;
    // Horizontal pass: the five planes' rows, filtered where the window fits.
    let mut across = vec![vec![0.0; rows_in * ow]; 5];
    let mut products = [vec![0.0; w], vec![0.0; w], vec![0.0; w]];
    let (mut rx, mut ry) = (vec![0.0; w], vec![0.0; w]);
    for j in 0..rows_in {
        x(r0 + j, &mut rx);
        y(r0 + j, &mut ry);
        let (rx, ry) = (&rx[..], &ry[..]);
        for i in 0..w {
            products[0][i] = rx[i] * rx[i];
            products[1][i] = ry[i] * ry[i];
            products[2][i] = rx[i] * ry[i];
        }
        let planes: [&[f64]; 5] = [rx, ry, &products[0], &products[1], &products[2]];
        for (plane, dst) in planes.iter().zip(across.iter_mut()) {
            let out = &mut dst[j * ow..][..ow];
            for (t, &kt) in k.iter().enumerate() {
                for (o, &v) in out.iter_mut().zip(&plane[t..t + ow]) {
                    *o += kt * v;
                }
            }
        }
    }
    // Vertical pass, one output row at a time, and the map's values.
    let mut values = Vec::with_capacity((r1 - r0) * ow);
    let mut m = vec![vec![0.0; ow]; 5];
    for r in 0..r1 - r0 {
        for (dst, src) in m.iter_mut().zip(&across) {
            dst.fill(0.0);
            for (t, &kt) in k.iter().enumerate() {
                for (o, &v) in dst.iter_mut().zip(&src[(r + t) * ow..][..ow]) {
                    *o += kt * v;
                }
            }
        }
        values.extend((0..ow).map(|i| ssim_from_moments(&[m[0][i], m[1][i], m[2][i], m[3][i], m[4][i]])));
    }
    values
}

/// One window over the whole image with uniform weights.
fn global_ssim(x: &[f64], y: &[f64]) -> f64 {
    if x.is_empty() {
        return 1.0;
    }
    let n = x.len() as f64;
    let mut m = [0.0; 5];
    for (&a, &b) in x.iter().zip(y) {
        m[0] += a;
        m[1] += b;
        m[2] += a * a;
        m[3] += b * b;
        m[4] += a * b;
    }
    ssim_from_moments(&m.map(|v| v / n))
}

/// Wang et al. 2004 with population (biased) variances and covariance.
fn ssim_from_moments(m: &Moments) -> f64 {
    let [mx, my, mxx, myy, mxy] = *m;
    let vx = mxx - mx * mx;
    let vy = myy - my * my;
    let vxy = mxy - mx * my;
    let num = (2.0 * mx * my + C1) * (2.0 * vxy + C2);
    let den = (mx * mx + my * my + C1) * (vx + vy + C2);
    num / den
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`ssim_rows`] of two whole planes.
    fn ssim(x: &[f64], y: &[f64], w: usize, h: usize) -> f64 {
        debug_assert_eq!(x.len(), w * h);
        debug_assert_eq!(y.len(), w * h);
        ssim_on(x, y, w, h, crate::threads_for(x.len()))
    }

    /// [`ssim`] with the windowed map's bands on up to `threads` threads.
    fn ssim_on(x: &[f64], y: &[f64], w: usize, h: usize, threads: usize) -> f64 {
        let (rx, ry) = (
            |r: usize, row: &mut [f64]| row.copy_from_slice(&x[r * w..][..w]),
            |r: usize, row: &mut [f64]| row.copy_from_slice(&y[r * w..][..w]),
        );
        if w >= WIN && h >= WIN { windowed_ssim(&rx, &ry, w, h, threads) } else { global_ssim(x, y) }
    }

    /// The whole-image form the bands replaced: five filtered planes.
    fn whole_image_ssim(x: &[f64], y: &[f64], w: usize, h: usize) -> f64 {
        let k = gaussian_kernel();
        let filter = |plane: &[f64]| filter_valid(plane, w, h, &k);
        let product = |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(p, q)| p * q).collect() };
        let (mx, my) = (filter(x), filter(y));
        let (mxx, myy, mxy) = (filter(&product(x, x)), filter(&product(y, y)), filter(&product(x, y)));
        let total: f64 = (0..mx.len()).map(|i| ssim_from_moments(&[mx[i], my[i], mxx[i], myy[i], mxy[i]])).sum();
        total / mx.len() as f64
    }

    fn filter_valid(src: &[f64], w: usize, h: usize, k: &[f64; WIN]) -> Vec<f64> {
        let (ow, oh) = (w - 2 * RADIUS, h - 2 * RADIUS);
        let mut rows = vec![0.0; h * ow];
        for (row, out) in src.chunks_exact(w).zip(rows.chunks_exact_mut(ow)) {
            for (t, &kt) in k.iter().enumerate() {
                for (o, &v) in out.iter_mut().zip(&row[t..t + ow]) {
                    *o += kt * v;
                }
            }
        }
        let mut out = vec![0.0; oh * ow];
        for (r, dst) in out.chunks_exact_mut(ow).enumerate() {
            for (t, &kt) in k.iter().enumerate() {
                for (o, &v) in dst.iter_mut().zip(&rows[(r + t) * ow..(r + t + 1) * ow]) {
                    *o += kt * v;
                }
            }
        }
        out
    }

    #[test]
    fn bands_give_the_whole_image_bits_on_any_threads() {
        // Heights around the band size, so that the last band is short, full
        // or a single row.
        for (w, h) in [(37, 11), (23, 74), (41, 75), (19, 150), (64, 203)] {
            let x: Vec<f64> = (0..w * h).map(|i| ((i as f64 * 0.37).sin() * 0.5 + 0.5).powi(2)).collect();
            let y: Vec<f64> = (0..w * h).map(|i| (i as f64 * 0.11).cos() * 0.4 + 0.5).collect();
            let whole = whole_image_ssim(&x, &y, w, h);
            for threads in [1, 2, 3] {
                let banded = ssim_on(&x, &y, w, h, threads);
                assert_eq!(banded.to_bits(), whole.to_bits(), "{w}x{h}, {threads} threads: {banded} vs {whole}");
            }
        }
    }

    #[test]
    fn kernel_is_normalised_and_symmetric() {
        let k = gaussian_kernel();
        assert!((k.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        for i in 0..RADIUS {
            assert_eq!(k[i], k[WIN - 1 - i]);
        }
        // Centre tap of a sigma-1.5 Gaussian truncated at radius 5.
        assert!((k[RADIUS] - 0.266_011_724).abs() < 1e-8, "{}", k[RADIUS]);
    }

    #[test]
    fn identical_inputs_score_one() {
        let x: Vec<f64> = (0..20 * 13).map(|i| (i as f64 * 0.37).sin() * 0.5 + 0.5).collect();
        assert!((ssim(&x, &x, 20, 13) - 1.0).abs() < 1e-12);
        assert!((ssim(&x[..50], &x[..50], 10, 5) - 1.0).abs() < 1e-12);
        assert_eq!(ssim(&[], &[], 0, 0), 1.0);
    }

    #[test]
    fn global_fallback_matches_formula() {
        // x = [0, 1], y = [0, 0]: mx = 0.5, my = 0, vx = 0.25, vy = 0, vxy = 0.
        let s = ssim(&[0.0, 1.0], &[0.0, 0.0], 2, 1);
        let expected = (C1 * C2) / ((0.25 + C1) * (0.25 + C2));
        assert!((s - expected).abs() < 1e-15, "{s} vs {expected}");
    }
}
