//! The fixed-function words of a render pass (SPEC 17), as WebGPU names
//! them: blend factors and operations, vertex formats, topologies and
//! culling. Manifests parse them here; engines map them to their own.

/// Finds `name` in a table of (name, value) pairs; the error lists the names.
fn lookup<T: Copy>(table: &[(&'static str, T)], what: &str, name: &str) -> Result<T, String> {
    table.iter().find(|(n, _)| *n == name).map(|(_, v)| *v).ok_or_else(|| {
        let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
        format!("{what} = \"{name}\" is not valid; expected {}", names.join("|"))
    })
}

/// Names a value of a table.
fn name_of<T: Copy + PartialEq>(table: &[(&'static str, T)], v: T) -> &'static str {
    table.iter().find(|(_, x)| *x == v).map(|(n, _)| *n).expect("every value is named")
}

/// A blend factor (WebGPU's `GPUBlendFactor`; the `src1` ones need
/// dual-source blending).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[allow(missing_docs)]
pub enum BlendFactor {
    Zero,
    One,
    Src,
    OneMinusSrc,
    SrcAlpha,
    OneMinusSrcAlpha,
    Dst,
    OneMinusDst,
    DstAlpha,
    OneMinusDstAlpha,
    SrcAlphaSaturated,
    Constant,
    OneMinusConstant,
    Src1,
    OneMinusSrc1,
    Src1Alpha,
    OneMinusSrc1Alpha,
}

impl BlendFactor {
    /// Every factor by its WebGPU name.
    pub const ALL: [(&'static str, BlendFactor); 17] = {
        use BlendFactor::*;
        [
            ("zero", Zero),
            ("one", One),
            ("src", Src),
            ("one-minus-src", OneMinusSrc),
            ("src-alpha", SrcAlpha),
            ("one-minus-src-alpha", OneMinusSrcAlpha),
            ("dst", Dst),
            ("one-minus-dst", OneMinusDst),
            ("dst-alpha", DstAlpha),
            ("one-minus-dst-alpha", OneMinusDstAlpha),
            ("src-alpha-saturated", SrcAlphaSaturated),
            ("constant", Constant),
            ("one-minus-constant", OneMinusConstant),
            ("src1", Src1),
            ("one-minus-src1", OneMinusSrc1),
            ("src1-alpha", Src1Alpha),
            ("one-minus-src1-alpha", OneMinusSrc1Alpha),
        ]
    };

    /// Whether the factor reads the fragment's second source
    /// (`@blend_src(1)`, dual-source blending).
    pub fn is_src1(self) -> bool {
        matches!(
            self,
            BlendFactor::Src1 | BlendFactor::OneMinusSrc1 | BlendFactor::Src1Alpha | BlendFactor::OneMinusSrc1Alpha
        )
    }

    /// WebGPU's name.
    pub fn web(self) -> &'static str {
        name_of(&Self::ALL, self)
    }
}

/// A blend operation (WebGPU's `GPUBlendOperation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[allow(missing_docs)]
pub enum BlendOp {
    Add,
    Subtract,
    ReverseSubtract,
    Min,
    Max,
}

impl BlendOp {
    /// Every operation by its WebGPU name.
    pub const ALL: [(&'static str, BlendOp); 5] = [
        ("add", BlendOp::Add),
        ("subtract", BlendOp::Subtract),
        ("reverse-subtract", BlendOp::ReverseSubtract),
        ("min", BlendOp::Min),
        ("max", BlendOp::Max),
    ];

    /// WebGPU's name.
    pub fn web(self) -> &'static str {
        name_of(&Self::ALL, self)
    }
}

/// One of a blend's two equations: `src * src_factor <op> dst * dst_factor`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct BlendComponent {
    /// The source (fragment output) factor.
    pub src: BlendFactor,
    /// The destination (texel) factor.
    pub dst: BlendFactor,
    /// How the two products combine.
    pub op: BlendOp,
}

impl BlendComponent {
    /// `[src, dst, op]` by WebGPU's names, as a manifest writes it.
    pub fn parse(words: &[&str]) -> Result<BlendComponent, String> {
        let [src, dst, op] = words else {
            return Err(format!("{} names; expected three: [src factor, dst factor, operation]", words.len()));
        };
        Ok(BlendComponent {
            src: lookup(&BlendFactor::ALL, "factor", src)?,
            dst: lookup(&BlendFactor::ALL, "factor", dst)?,
            op: lookup(&BlendOp::ALL, "operation", op)?,
        })
    }

    /// Whether either factor reads the pass's blend constant.
    pub fn uses_constant(self) -> bool {
        [self.src, self.dst].iter().any(|f| matches!(f, BlendFactor::Constant | BlendFactor::OneMinusConstant))
    }

    /// Whether either factor reads the fragment's second source.
    pub fn uses_src1(self) -> bool {
        self.src.is_src1() || self.dst.is_src1()
    }
}

/// How a render pass's fragment output meets what its target holds
/// (`blend` of a target; SPEC 17).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Blend {
    /// `replace`: the output replaces the texel.
    Replace,
    /// `alpha`: `src * src.a + dst * (1 - src.a)`, alpha `src.a + dst.a * (1 - src.a)`.
    Alpha,
    /// `additive`: `src + dst`, colour and alpha.
    Additive,
    /// `{ color = [src, dst, op], alpha = [src, dst, op] }` by WebGPU's names.
    Factors {
        /// The colour channels' equation.
        color: BlendComponent,
        /// The alpha channel's equation.
        alpha: BlendComponent,
    },
}

impl Blend {
    /// Every named blend.
    pub const ALL: [(&'static str, Blend); 3] =
        [("replace", Blend::Replace), ("alpha", Blend::Alpha), ("additive", Blend::Additive)];

    /// The blend a manifest names; the error lists the names allowed.
    pub fn parse(name: &str) -> Result<Blend, String> {
        lookup(&Blend::ALL, "blend", name)
    }

    /// The colour and alpha equations; `None` for `replace` (no blending).
    pub fn components(self) -> Option<(BlendComponent, BlendComponent)> {
        use BlendFactor::*;
        let c = |src, dst| BlendComponent { src, dst, op: BlendOp::Add };
        match self {
            Blend::Replace => None,
            Blend::Alpha => Some((c(SrcAlpha, OneMinusSrcAlpha), c(One, OneMinusSrcAlpha))),
            Blend::Additive => Some((c(One, One), c(One, One))),
            Blend::Factors { color, alpha } => Some((color, alpha)),
        }
    }

    /// Whether the blend reads the pass's blend constant.
    pub fn uses_constant(self) -> bool {
        self.components().is_some_and(|(c, a)| c.uses_constant() || a.uses_constant())
    }

    /// Whether the blend reads the fragment's second source (`@blend_src(1)`).
    pub fn uses_src1(self) -> bool {
        self.components().is_some_and(|(c, a)| c.uses_src1() || a.uses_src1())
    }
}

/// A vertex attribute's format (WebGPU's `GPUVertexFormat`, the 32-bit
/// ones and the four-byte 8-bit ones).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct VertexFormat {
    /// WebGPU's name.
    pub name: &'static str,
    /// The shader's scalar kind: 'f' (normalized formats too), 'u' or 'i'.
    pub kind: char,
    /// Components (the shader's vector size; 1: a scalar).
    pub components: u32,
    /// Bytes in the buffer.
    pub bytes: u32,
}

impl VertexFormat {
    /// Every vertex format of WebGPU (`GPUVertexFormat`), in its order.
    pub const ALL: [VertexFormat; 41] = {
        const fn f(name: &'static str, kind: char, components: u32, bytes: u32) -> VertexFormat {
            VertexFormat { name, kind, components, bytes }
        }
        [
            f("uint8", 'u', 1, 1),
            f("uint8x2", 'u', 2, 2),
            f("uint8x4", 'u', 4, 4),
            f("sint8", 'i', 1, 1),
            f("sint8x2", 'i', 2, 2),
            f("sint8x4", 'i', 4, 4),
            f("unorm8", 'f', 1, 1),
            f("unorm8x2", 'f', 2, 2),
            f("unorm8x4", 'f', 4, 4),
            f("snorm8", 'f', 1, 1),
            f("snorm8x2", 'f', 2, 2),
            f("snorm8x4", 'f', 4, 4),
            f("uint16", 'u', 1, 2),
            f("uint16x2", 'u', 2, 4),
            f("uint16x4", 'u', 4, 8),
            f("sint16", 'i', 1, 2),
            f("sint16x2", 'i', 2, 4),
            f("sint16x4", 'i', 4, 8),
            f("unorm16", 'f', 1, 2),
            f("unorm16x2", 'f', 2, 4),
            f("unorm16x4", 'f', 4, 8),
            f("snorm16", 'f', 1, 2),
            f("snorm16x2", 'f', 2, 4),
            f("snorm16x4", 'f', 4, 8),
            f("float16", 'f', 1, 2),
            f("float16x2", 'f', 2, 4),
            f("float16x4", 'f', 4, 8),
            f("float32", 'f', 1, 4),
            f("float32x2", 'f', 2, 8),
            f("float32x3", 'f', 3, 12),
            f("float32x4", 'f', 4, 16),
            f("uint32", 'u', 1, 4),
            f("uint32x2", 'u', 2, 8),
            f("uint32x3", 'u', 3, 12),
            f("uint32x4", 'u', 4, 16),
            f("sint32", 'i', 1, 4),
            f("sint32x2", 'i', 2, 8),
            f("sint32x3", 'i', 3, 12),
            f("sint32x4", 'i', 4, 16),
            f("unorm10-10-10-2", 'f', 4, 4),
            f("unorm8x4-bgra", 'f', 4, 4),
        ]
    };

    /// The format a manifest names; the error lists the names allowed.
    pub fn parse(name: &str) -> Result<VertexFormat, String> {
        VertexFormat::ALL.iter().find(|f| f.name == name).copied().ok_or_else(|| {
            let names: Vec<&str> = VertexFormat::ALL.iter().map(|f| f.name).collect();
            format!("format = \"{name}\" is not valid; expected {}", names.join("|"))
        })
    }

    /// The 32-bit format a shader input of this kind and size reads unconverted.
    pub fn of_input(kind: char, components: u32) -> Option<VertexFormat> {
        VertexFormat::ALL
            .iter()
            .find(|f| f.kind == kind && f.components == components && f.bytes == 4 * components)
            .copied()
    }

    /// Whether each component is one 32-bit word in the buffer.
    pub fn is_32bit(self) -> bool {
        self.bytes == 4 * self.components
    }
}

/// How a draw's vertices make primitives (WebGPU's `GPUPrimitiveTopology`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[allow(missing_docs)]
pub enum Topology {
    TriangleList,
    TriangleStrip,
    LineList,
    LineStrip,
    PointList,
}

impl Topology {
    /// Every topology by its WebGPU name.
    pub const ALL: [(&'static str, Topology); 5] = [
        ("triangle-list", Topology::TriangleList),
        ("triangle-strip", Topology::TriangleStrip),
        ("line-list", Topology::LineList),
        ("line-strip", Topology::LineStrip),
        ("point-list", Topology::PointList),
    ];

    /// The topology a manifest names.
    pub fn parse(name: &str) -> Result<Topology, String> {
        lookup(&Topology::ALL, "topology", name)
    }

    /// WebGPU's name.
    pub fn web(self) -> &'static str {
        name_of(&Self::ALL, self)
    }
}

/// Which faces a draw discards (WebGPU's `GPUCullMode`; front faces wind
/// counter-clockwise).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[allow(missing_docs)]
pub enum Cull {
    None,
    Back,
    Front,
}

impl Cull {
    /// Every mode by its WebGPU name.
    pub const ALL: [(&'static str, Cull); 3] = [("none", Cull::None), ("back", Cull::Back), ("front", Cull::Front)];

    /// The mode a manifest names.
    pub fn parse(name: &str) -> Result<Cull, String> {
        lookup(&Cull::ALL, "cull", name)
    }

    /// WebGPU's name.
    pub fn web(self) -> &'static str {
        name_of(&Self::ALL, self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_blends_are_their_factors() {
        let (c, a) = Blend::Alpha.components().unwrap();
        assert_eq!((c.src, c.dst, a.src), (BlendFactor::SrcAlpha, BlendFactor::OneMinusSrcAlpha, BlendFactor::One));
        assert_eq!(Blend::Replace.components(), None);
        let k = BlendComponent::parse(&["constant", "one-minus-src", "max"]).unwrap();
        assert!(k.uses_constant() && k.op == BlendOp::Max);
        assert!(BlendComponent::parse(&["one", "two", "add"]).unwrap_err().contains("factor = \"two\""));
        assert!(BlendComponent::parse(&["one", "one"]).unwrap_err().contains("expected three"));
    }

    #[test]
    fn vertex_formats_match_shader_inputs() {
        assert_eq!(VertexFormat::of_input('f', 3).unwrap().name, "float32x3");
        assert_eq!(VertexFormat::of_input('u', 1).unwrap().name, "uint32");
        assert!(!VertexFormat::parse("unorm8x4").unwrap().is_32bit());
        assert!(VertexFormat::parse("float16x3").unwrap_err().contains("float32x4"));
        assert_eq!(VertexFormat::parse("unorm10-10-10-2").unwrap().components, 4);
        assert_eq!(Topology::parse("line-strip").unwrap().web(), "line-strip");
        assert!(Cull::parse("both").unwrap_err().contains("none|back|front"));
    }
}
