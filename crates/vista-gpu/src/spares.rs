//! What one run of the wgpu executor leaves for the next (see [`Spares`]).

/// Textures, sentinel fills and readback buffers a run leaves for the next
/// run to take instead of allocating its own: fresh ones cost a page fault
/// per 4 KiB as they are first written (filling a fresh 16 MiB image, 1024
/// x 1024, took 10-12 ms here). Only sentinel-filled textures are kept:
/// every run copies the sentinel over them first, so a texel a pass leaves
/// unwritten is counted and never shows an earlier run's value. A
/// concurrent run finds the pool empty and allocates.
#[derive(Default)]
pub(crate) struct Spares {
    pub(crate) textures: Vec<(TextureKey, wgpu::Texture)>,
    /// Sentinel `which` of a format, as many bytes as a padded copy needs.
    pub(crate) fills: Vec<((&'static str, usize, u64), wgpu::Buffer)>,
    pub(crate) staging: Vec<(u64, wgpu::Buffer)>,
}

/// A texture's shape: format, dimension, width, height, layers.
pub(crate) type TextureKey = (&'static str, vista_texel::Dimension, u32, u32, u32);
