//! The storage formats a texture may have, listed once: each one's WGSL
//! (and WebGPU) name, naga's format, its texel size, the two sentinel
//! texels that find unwritten texels, and the encoding of f32 RGBA into its
//! texels and back (missing channels read 0, alpha 1, as a shader's load of
//! the format does).

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
            Channel::Uint32 => "<u4",
            Channel::Sint32 => "<i4",
        }
    }

    fn bytes(self) -> usize {
        match self {
            Channel::Unorm8 | Channel::Snorm8 | Channel::Uint8 | Channel::Sint8 => 1,
            Channel::Float16 | Channel::Uint16 | Channel::Sint16 => 2,
            _ => 4,
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

/// A storage format a texture may have.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Format {
    /// The WGSL (and WebGPU) name.
    pub name: &'static str,
    /// naga's storage format (engines map it to their own).
    pub storage: naga::StorageFormat,
    channels: &'static [Channel],
}

/// Every storage format a texture may have (WebGPU's core write-only set;
/// `bgra8unorm` needs an optional feature and is refused).
const FORMATS: &[(&str, naga::StorageFormat, &[Channel])] = {
    use Channel::*;
    use naga::StorageFormat as F;
    &[
        ("rgba8unorm", F::Rgba8Unorm, &[Unorm8, Unorm8, Unorm8, Unorm8]),
        ("rgba8snorm", F::Rgba8Snorm, &[Snorm8, Snorm8, Snorm8, Snorm8]),
        ("rgba8uint", F::Rgba8Uint, &[Uint8, Uint8, Uint8, Uint8]),
        ("rgba8sint", F::Rgba8Sint, &[Sint8, Sint8, Sint8, Sint8]),
        ("rgba16float", F::Rgba16Float, &[Float16, Float16, Float16, Float16]),
        ("rgba16uint", F::Rgba16Uint, &[Uint16, Uint16, Uint16, Uint16]),
        ("rgba16sint", F::Rgba16Sint, &[Sint16, Sint16, Sint16, Sint16]),
        ("rgba32float", F::Rgba32Float, &[Float32, Float32, Float32, Float32]),
        ("rgba32uint", F::Rgba32Uint, &[Uint32, Uint32, Uint32, Uint32]),
        ("rgba32sint", F::Rgba32Sint, &[Sint32, Sint32, Sint32, Sint32]),
        ("r32float", F::R32Float, &[Float32]),
        ("r32uint", F::R32Uint, &[Uint32]),
        ("r32sint", F::R32Sint, &[Sint32]),
        ("rg32float", F::Rg32Float, &[Float32, Float32]),
        ("rg32uint", F::Rg32Uint, &[Uint32, Uint32]),
        ("rg32sint", F::Rg32Sint, &[Sint32, Sint32]),
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
            .map(|&(name, storage, channels)| Format { name, storage, channels })
            .ok_or_else(|| format!("format {name} is not supported; supported: {}", format_names().join(", ")))
    }

    /// The format of naga's storage format, where it is one of the table's.
    pub fn of_naga(storage: naga::StorageFormat) -> Option<Format> {
        FORMATS.iter().find(|f| f.1 == storage).map(|&(name, storage, channels)| Format { name, storage, channels })
    }

    /// Whether the channels are unsigned or signed integers (an integer
    /// output compares exactly).
    pub fn is_integer(&self) -> bool {
        self.sample_kind() != SampleKind::Float
    }

    /// NumPy's dtype of one channel and the channel count: a `.npy` of
    /// this texture holds an (H, W, channels) array of it (H, W for one).
    pub fn numpy(&self) -> (&'static str, usize) {
        (self.channels[0].numpy(), self.channels.len())
    }

    /// The first format whose texels a `.npy` of this dtype and channel
    /// count holds, byte for byte.
    pub fn of_numpy(descr: &str, channels: usize) -> Option<Format> {
        format_names().into_iter().map(|n| Format::parse(n).expect("a listed name")).find(|f| {
            let (d, c) = f.numpy();
            (d, c) == (descr, channels) || (d.strip_prefix('|').is_some_and(|d| descr.ends_with(d)) && c == channels)
        })
    }

    /// Bytes of one texel.
    pub fn texel_bytes(&self) -> usize {
        self.channels.iter().map(|c| c.bytes()).sum()
    }

    /// Sentinel texel 0 or 1.
    pub fn sentinel(&self, which: usize) -> Vec<u8> {
        self.channels.iter().flat_map(|c| c.sentinel(which)).collect()
    }

    /// One texel from f32 RGBA (channels the format lacks are dropped).
    pub fn encode(&self, rgba: [f32; 4]) -> Vec<u8> {
        self.channels.iter().zip(rgba).flat_map(|(c, v)| c.encode(v)).collect()
    }

    /// Whether the channels are 32-bit floats (filterable only with the
    /// float32-filterable feature).
    pub fn is_float32(&self) -> bool {
        self.channels[0] == Channel::Float32
    }

    /// Whether a render pass may draw into it: every storage format but
    /// the 8-bit snorm one (WebGPU's rgba8snorm is not renderable).
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
        let mut at = 0;
        for (i, c) in self.channels.iter().enumerate() {
            out[i] = c.decode(&texel[at..]);
            at += c.bytes();
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
        let e = Format::parse("bgra8unorm").unwrap_err();
        assert!(e.contains("bgra8unorm is not supported") && e.contains("rgba16float"), "{e}");
        for name in format_names() {
            assert_eq!(Format::of_naga(f(name).storage).map(|g| g.name), Some(name));
        }
    }
}
