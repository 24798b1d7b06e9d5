//! naga_oil's names for an imported module's declarations,
//! `<item>X_naga_oil_mod_X<base32 of the module path>X`: written for the
//! wesl crate's output (so a manifest binds an imported global by its own
//! name in either language) and read back wherever a name is shown or
//! traced.

/// What naga_oil puts between an imported declaration's name and its
/// module's base32 path.
const DECORATION: &str = "X_naga_oil_mod_X";

/// `item` of the module at import path `module`, decorated.
pub(crate) fn decorate(item: &str, module: &str) -> String {
    format!("{item}{DECORATION}{}X", base32(module.as_bytes()))
}

/// RFC 4648 base32 without padding, as naga_oil writes module paths.
pub(crate) fn base32(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 32] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZ234567";
    let (mut out, mut acc, mut bits) = (String::new(), 0u32, 0u32);
    for &b in bytes {
        acc = (acc << 8) | b as u32;
        bits += 8;
        while bits >= 5 {
            bits -= 5;
            out.push(ALPHABET[((acc >> bits) & 31) as usize] as char);
        }
        acc &= (1 << bits) - 1;
    }
    if bits > 0 {
        out.push(ALPHABET[((acc << (5 - bits)) & 31) as usize] as char);
    }
    out
}

/// A declaration's name as its module wrote it and that module's path,
/// from the name naga_oil gives an imported one:
/// `frameX_naga_oil_mod_XNV4WY2LCHI5GGYLNMVZGCX` is `frame` of
/// `mylib::camera`. A name that is not so decorated is itself, no module.
pub fn undecorate(name: &str) -> (String, Option<String>) {
    let Some((item, rest)) = name.split_once(DECORATION) else { return (name.to_string(), None) };
    let encoded = rest.strip_suffix('X').unwrap_or(rest);
    // RFC 4648 base32 without padding, as naga_oil writes it.
    let (mut bits, mut acc, mut out) = (0u32, 0u32, Vec::new());
    for c in encoded.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'2'..=b'7' => c - b'2' + 26,
            _ => return (name.to_string(), None),
        };
        acc = (acc << 5) | v as u32;
        bits += 5;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    match String::from_utf8(out) {
        Ok(module) => (item.to_string(), Some(module)),
        Err(_) => (name.to_string(), None),
    }
}
