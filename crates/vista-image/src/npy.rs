//! NumPy `.npy` files (format version 1.0) for buffer goldens and inputs:
//! a dtype (`<f4`, `<u4`, `<i4`, or a structured dtype for a WGSL struct,
//! padding as void fields), a C-order shape, and the raw little-endian
//! bytes. Written by hand rather than with npyz: vista's buffers are bytes
//! whose dtype comes from naga's reflection at run time, which a typed
//! reader/writer would have to re-derive; and npyz 0.9 brings 27 more crates
//! (a Python-literal parser on pest, big integers) and 11.8 s of build
//! (18 CPU-s, debug, 2 cores; 2026-12-07) for these 290 lines.

use std::path::Path;

use crate::ImageError;

const MAGIC: &[u8] = b"\x93NUMPY";

/// A decoded `.npy` file.
#[derive(Debug, Clone, PartialEq)]
pub struct Npy {
    /// The dtype as the header spells it (`<f4`, or a list for a struct).
    pub descr: String,
    /// The array shape in C order, in elements of the dtype.
    pub shape: Vec<u64>,
    /// Bytes of one element (of the dtype).
    pub item_bytes: u64,
    /// The raw data, C order.
    pub data: Vec<u8>,
}

impl Npy {
    /// Elements along the first axis times the rest: the total count of
    /// dtype items.
    pub fn items(&self) -> u64 {
        self.shape.iter().product()
    }
}

/// The `.npy` bytes of `data` with this dtype and shape.
pub fn encode_npy(descr: &str, shape: &[u64], data: &[u8]) -> Vec<u8> {
    let shape_text = match shape {
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ")),
    };
    let descr_text = if descr.starts_with('[') { descr.to_string() } else { format!("'{descr}'") };
    let mut header = format!("{{'descr': {descr_text}, 'fortran_order': False, 'shape': {shape_text}, }}");
    // Magic (6) + version (2) + length (2) + header, padded to 64 bytes.
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat(total.next_multiple_of(64) - total));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

/// Writes a `.npy` atomically.
pub fn write_npy(path: &Path, descr: &str, shape: &[u64], data: &[u8]) -> Result<(), ImageError> {
    crate::atomic_write(path, &encode_npy(descr, shape, data))
}

/// Reads a `.npy` file.
pub fn read_npy(path: &Path) -> Result<Npy, ImageError> {
    let bytes = std::fs::read(path).map_err(|source| ImageError::Io { path: path.to_path_buf(), source })?;
    decode_npy(path, &bytes)
}

/// Decodes `.npy` bytes (`path` names the file in errors): version 1 or 2,
/// little-endian or byte-sized dtypes, C order.
pub fn decode_npy(path: &Path, bytes: &[u8]) -> Result<Npy, ImageError> {
    let bad = |msg: String| ImageError::Decode { path: path.to_path_buf(), format: "NumPy .npy", msg };
    if !bytes.starts_with(MAGIC) || bytes.len() < 10 {
        return Err(bad("no \\x93NUMPY magic at the start".into()));
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12),
        v => return Err(bad(format!("format version {v} is not supported; expected 1, 2 or 3"))),
    };
    let header = bytes.get(start..start + len).ok_or_else(|| bad("the header is cut short".into()))?;
    let header = std::str::from_utf8(header).map_err(|_| bad("the header is not text".into()))?;
    let value = |key: &str| -> Result<&str, ImageError> {
        let at = header.find(&format!("'{key}':")).ok_or_else(|| bad(format!("the header has no '{key}'")))?;
        Ok(header[at + key.len() + 3..].trim_start())
    };
    let descr_at = value("descr")?;
    let descr = if descr_at.starts_with('[') {
        let mut depth = 0;
        let end = descr_at
            .char_indices()
            .find(|&(_, c)| {
                depth += match c {
                    '[' | '(' => 1,
                    ']' | ')' => -1,
                    _ => 0,
                };
                depth == 0
            })
            .map(|(i, _)| i)
            .ok_or_else(|| bad("the structured descr is not closed".into()))?;
        descr_at[..=end].to_string()
    } else {
        let q = descr_at.chars().next().unwrap_or('\'');
        descr_at[1..].split(q).next().unwrap_or_default().to_string()
    };
    if value("fortran_order")?.starts_with("True") {
        return Err(bad("fortran_order = True is not supported; save it in C order".into()));
    }
    let shape_at = value("shape")?;
    let shape_text = shape_at
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| bad("the shape is not a tuple".into()))?;
    let shape: Vec<u64> = shape_text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<u64>().map_err(|_| bad(format!("shape entry {s} is not a number"))))
        .collect::<Result<_, _>>()?;
    let item_bytes = dtype_bytes(&descr).map_err(bad)?;
    let data = bytes[start + len..].to_vec();
    // Checked: a crafted shape must not wrap around to the file's length.
    let want = shape
        .iter()
        .try_fold(1u64, |n, &d| n.checked_mul(d))
        .and_then(|n| n.checked_mul(item_bytes))
        .ok_or_else(|| bad(format!("shape {shape:?} of {descr} overflows 64-bit byte counts")))?;
    if data.len() as u64 != want {
        return Err(bad(format!("{} data bytes for shape {shape:?} of {descr} ({want} expected)", data.len())));
    }
    Ok(Npy { descr, shape, item_bytes, data })
}

/// The largest dtype item [`dtype_bytes`] accepts: 64 KiB, far above any
/// struct a shader reads (a 4x4 matrix is 64 bytes).
pub const MAX_ITEM_BYTES: u64 = 1 << 16;

/// Bytes of one item of a dtype: a simple one (`<f4`, `|u1`, `|V4`) or a
/// structured list (`[('a', '<f4'), ('b', '<u4', (3,))]`).
pub fn dtype_bytes(descr: &str) -> Result<u64, String> {
    let mut total = 0u64;
    if !descr.starts_with('[') {
        total = simple_bytes(descr)?;
    }
    for (ty, count) in if descr.starts_with('[') { structured_fields(descr)? } else { Vec::new() } {
        total = simple_bytes(&ty)?.checked_mul(count).and_then(|b| total.checked_add(b)).unwrap_or(u64::MAX);
    }
    // An item is a few numbers; one larger than this is a crafted header
    // (and listing its numbers would take the machine's memory).
    if total > MAX_ITEM_BYTES {
        return Err(format!("dtype {descr} has items of {total} bytes; at most {MAX_ITEM_BYTES} are allowed"));
    }
    Ok(total)
}

/// Bytes of a simple little-endian (or byte-sized) dtype.
fn simple_bytes(descr: &str) -> Result<u64, String> {
    let (order, rest) = descr.split_at(descr.len().min(1));
    let little = ["<", "|", "="].contains(&order) || (order == ">" && rest.ends_with('1'));
    if !little {
        return Err(format!("dtype {descr} is not little-endian; save it as little-endian ('<')"));
    }
    rest.get(1..)
        .and_then(|n| n.parse::<u64>().ok())
        .ok_or_else(|| format!("dtype {descr} is not a fixed-size number type"))
}

/// The fields of a structured dtype, in order: each one's simple type and
/// how many of it (the product of its subarray shape, 1 without one).
fn structured_fields(descr: &str) -> Result<Vec<(String, u64)>, String> {
    let mut out = Vec::new();
    // Each field: ('name', 'type') or ('name', 'type', (dims)).
    for field in descr[1..descr.len() - 1].split("),").map(|f| f.trim().trim_start_matches('(').trim_end_matches(')')) {
        if field.trim().is_empty() {
            continue;
        }
        let parts: Vec<&str> = field.splitn(3, ',').map(str::trim).collect();
        let ty = parts.get(1).ok_or_else(|| format!("structured field {field} has no type"))?;
        let mut count = 1u64;
        if let Some(dims) = parts.get(2) {
            for d in dims.trim_matches(|c| c == '(' || c == ')').split(',').map(str::trim).filter(|d| !d.is_empty()) {
                let d = d.parse::<u64>().map_err(|_| format!("structured field {field} has a bad shape"))?;
                count = count.checked_mul(d).ok_or_else(|| format!("structured field {field}'s shape overflows"))?;
            }
        }
        out.push((ty.trim_matches(|c| c == '\'' || c == '"').to_string(), count));
    }
    Ok(out)
}

/// Every number of one item of a dtype, in order: (byte offset, kind
/// `f` `u` `i`, bytes). Void (padding) fields are skipped.
pub fn dtype_numbers(descr: &str) -> Result<Vec<(u64, char, u64)>, String> {
    let simple = |ty: &str| -> Result<(char, u64), String> {
        let kind = ty.chars().nth(1).ok_or_else(|| format!("dtype {ty} is not valid"))?;
        Ok((kind, simple_bytes(ty)?))
    };
    if !descr.starts_with('[') {
        let (kind, n) = simple(descr)?;
        return Ok(vec![(0, kind, n)]);
    }
    dtype_bytes(descr)?;
    let mut out = Vec::new();
    let mut at = 0;
    for (ty, count) in structured_fields(descr)? {
        let (kind, n) = simple(&ty)?;
        for i in 0..count {
            if kind != 'V' {
                out.push((at + i * n, kind, n));
            }
        }
        at += count * n;
    }
    Ok(out)
}

/// Every number of `n`'s data as f64, item after item.
pub fn values(n: &Npy) -> Result<Vec<f64>, String> {
    let numbers = dtype_numbers(&n.descr)?;
    let mut out = Vec::new();
    for item in n.data.chunks_exact(n.item_bytes.max(1) as usize) {
        for &(offset, kind, size) in &numbers {
            let b = &item[offset as usize..(offset + size) as usize];
            out.push(match (kind, size) {
                ('f', 4) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                ('f', 8) => f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]),
                ('u', 1) => b[0] as f64,
                ('u', 2) => u16::from_le_bytes([b[0], b[1]]) as f64,
                ('u', 4) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                ('i', 1) => b[0] as i8 as f64,
                ('i', 2) => i16::from_le_bytes([b[0], b[1]]) as f64,
                ('i', 4) => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                ('b', 1) => b[0] as f64,
                _ => return Err(format!("dtype {} holds a {kind}{size} number, which vista cannot read", n.descr)),
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_round_trips_simple_and_structured_dtypes() {
        let p = Path::new("x.npy");
        let data: Vec<u8> = [1.5f32, -2.0, 3.25].iter().flat_map(|v| v.to_le_bytes()).collect();
        let bytes = encode_npy("<f4", &[3], &data);
        assert_eq!((10 + u16::from_le_bytes([bytes[8], bytes[9]]) as usize) % 64, 0, "header padded to 64");
        let n = decode_npy(p, &bytes).unwrap();
        assert_eq!((n.descr.as_str(), n.shape.as_slice(), n.item_bytes, &n.data), ("<f4", &[3u64][..], 4, &data));
        let s = "[('pos', '<f4', (2,)), ('id', '<u4'), ('_pad', '|V4')]";
        let n = decode_npy(p, &encode_npy(s, &[2, 1], &[0u8; 32])).unwrap();
        assert_eq!((n.descr.as_str(), n.item_bytes, n.items()), (s, 16, 2));
        // Real NumPy headers: version 1, double quotes absent, a trailing comma.
        let e = decode_npy(p, &encode_npy("<f4", &[4], &data)).unwrap_err().to_string();
        assert!(e.contains("12 data bytes for shape [4]"), "{e}");
        assert!(decode_npy(p, &encode_npy(">f4", &[3], &data)).unwrap_err().to_string().contains("little-endian"));
        assert!(decode_npy(p, b"PK\x03\x04").unwrap_err().to_string().contains("magic"));
        let mut item = Vec::new();
        item.extend(1.5f32.to_le_bytes());
        item.extend(2.5f32.to_le_bytes());
        item.extend(7u32.to_le_bytes());
        item.extend([0xFF; 4]);
        let n = decode_npy(p, &encode_npy(s, &[1], &item)).unwrap();
        assert_eq!(values(&n).unwrap(), [1.5, 2.5, 7.0], "padding skipped");
    }

    /// Shapes and dtypes whose byte count overflows 64 bits (or whose one
    /// item is absurdly large) are refused, never wrapped to the file's
    /// length or listed number by number.
    #[test]
    fn crafted_shapes_and_dtypes_are_refused_with_checked_arithmetic() {
        let p = Path::new("x.npy");
        let data = [0u8; 16];
        // 2^62 * 4 * 4 bytes wraps to 0 in u64; with a 0 the data is empty too.
        let e = decode_npy(p, &encode_npy("<f4", &[1 << 62, 4, 0], &[])).unwrap_err().to_string();
        assert!(e.contains("overflows 64-bit byte counts"), "{e}");
        let e = decode_npy(p, &encode_npy("<f4", &[1 << 62, 4], &data)).unwrap_err().to_string();
        assert!(e.contains("overflows"), "{e}");
        let e = decode_npy(p, &encode_npy("<f18446744073709551615", &[1], &data)).unwrap_err().to_string();
        assert!(e.contains("at most 65536 are allowed"), "{e}");
        let huge = "[('a', '<f4', (4294967296, 4294967296))]";
        let e = decode_npy(p, &encode_npy(huge, &[0], &[])).unwrap_err().to_string();
        assert!(e.contains("overflows") || e.contains("at most 65536"), "{e}");
        assert!(dtype_numbers("[('a', '<f4', (1000000000,))]").unwrap_err().contains("at most 65536"));
    }
}
