// Appended by the host: the sky behind the mask and its tone curves (the
// host picks one by writing its name into the kernel).
fn sky(v: f32) -> vec3<f32> {
    return mix(vec3(0.25, 0.45, 0.8), vec3(0.55, 0.7, 0.95), v);
}

fn tone_reinhard(c: vec3<f32>) -> vec3<f32> {
    return c / (1.0 + c);
}

fn tone_exponential(c: vec3<f32>) -> vec3<f32> {
    return 1.0 - exp(-c);
}
