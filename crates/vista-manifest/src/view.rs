//! How a kernel's raw output is shown: HDR tone-mapped, display values as
//! they are, or normalised ([`Output`], [`DisplayMap`]).

use vista_image::Image;

/// How the raw GPU output is turned into display values for PNG goldens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// The kernel writes display values in [0, 1] directly.
    Display,
    /// The kernel writes linear radiance; display = tonemap(exposure).
    Hdr,
    /// Display = (raw - min) / (max - min) over the image's finite RGB
    /// values (`view = "normalize"`; the default for integer formats).
    Normalize,
}

/// Raw output to display values (SPEC 3) for one param set: the HDR tone
/// map with its exposure, and whether alpha is forced to 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayMap {
    pub(crate) exposure: Option<f32>,
    pub(crate) opaque: bool,
    pub(crate) normalize: bool,
    /// Channels the output's format has (1 for r32*, 2 for rg32*, else 3
    /// counted): a normalised view spans only those, a single channel shown
    /// grey.
    pub(crate) channels: u8,
}

impl DisplayMap {
    /// Display values are the raw values.
    pub fn identity() -> DisplayMap {
        DisplayMap { exposure: None, opaque: false, normalize: false, channels: 3 }
    }

    /// The display values of `raw`, or None where they are `raw` itself (a
    /// display kernel that keeps its alpha), so callers need not copy it.
    pub fn apply(&self, raw: &Image) -> Option<Image> {
        let mut out = match self.exposure {
            Some(e) => vista_image::tonemap(raw, e),
            None if self.normalize => normalized(raw, self.channels),
            None if self.opaque => raw.clone(),
            None => return None,
        };
        if self.opaque {
            for px in &mut out.data {
                px[3] = 1.0;
            }
        }
        Some(out)
    }
}

/// `raw` mapped to [0, 1] by the min and max of the finite values of its
/// first `channels` of R, G, B (a constant image maps to 0), alpha 1;
/// non-finite values map to 0. A single channel is shown grey.
pub fn normalized(raw: &Image, channels: u8) -> Image {
    let n = channels.clamp(1, 3) as usize;
    let finite = raw.data.iter().flat_map(|p| p[..n].iter().copied()).filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let span = if hi > lo { (hi as f64 - lo as f64) as f32 } else { f32::INFINITY };
    let map = |v: f32| if v.is_finite() { ((v - lo) / span).clamp(0.0, 1.0) } else { 0.0 };
    let data = raw
        .data
        .iter()
        .map(|p| match n {
            1 => [map(p[0]), map(p[0]), map(p[0]), 1.0],
            2 => [map(p[0]), map(p[1]), 0.0, 1.0],
            _ => [map(p[0]), map(p[1]), map(p[2]), 1.0],
        })
        .collect();
    Image::from_raw(raw.width, raw.height, data).expect("same size")
}

/// Whether a storage format holds integers (compared exactly, shown
/// normalised by default).
pub fn is_integer_format(format: &str) -> bool {
    vista_texel::Format::parse(format).is_ok_and(|f| f.is_integer())
}
