//! Images read a row at a time, however their texels are held: an
//! [`Image`] lends its f32 rows, an [`Image16`] (a golden PNG's values,
//! 8 bytes a texel instead of 16) converts each row as it is read. The
//! metrics compare a golden of either kind with a render.

use crate::Image;

/// An image whose rows read as f32 RGBA texels.
pub trait Texels: Sync {
    /// Width and height in pixels.
    fn size(&self) -> (u32, u32);

    /// Row `y`'s texels: where they lie, or converted into `buf`.
    fn row<'a>(&'a self, y: u32, buf: &'a mut Vec<[f32; 4]>) -> &'a [[f32; 4]];
}

impl Texels for Image {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn row<'a>(&'a self, y: u32, _buf: &'a mut Vec<[f32; 4]>) -> &'a [[f32; 4]] {
        let w = self.width as usize;
        &self.data[y as usize * w..][..w]
    }
}

/// 16-bit RGBA values, as a 16-bit PNG holds them (an 8-bit one's `v` as
/// `257 v`): a golden's view decoded for the verdict. Each reads as
/// `v / 65535` in f32, the very values [`crate::decode_png16`] gives (for
/// an 8-bit PNG too: `257 v / 65535` and `v / 255` are the same real, so
/// the same correctly rounded f32). A 2048 x 2048 golden is 32 MiB here,
/// 64 MiB as an [`Image`] (a failing case's peak memory).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image16 {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `4 * width * height` values, RGBA, row after row.
    pub data: Vec<u16>,
}

impl Image16 {
    /// The value a 16-bit channel reads as.
    pub fn value(v: u16) -> f32 {
        f32::from(v) / 65535.0
    }

    /// The texel whose four channels are `p`, as f32.
    fn texel(p: &[u16]) -> [f32; 4] {
        [0, 1, 2, 3].map(|c| Image16::value(p[c]))
    }

    /// The texel at `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        let at = 4 * (y as usize * self.width as usize + x as usize);
        Image16::texel(&self.data[at..at + 4])
    }

    /// The same values as an [`Image`] (the report's images take one).
    pub fn to_image(&self) -> Image {
        let data = self.data.chunks_exact(4).map(Image16::texel).collect();
        Image::from_raw(self.width, self.height, data).expect("one texel per pixel")
    }
}

impl Texels for Image16 {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn row<'a>(&'a self, y: u32, buf: &'a mut Vec<[f32; 4]>) -> &'a [[f32; 4]] {
        let w = self.width as usize;
        buf.clear();
        buf.extend(self.data[4 * y as usize * w..][..4 * w].chunks_exact(4).map(Image16::texel));
        buf
    }
}
