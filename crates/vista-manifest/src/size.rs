//! The size a request may ask for, checked before any GPU work.

use crate::ParamError;

/// Largest width or height any request may ask for. Devices limit 2D storage
/// textures to 8192 by default, and the check happens before GPU work.
pub const MAX_DIMENSION: u32 = 8192;

/// Validates an image size before any GPU work.
pub fn check_size(width: u32, height: u32) -> Result<(), ParamError> {
    for (what, v) in [("width", width), ("height", height)] {
        if v == 0 || v > MAX_DIMENSION {
            return Err(ParamError::OutOfRange {
                param: what.to_string(),
                value: v.to_string(),
                range: format!("[1, {MAX_DIMENSION}]"),
            });
        }
    }
    Ok(())
}

/// Parses `WxH` (e.g. `256x256`).
pub fn parse_size(text: &str) -> Result<(u32, u32), ParamError> {
    let bad = || ParamError::BadValue {
        param: "size".into(),
        value: text.into(),
        expected: format!("WIDTHxHEIGHT with each in [1, {MAX_DIMENSION}], e.g. 256x256"),
    };
    let (w, h) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    check_size(w, h)?;
    Ok((w, h))
}
