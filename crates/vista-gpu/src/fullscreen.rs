//! vista's own vertex stage for full-screen render passes (SPEC 17,
//! `vertex = "fullscreen"`), the same WGSL on every engine.

/// The vertex stage of `vertex = "fullscreen"`: one triangle over the
/// viewport, `@location(0) uv` from (0, 0) at the top left to (1, 1) at the
/// bottom right, as engines' full-screen vertex shaders have it.
pub const FULLSCREEN_WGSL: &str = "struct VistaFullscreen {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vista_fullscreen(@builtin(vertex_index) i: u32) -> VistaFullscreen {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var out: VistaFullscreen;
    out.position = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}
";

/// The vertex entry of [`FULLSCREEN_WGSL`].
pub const FULLSCREEN_ENTRY: &str = "vista_fullscreen";

/// The fragment entry of [`depth_fill_wgsl`].
pub const DEPTH_FILL_ENTRY: &str = "vista_depth_fill";

/// A pass that writes a depth texture's first values from an r32float
/// texture of them (WebGPU copies into no depth32float texture): the
/// full-screen triangle and a fragment entry returning each texel's value
/// as `frag_depth`.
pub fn depth_fill_wgsl() -> String {
    format!(
        "{FULLSCREEN_WGSL}
@group(0) @binding(0) var vista_depth_values: texture_2d<f32>;

@fragment
fn {DEPTH_FILL_ENTRY}(@builtin(position) p: vec4<f32>) -> @builtin(frag_depth) f32 {{
    return textureLoad(vista_depth_values, vec2<u32>(p.xy), 0).r;
}}
"
    )
}
