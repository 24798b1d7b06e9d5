//! The formats a texture may have, listed once: each one's WGSL (and
//! WebGPU) name, naga's format, whether it may be a storage texture, its
//! texel size, the two sentinel texels that find unwritten texels, and the
//! encoding of f32 RGBA into its texels and back (missing channels read 0,
//! alpha 1, as a shader's load of the format does).

/// How a channel is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Channel {
    Unorm8,
    Snorm8,
    Uint8,
    Sint8,
    Float16,
    Uint16,
    Sint16,
    Float32,
    Uint32,
    Sint32,
    /// Packed channels of a 32-bit word (`rgb10a2unorm`, `rg11b10ufloat`):
    /// unsigned normalized 10 and 2 bits, unsigned floats with a 5-bit
    /// exponent and a 6- or 5-bit mantissa.
    Unorm10,
    Unorm2,
    UFloat11,
    UFloat10,
}

impl Channel {
    /// NumPy's dtype of one channel.
    fn numpy(self) -> &'static str {
        match self {
            Channel::Unorm8 | Channel::Uint8 => "|u1",
            Channel::Snorm8 | Channel::Sint8 => "|i1",
            Channel::Float16 => "<f2",
            Channel::Uint16 => "<u2",
            Channel::Sint16 => "<i2",
            Channel::Float32 => "<f4",
            Channel::Uint32 | Channel::Unorm10 | Channel::Unorm2 | Channel::UFloat11 | Channel::UFloat10 => "<u4",
            Channel::Sint32 => "<i4",
        }
    }

    fn bits(self) -> u32 {
        match self {
            Channel::Unorm8 | Channel::Snorm8 | Channel::Uint8 | Channel::Sint8 => 8,
            Channel::Float16 | Channel::Uint16 | Channel::Sint16 => 16,
            Channel::Unorm10 | Channel::UFloat10 => 10,
            Channel::Unorm2 => 2,
            Channel::UFloat11 => 11,
            Channel::Float32 | Channel::Uint32 | Channel::Sint32 => 32,
        }
    }

    fn bytes(self) -> usize {
        self.bits() as usize / 8
    }

    fn is_packed(self) -> bool {
        !self.bits().is_multiple_of(8)
    }

    /// A packed channel's value from its bits.
    fn unpack(self, v: u32) -> f32 {
        match self {
            Channel::Unorm10 => v as f32 / 1023.0,
            Channel::Unorm2 => v as f32 / 3.0,
            Channel::UFloat11 => ufloat_to_f32(v, 6),
            Channel::UFloat10 => ufloat_to_f32(v, 5),
            _ => unreachable!("{self:?} is not packed"),
        }
    }

    /// A packed channel's bits from a value, as an upload stores it.
    fn pack(self, v: f32) -> u32 {
        match self {
            Channel::Unorm10 => (v.clamp(0.0, 1.0) * 1023.0).round() as u32,
            Channel::Unorm2 => (v.clamp(0.0, 1.0) * 3.0).round() as u32,
            Channel::UFloat11 => f32_to_ufloat(v, 6),
            Channel::UFloat10 => f32_to_ufloat(v, 5),
            _ => unreachable!("{self:?} is not packed"),
        }
    }

    fn decode(self, b: &[u8]) -> f32 {
        match self {
            Channel::Unorm8 => b[0] as f32 / 255.0,
            Channel::Snorm8 => (b[0] as i8 as f32 / 127.0).max(-1.0),
            Channel::Uint8 => b[0] as f32,
            Channel::Sint8 => b[0] as i8 as f32,
            Channel::Float16 => f16_to_f32(u16::from_le_bytes([b[0], b[1]])),
            Channel::Uint16 => u16::from_le_bytes([b[0], b[1]]) as f32,
            Channel::Sint16 => i16::from_le_bytes([b[0], b[1]]) as f32,
            Channel::Float32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            Channel::Uint32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            Channel::Sint32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            _ => unreachable!("a packed channel is decoded from its word"),
        }
    }

    /// One channel of sentinel texel `which` (0 or 1): for 32-bit floats a
    /// NaN payload no arithmetic produces, for 16-bit floats the same idea,
    /// otherwise a bit pattern a kernel writes only by coincidence, which
    /// the second sentinel then tells apart.
    fn sentinel(self, which: usize) -> Vec<u8> {
        match (self.bytes(), which) {
            (4, 0) => crate::UNWRITTEN.to_le_bytes().to_vec(),
            (4, _) => 0x7FC0_BEEFu32.to_le_bytes().to_vec(),
            (2, 0) => 0x7E5Au16.to_le_bytes().to_vec(),
            (2, _) => 0x7E3Cu16.to_le_bytes().to_vec(),
            (_, 0) => vec![0xA5],
            (_, _) => vec![0x5A],
        }
    }
}

impl Channel {
    /// One channel of a texel from an f32 value, as a texture upload
    /// stores it: normalized formats clamp and round, integers round and
    /// saturate, half floats round to nearest.
    fn encode(self, v: f32) -> Vec<u8> {
        let int = |lo: f64, hi: f64| (v as f64).round().clamp(lo, hi);
        match self {
            Channel::Unorm8 => vec![(v.clamp(0.0, 1.0) * 255.0).round() as u8],
            Channel::Snorm8 => vec![((v.clamp(-1.0, 1.0) * 127.0).round() as i8) as u8],
            Channel::Uint8 => vec![int(0.0, 255.0) as u8],
            Channel::Sint8 => vec![(int(-128.0, 127.0) as i8) as u8],
            Channel::Float16 => half::f16::from_f32(v).to_le_bytes().to_vec(),
            Channel::Uint16 => (int(0.0, 65535.0) as u16).to_le_bytes().to_vec(),
            Channel::Sint16 => (int(-32768.0, 32767.0) as i16).to_le_bytes().to_vec(),
            Channel::Float32 => v.to_le_bytes().to_vec(),
            Channel::Uint32 => (int(0.0, u32::MAX as f64) as u32).to_le_bytes().to_vec(),
            Channel::Sint32 => (int(i32::MIN as f64, i32::MAX as f64) as i32).to_le_bytes().to_vec(),
            _ => unreachable!("a packed channel is encoded into its word"),
        }
    }
}

/// Half-precision bits to f32 (IEEE 754 binary16).
fn f16_to_f32(h: u16) -> f32 {
    let sign = ((h >> 15) as u32) << 31;
    let exp = ((h >> 10) & 0x1f) as u32;
    let frac = (h & 0x3ff) as u32;
    let bits = match (exp, frac) {
        (0, 0) => sign,
        (0, f) => {
            // Subnormal: normalise the fraction.
            let shift = f.leading_zeros() - 21;
            sign | ((127 - 15 + 1 - shift) << 23) | ((f << shift) & 0x3ff) << 13
        }
        (0x1f, f) => sign | 0x7f80_0000 | (f << 13),
        (e, f) => sign | ((e + 127 - 15) << 23) | (f << 13),
    };
    f32::from_bits(bits)
}

/// An unsigned float of a 5-bit exponent (bias 15) and an `m`-bit mantissa
/// (the channels of rg11b10ufloat) to f32.
fn ufloat_to_f32(bits: u32, m: u32) -> f32 {
    let (exp, frac) = (bits >> m, bits & ((1 << m) - 1));
    let frac = frac as f32 / (1u32 << m) as f32;
    match exp {
        0 => frac * 2f32.powi(-14),
        31 if frac == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + frac) * 2f32.powi(e as i32 - 15),
    }
}

/// f32 to an unsigned float of a 5-bit exponent and an `m`-bit mantissa,
/// rounding to nearest even: negatives give 0, values past the largest
/// finite one give it, infinity and NaN stay themselves.
fn f32_to_ufloat(v: f32, m: u32) -> u32 {
    if v.is_nan() {
        return (31 << m) | (1 << (m - 1));
    }
    if v == f32::INFINITY {
        return 31 << m;
    }
    if v <= 0.0 {
        return 0;
    }
    let v = v as f64;
    // The exponent of v, at least the subnormals' (2^-14).
    let e = v.log2().floor().max(-14.0) as i32;
    let q = (v / 2f64.powi(e - m as i32)).round_ties_even() as u32;
    let (e, q) = if q >= 2 << m { (e + 1, 1 << m) } else { (e, q) };
    if e > 15 {
        return (30 << m) | ((1 << m) - 1);
    }
    if q < 1 << m {
        return q; // a subnormal: exponent field 0
    }
    (((e + 15) as u32) << m) | (q - (1 << m))
}

/// What a sampled texture of a format returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleKind {
    /// Floats, normalized formats included (`texture_2d<f32>`).
    Float,
    /// Unsigned integers (`texture_2d<u32>`).
    Uint,
    /// Signed integers (`texture_2d<i32>`).
    Sint,
}

/// A format a texture may have.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Format {
    /// The WGSL (and WebGPU) name.
    pub name: &'static str,
    /// naga's storage format (engines map it to their own).
    pub storage: naga::StorageFormat,
    channels: &'static [Channel],
    /// Whether WebGPU's core lets a storage texture have it.
    storable: bool,
}

/// Every format a texture may have: WebGPU's core storage (write-only)
/// set, then formats engines render into and sample but core WebGPU does
/// not store to (`bgra8unorm` holds its channels blue first).
const FORMATS: &[(&str, naga::StorageFormat, &[Channel], bool)] = {
    use Channel::*;
    use naga::StorageFormat as F;
    &[
        ("rgba8unorm", F::Rgba8Unorm, &[Unorm8, Unorm8, Unorm8, Unorm8], true),
        ("rgba8snorm", F::Rgba8Snorm, &[Snorm8, Snorm8, Snorm8, Snorm8], true),
        ("rgba8uint", F::Rgba8Uint, &[Uint8, Uint8, Uint8, Uint8], true),
        ("rgba8sint", F::Rgba8Sint, &[Sint8, Sint8, Sint8, Sint8], true),
        ("rgba16float", F::Rgba16Float, &[Float16, Float16, Float16, Float16], true),
        ("rgba16uint", F::Rgba16Uint, &[Uint16, Uint16, Uint16, Uint16], true),
        ("rgba16sint", F::Rgba16Sint, &[Sint16, Sint16, Sint16, Sint16], true),
        ("rgba32float", F::Rgba32Float, &[Float32, Float32, Float32, Float32], true),
        ("rgba32uint", F::Rgba32Uint, &[Uint32, Uint32, Uint32, Uint32], true),
        ("rgba32sint", F::Rgba32Sint, &[Sint32, Sint32, Sint32, Sint32], true),
        ("r32float", F::R32Float, &[Float32], true),
        ("r32uint", F::R32Uint, &[Uint32], true),
        ("r32sint", F::R32Sint, &[Sint32], true),
        ("rg32float", F::Rg32Float, &[Float32, Float32], true),
        ("rg32uint", F::Rg32Uint, &[Uint32, Uint32], true),
        ("rg32sint", F::Rg32Sint, &[Sint32, Sint32], true),
        ("r8unorm", F::R8Unorm, &[Unorm8], false),
        ("rg8unorm", F::Rg8Unorm, &[Unorm8, Unorm8], false),
        ("r16float", F::R16Float, &[Float16], false),
        ("rg16float", F::Rg16Float, &[Float16, Float16], false),
        ("bgra8unorm", F::Bgra8Unorm, &[Unorm8, Unorm8, Unorm8, Unorm8], false),
        ("rgb10a2unorm", F::Rgb10a2Unorm, &[Unorm10, Unorm10, Unorm10, Unorm2], false),
        ("rg11b10ufloat", F::Rg11b10Ufloat, &[UFloat11, UFloat11, UFloat10], false),
    ]
};

/// The names [`Format::parse`] accepts, in the table's order.
pub fn format_names() -> Vec<&'static str> {
    FORMATS.iter().map(|f| f.0).collect()
}

impl Format {
    /// The format of a WGSL storage format name, or the error listing them.
    pub fn parse(name: &str) -> Result<Format, String> {
        FORMATS
            .iter()
            .find(|f| f.0 == name)
            .map(|&(name, storage, channels, storable)| Format { name, storage, channels, storable })
            .ok_or_else(|| format!("format {name} is not supported; supported: {}", format_names().join(", ")))
    }

    /// The format of naga's storage format, where it is one of the table's.
    pub fn of_naga(storage: naga::StorageFormat) -> Option<Format> {
        FORMATS.iter().find(|f| f.1 == storage).map(|&(name, storage, channels, storable)| Format {
            name,
            storage,
            channels,
            storable,
        })
    }

    /// Whether a storage texture may have this format (WebGPU's core set);
    /// the others are render targets and sampled textures only.
    pub fn is_storable(&self) -> bool {
        self.storable
    }

    /// Whether the channels are packed into one 32-bit word.
    fn is_packed(&self) -> bool {
        self.channels[0].is_packed()
    }

    /// Whether the texel holds blue before red (`bgra8unorm`).
    fn is_bgra(&self) -> bool {
        self.storage == naga::StorageFormat::Bgra8Unorm
    }

    /// Whether the channels are unsigned or signed integers (an integer
    /// output compares exactly).
    pub fn is_integer(&self) -> bool {
        self.sample_kind() != SampleKind::Float
    }

    /// NumPy's dtype of one channel and the channel count: a `.npy` of
    /// this texture holds an (H, W, channels) array of it (H, W for one).
    pub fn numpy(&self) -> (&'static str, usize) {
        if self.is_packed() {
            return ("<u4", 1); // one word per texel, as the GPU holds it
        }
        (self.channels[0].numpy(), self.channels.len())
    }

    /// The first format whose texels a `.npy` of this dtype and channel
    /// count holds, byte for byte.
    pub fn of_numpy(descr: &str, channels: usize) -> Option<Format> {
        format_names()
            .into_iter()
            .map(|n| Format::parse(n).expect("a listed name"))
            .find(|f| f.holds_numpy(descr, channels))
    }

    /// Whether a `.npy` of this dtype and channel count holds this format's
    /// texels byte for byte (a one-byte dtype in any byte order).
    pub fn holds_numpy(&self, descr: &str, channels: usize) -> bool {
        let (d, c) = self.numpy();
        c == channels && (d == descr || d.strip_prefix('|').is_some_and(|d| descr.ends_with(d)))
    }

    /// Bytes of one texel.
    pub fn texel_bytes(&self) -> usize {
        self.channels.iter().map(|c| c.bits() as usize).sum::<usize>() / 8
    }

    /// Sentinel texel 0 or 1 (for packed formats two words with channels
    /// a kernel writes only by coincidence).
    pub fn sentinel(&self, which: usize) -> Vec<u8> {
        if self.is_packed() {
            return [0xA5A5_A5A5u32, 0x5A5A_5A5A][which.min(1)].to_le_bytes().to_vec();
        }
        self.channels.iter().flat_map(|c| c.sentinel(which)).collect()
    }

    /// One texel from f32 RGBA (channels the format lacks are dropped).
    pub fn encode(&self, mut rgba: [f32; 4]) -> Vec<u8> {
        if self.is_bgra() {
            rgba.swap(0, 2);
        }
        if self.is_packed() {
            let (mut word, mut at) = (0u32, 0);
            for (c, v) in self.channels.iter().zip(rgba) {
                word |= c.pack(v) << at;
                at += c.bits();
            }
            return word.to_le_bytes().to_vec();
        }
        self.channels.iter().zip(rgba).flat_map(|(c, v)| c.encode(v)).collect()
    }

    /// Whether the channels are 32-bit floats (filterable only with the
    /// float32-filterable feature).
    pub fn is_float32(&self) -> bool {
        self.channels[0] == Channel::Float32
    }

    /// Whether a render pass may draw into it: every format but the 8-bit
    /// snorm one (WebGPU's rgba8snorm is not renderable; rg11b10ufloat
    /// needs the rg11b10ufloat-renderable feature, which engines check).
    pub fn is_renderable(&self) -> bool {
        self.channels[0] != Channel::Snorm8
    }

    /// Whether the channels are unsigned or signed integers (sampled as
    /// `texture_2d<u32>` / `<i32>`), else floats (normalized ones included).
    pub fn sample_kind(&self) -> SampleKind {
        match self.channels[0] {
            Channel::Uint8 | Channel::Uint16 | Channel::Uint32 => SampleKind::Uint,
            Channel::Sint8 | Channel::Sint16 | Channel::Sint32 => SampleKind::Sint,
            _ => SampleKind::Float,
        }
    }

    /// Channels per texel.
    pub fn channels(&self) -> usize {
        self.channels.len()
    }

    /// One texel as f32 RGBA.
    pub fn decode(&self, texel: &[u8]) -> [f32; 4] {
        let mut out = [0.0, 0.0, 0.0, 1.0];
        if self.is_packed() {
            let (word, mut at) = (u32::from_le_bytes([texel[0], texel[1], texel[2], texel[3]]), 0);
            for (o, c) in out.iter_mut().zip(self.channels) {
                *o = c.unpack((word >> at) & ((1 << c.bits()) - 1));
                at += c.bits();
            }
            return out;
        }
        let mut at = 0;
        for (i, c) in self.channels.iter().enumerate() {
            out[i] = c.decode(&texel[at..]);
            at += c.bytes();
        }
        if self.is_bgra() {
            out.swap(0, 2);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Of the storage formats, only rgba8snorm cannot be a render target.
    #[test]
    fn every_storage_format_but_rgba8snorm_is_renderable() {
        let not: Vec<&str> =
            format_names().iter().filter(|n| !Format::parse(n).unwrap().is_renderable()).copied().collect();
        assert_eq!(not, ["rgba8snorm"]);
    }

    /// The packed formats against values worked by hand from their bit
    /// layouts (red in the low bits).
    #[test]
    fn packed_and_blue_first_texels() {
        let f = |n| Format::parse(n).unwrap();
        // rg11b10ufloat: r = 1.0 (exp 15, mantissa 0), g = 0.5 + 0.5/64 (exp 14,
        // mantissa 1), b = 2^-14 * 3/32 (a subnormal of the 10-bit float).
        let word: u32 = (15 << 6) | (((14 << 6) | 1) << 11) | (3 << 22);
        let want = [1.0, 0.5 * (1.0 + 1.0 / 64.0), 3.0 / 32.0 * 2f32.powi(-14), 1.0];
        assert_eq!(f("rg11b10ufloat").decode(&word.to_le_bytes()), want);
        assert_eq!(f("rg11b10ufloat").encode(want), word.to_le_bytes());
        // Rounding to the 6-bit mantissa, ties to even; negatives to 0; the
        // largest finite value (65024) for anything beyond it.
        let g = |v: f32| u32::from_le_bytes(f("rg11b10ufloat").encode([v, 0.0, 0.0, 0.0]).try_into().unwrap()) & 0x7FF;
        assert_eq!(g(1.0 + 1.0 / 128.0), 15 << 6); // half an ulp: to the even 0
        assert_eq!(g(1.0 + 3.0 / 128.0), (15 << 6) | 2); // 1.5 ulps: to the even 2
        assert_eq!(g(-3.0), 0);
        assert_eq!(g(1e9), (30 << 6) | 63);
        assert_eq!(ufloat_to_f32((30 << 6) | 63, 6), 65024.0);
        assert_eq!(g(f32::INFINITY), 31 << 6);
        assert!(ufloat_to_f32(g(f32::NAN), 6).is_nan());
        assert_eq!(g(2f32.powi(-15)), 32); // a subnormal: half of 2^-14
        assert_eq!(g(2f32.powi(-14) * (127.0 / 128.0)), 1 << 6); // rounds up into the normals
        // rgb10a2unorm: 10-bit r, g, b and a 2-bit alpha.
        let word: u32 = 1023 | (341 << 20) | (2 << 30);
        assert_eq!(f("rgb10a2unorm").decode(&word.to_le_bytes()), [1.0, 0.0, 341.0 / 1023.0, 2.0 / 3.0]);
        assert_eq!(f("rgb10a2unorm").encode([1.0, -1.0, 341.0 / 1023.0, 0.7]), word.to_le_bytes());
        // bgra8unorm: blue first in memory, red first to shaders.
        assert_eq!(f("bgra8unorm").decode(&[255, 0, 51, 255]), [0.2, 0.0, 1.0, 1.0]);
        assert_eq!(f("bgra8unorm").encode([0.2, 0.0, 1.0, 1.0]), [255, 0, 51, 255]);
        assert_eq!(f("rg11b10ufloat").numpy(), ("<u4", 1));
        assert_eq!(f("rg11b10ufloat").texel_bytes(), 4);
        assert_ne!(f("rgb10a2unorm").sentinel(0), f("rgb10a2unorm").sentinel(1));
        let render_only: Vec<&str> = format_names().into_iter().filter(|n| !f(n).is_storable()).collect();
        assert_eq!(
            render_only,
            ["r8unorm", "rg8unorm", "r16float", "rg16float", "bgra8unorm", "rgb10a2unorm", "rg11b10ufloat"]
        );
    }

    #[test]
    fn texels_decode_per_format() {
        let f = |n| Format::parse(n).unwrap();
        assert_eq!(f("rgba8unorm").decode(&[0, 255, 51, 255]), [0.0, 1.0, 0.2, 1.0]);
        assert_eq!(f("rgba8snorm").decode(&[0x81, 0x80, 127, 0]), [-1.0, -1.0, 1.0, 0.0]);
        assert_eq!(f("r32float").decode(&2.5f32.to_le_bytes()), [2.5, 0.0, 0.0, 1.0]);
        let rg: Vec<u8> = [7u32, 9].iter().flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(f("rg32uint").decode(&rg), [7.0, 9.0, 0.0, 1.0]);
        // binary16: 1.0, -2.0, 65504, the smallest subnormal.
        let h: Vec<u8> = [0x3C00u16, 0xC000, 0x7BFF, 0x0001].iter().flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(f("rgba16float").decode(&h), [1.0, -2.0, 65504.0, 2f32.powi(-24)]);
        assert!(f16_to_f32(0x7E5A).is_nan() && f16_to_f32(0x7C00).is_infinite());
        assert_eq!(f("rgba16float").texel_bytes(), 8);
        assert_ne!(f("rgba8uint").sentinel(0), f("rgba8uint").sentinel(1));
        for name in format_names() {
            let fmt = f(name);
            let texel = [0.5, -2.0, 3.0, 1.0];
            let back = fmt.decode(&fmt.encode(texel));
            assert_eq!(fmt.encode(texel).len(), fmt.texel_bytes(), "{name}");
            assert_eq!(fmt.encode(back), fmt.encode(texel), "{name}: encode . decode . encode");
        }
        assert_eq!(f("rgba8unorm").encode([0.5, -1.0, 2.0, 1.0]), [128, 0, 255, 255]);
        assert_eq!(f("r32sint").encode([-3.4, 0.0, 0.0, 0.0]), (-3i32).to_le_bytes());
        let e = Format::parse("rgba8unorm-srgb").unwrap_err();
        assert!(e.contains("rgba8unorm-srgb is not supported") && e.contains("rg11b10ufloat"), "{e}");
        for name in format_names() {
            assert_eq!(Format::of_naga(f(name).storage).map(|g| g.name), Some(name));
        }
    }
}
