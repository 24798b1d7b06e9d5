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
