//! Byte layout of a kernel's uniform block.
//!
//! Kernels push named scalars in the order of their WGSL `Params` struct
//! (u32 and f32 only, so every field is 4-byte aligned with no implicit
//! padding). The names are kept so a test can compare the layout against the
//! struct that naga reflects from the shader.

/// One field: name, byte offset, and whether it is an integer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub offset: u32,
    pub is_uint: bool,
}

/// A uniform block under construction. Starts with `width`, `height`.
#[derive(Debug, Clone)]
pub struct Uniforms {
    bytes: Vec<u8>,
    fields: Vec<Field>,
}

impl Uniforms {
    pub fn new(width: u32, height: u32) -> Uniforms {
        Uniforms { bytes: Vec::new(), fields: Vec::new() }.u32("width", width).u32("height", height)
    }

    pub fn u32(mut self, name: &'static str, v: u32) -> Self {
        self.fields.push(Field { name, offset: self.bytes.len() as u32, is_uint: true });
        self.bytes.extend_from_slice(&v.to_le_bytes());
        self
    }

    pub fn f32(mut self, name: &'static str, v: f32) -> Self {
        self.fields.push(Field { name, offset: self.bytes.len() as u32, is_uint: false });
        self.bytes.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// A vector as three scalars `name_x`, `name_y`, `name_z` (`vec3` would
    /// bring 16-byte alignment rules into every struct).
    pub fn vec3(self, names: [&'static str; 3], v: [f64; 3]) -> Self {
        self.f32(names[0], v[0] as f32).f32(names[1], v[1] as f32).f32(names[2], v[2] as f32)
    }

    pub fn fields(&self) -> &[Field] {
        &self.fields
    }

    /// The block padded to a multiple of 16 bytes, as uniform buffers want.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = self.bytes.clone();
        b.resize(b.len().div_ceil(16).max(1) * 16, 0);
        b
    }

    /// Size without the trailing padding: equals the WGSL struct's size.
    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }
}
