#![deny(missing_docs)]
//! The storage vocabulary vista's manifests (`vista-kernels`), plans
//! (`vista-render`) and engines (`vista-gpu`) share, each fact listed once:
//! the texel formats ([`Format`]), texture dimensions ([`Dimension`]) and
//! storage texture access modes ([`Access`]).
//!
//! Not for: any engine's own types (wgpu's formats are mapped in
//! `vista-gpu`) or what a kernel means.

mod format;
mod raster;

pub use format::{Format, SampleKind, format_names};
pub use raster::{Blend, BlendComponent, BlendFactor, BlendOp, Cull, Topology, VertexFormat};

/// What each 32-bit channel of a sentinel-filled texture holds before the
/// passes run (sentinel 0 of the 32-bit formats): a NaN with a payload no
/// arithmetic produces (operations give the canonical NaN). A texel still
/// holding the sentinel afterwards was never written.
pub const UNWRITTEN: u32 = 0x7FC0_DEAD;

/// A texture's dimension, as manifests and WebGPU's view dimensions spell it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Dimension {
    /// `1d`.
    D1,
    /// `2d`.
    D2,
    /// `2d-array`: layers of a 2d texture.
    D2Array,
    /// `3d`.
    D3,
    /// `cube`: six square layers, sampled as a cube (stored and written as
    /// their 2d-array).
    Cube,
    /// `cube-array`: cubes of six square layers each, sampled as a cube
    /// array (stored and written as their 2d-array).
    CubeArray,
}

impl Dimension {
    /// Every dimension, in order.
    pub const ALL: [Dimension; 6] =
        [Dimension::D1, Dimension::D2, Dimension::D2Array, Dimension::D3, Dimension::Cube, Dimension::CubeArray];
    /// The names of the dimensions a storage texture may have, for messages.
    pub const STORAGE_NAMES: &'static str = "1d|2d|2d-array|3d";
    /// The names of every dimension, for messages.
    pub const NAMES: &'static str = "1d|2d|2d-array|3d|cube|cube-array";

    /// The manifest's (and WebGPU's view) name.
    pub fn name(self) -> &'static str {
        match self {
            Dimension::D1 => "1d",
            Dimension::D2 => "2d",
            Dimension::D2Array => "2d-array",
            Dimension::D3 => "3d",
            Dimension::Cube => "cube",
            Dimension::CubeArray => "cube-array",
        }
    }

    /// The dimension a manifest names, or `None` for any other text.
    pub fn parse(text: &str) -> Option<Dimension> {
        Dimension::ALL.into_iter().find(|d| d.name() == text)
    }

    /// WebGPU's texture dimension (`1d`, `2d` or `3d`) of a texture viewed
    /// with this dimension.
    pub fn texture_name(self) -> &'static str {
        match self {
            Dimension::D1 => "1d",
            Dimension::D2 | Dimension::D2Array | Dimension::Cube | Dimension::CubeArray => "2d",
            Dimension::D3 => "3d",
        }
    }

    /// Entries of a manifest's `size` for this dimension (a cube's is its
    /// face's edge; a cube array's, the edge and the number of cubes).
    pub fn size_entries(self) -> usize {
        match self {
            Dimension::D1 | Dimension::Cube => 1,
            Dimension::D2 | Dimension::CubeArray => 2,
            Dimension::D2Array | Dimension::D3 => 3,
        }
    }

    /// The dimension of a WGSL texture type as naga reflects it.
    pub fn of_naga(dim: naga::ImageDimension, arrayed: bool) -> Option<Dimension> {
        use naga::ImageDimension as I;
        match (dim, arrayed) {
            (I::D1, false) => Some(Dimension::D1),
            (I::D2, false) => Some(Dimension::D2),
            (I::D2, true) => Some(Dimension::D2Array),
            (I::D3, false) => Some(Dimension::D3),
            (I::Cube, false) => Some(Dimension::Cube),
            (I::Cube, true) => Some(Dimension::CubeArray),
            _ => None,
        }
    }

    /// Whether it is sampled as cubes (`cube`, `cube-array`).
    pub fn is_cube(self) -> bool {
        matches!(self, Dimension::Cube | Dimension::CubeArray)
    }

    /// How the texture of a resource with this dimension is stored: a cube
    /// as its six layers, a cube array as its 6 N.
    pub fn stored(self) -> Dimension {
        match self {
            Dimension::Cube | Dimension::CubeArray => Dimension::D2Array,
            d => d,
        }
    }
}

/// How a pass may use a storage texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Access {
    /// WGSL `write` (WebGPU `write-only`).
    Write,
    /// WGSL `read` (WebGPU `read-only`).
    Read,
    /// WGSL `read_write` (WebGPU `read-write`); beyond the r32 formats it
    /// needs an adapter feature.
    ReadWrite,
}

impl Access {
    /// WGSL's name.
    pub fn wgsl(self) -> &'static str {
        match self {
            Access::Write => "write",
            Access::Read => "read",
            Access::ReadWrite => "read_write",
        }
    }

    /// WebGPU's name.
    pub fn web(self) -> &'static str {
        match self {
            Access::Write => "write-only",
            Access::Read => "read-only",
            Access::ReadWrite => "read-write",
        }
    }

    /// The access naga reflects from a storage texture's declaration.
    pub fn of_naga(access: naga::StorageAccess) -> Access {
        match (access.contains(naga::StorageAccess::LOAD), access.contains(naga::StorageAccess::STORE)) {
            (true, true) => Access::ReadWrite,
            (true, false) => Access::Read,
            (false, _) => Access::Write,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dimensions_round_trip_their_names_and_naga_types() {
        for d in Dimension::ALL {
            assert_eq!(Dimension::parse(d.name()), Some(d));
        }
        assert_eq!(Dimension::parse("cube-array"), Some(Dimension::CubeArray));
        assert_eq!(Dimension::parse("cubearray"), None);
        assert_eq!(Dimension::CubeArray.stored(), Dimension::D2Array);
        assert_eq!(Dimension::of_naga(naga::ImageDimension::D2, true), Some(Dimension::D2Array));
        assert_eq!(Dimension::of_naga(naga::ImageDimension::Cube, true), Some(Dimension::CubeArray));
        assert_eq!((Dimension::Cube.stored(), Dimension::Cube.texture_name()), (Dimension::D2Array, "2d"));
        let rw = naga::StorageAccess::LOAD | naga::StorageAccess::STORE;
        assert_eq!(Access::of_naga(rw).web(), "read-write");
        assert_eq!(Access::of_naga(naga::StorageAccess::LOAD).wgsl(), "read");
    }
}
