struct Frame {
    width: u32,
    height: u32,
    cells: f32,
    seed: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var noise_out: texture_storage_2d<rgba8unorm, write>;
