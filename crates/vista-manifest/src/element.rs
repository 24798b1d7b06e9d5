//! What one element of a buffer resource holds: its stride, header and
//! leaf scalars, as a binding's WGSL type or a draw's vertex layout says.

/// A buffer binding's element: what one entry of its runtime-sized array
/// (or the whole binding, when fixed-size) holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Element {
    /// Bytes from one element to the next.
    pub stride: u32,
    /// Bytes before the runtime-sized array (0 for a bare array).
    pub header: u32,
    /// Elements of a fixed-size binding (`None`: runtime-sized).
    pub fixed: Option<u32>,
    /// Every leaf scalar of one element: byte offset, kind ('f' 'u' 'i':
    /// 32-bit; 'h': a u16, only a 16-bit index buffer's), and its field
    /// path (for NumPy's structured dtype).
    pub leaves: Vec<(u32, char, String)>,
    /// The WGSL type, for messages.
    pub wgsl: String,
}

/// A leaf kind's NumPy kind and its size in bytes.
pub fn leaf_numpy(kind: char) -> (char, u32) {
    match kind {
        'h' => ('u', 2),
        k => (k, 4),
    }
}
