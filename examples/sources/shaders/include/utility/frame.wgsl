fn in_frame(id: vec2<u32>) -> bool {
    return id.x < frame.width && id.y < frame.height;
}

fn pixel_uv(id: vec2<u32>) -> vec2<f32> {
    return (vec2<f32>(id) + 0.5) / vec2(f32(frame.width), f32(frame.height));
}
