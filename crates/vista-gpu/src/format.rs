//! vista-texel's formats and dimensions as wgpu's types (the formats
//! themselves, their sentinels and decoding are `vista_texel::Format`).

use vista_texel::{Dimension, Format};

use crate::GpuError;

/// The format of a WGSL storage format name.
pub(crate) fn parse(name: &str) -> Result<Format, GpuError> {
    Format::parse(name).map_err(|e| GpuError::Request(format!("output {e}")))
}

/// wgpu's texture format of one of vista-texel's formats.
pub(crate) fn wgpu_format(f: &Format) -> wgpu::TextureFormat {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as T;
    match f.storage {
        S::Rgba8Unorm => T::Rgba8Unorm,
        S::Rgba8Snorm => T::Rgba8Snorm,
        S::Rgba8Uint => T::Rgba8Uint,
        S::Rgba8Sint => T::Rgba8Sint,
        S::Rgba16Float => T::Rgba16Float,
        S::Rgba16Uint => T::Rgba16Uint,
        S::Rgba16Sint => T::Rgba16Sint,
        S::Rgba32Float => T::Rgba32Float,
        S::Rgba32Uint => T::Rgba32Uint,
        S::Rgba32Sint => T::Rgba32Sint,
        S::R32Float => T::R32Float,
        S::R32Uint => T::R32Uint,
        S::R32Sint => T::R32Sint,
        S::Rg32Float => T::Rg32Float,
        S::Rg32Uint => T::Rg32Uint,
        S::Rg32Sint => T::Rg32Sint,
        S::R8Unorm => T::R8Unorm,
        S::Rg8Unorm => T::Rg8Unorm,
        S::R16Float => T::R16Float,
        S::Rg16Float => T::Rg16Float,
        S::Bgra8Unorm => T::Bgra8Unorm,
        S::Rgb10a2Unorm => T::Rgb10a2Unorm,
        S::Rg11b10Ufloat => T::Rg11b10Ufloat,
        other => unreachable!("vista_texel lists no {other:?}"),
    }
}

/// wgpu's dimension of a texture viewed with `d`.
pub(crate) fn texture_dimension(d: Dimension) -> wgpu::TextureDimension {
    match d {
        Dimension::D1 => wgpu::TextureDimension::D1,
        Dimension::D2 | Dimension::D2Array | Dimension::Cube | Dimension::CubeArray => wgpu::TextureDimension::D2,
        Dimension::D3 => wgpu::TextureDimension::D3,
    }
}

/// wgpu's view dimension `d`.
pub(crate) fn view_dimension(d: Dimension) -> wgpu::TextureViewDimension {
    match d {
        Dimension::D1 => wgpu::TextureViewDimension::D1,
        Dimension::D2 => wgpu::TextureViewDimension::D2,
        Dimension::D2Array => wgpu::TextureViewDimension::D2Array,
        Dimension::D3 => wgpu::TextureViewDimension::D3,
        Dimension::Cube => wgpu::TextureViewDimension::Cube,
        Dimension::CubeArray => wgpu::TextureViewDimension::CubeArray,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_format_maps_to_the_wgpu_format_of_its_name() {
        for name in vista_texel::format_names() {
            let w = super::wgpu_format(&super::parse(name).unwrap());
            assert_eq!(format!("{w:?}").to_lowercase(), name, "{name}");
        }
        assert!(super::parse("rgba8unorm-srgb").unwrap_err().to_string().starts_with("output format rgba8unorm-srgb"));
    }
}
