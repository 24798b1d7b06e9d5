// Appended by the host: the sky behind the mask and its tone curve.
fn sky(v: f32) -> vec3<f32> {
    return mix(vec3(0.25, 0.45, 0.8), vec3(0.55, 0.7, 0.95), v);
}

fn tone(c: vec3<f32>) -> vec3<f32> {
    return c / (1.0 + c);
}
