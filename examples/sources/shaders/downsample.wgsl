// One level of a mip chain, 2x2 texels to one. An engine composes this file
// once per pipeline: FIRST_PASS for the level read from the source, where a
// Karis average (each tap weighted by 1 / (1 + luma)) keeps one hot texel
// from flooding the level, and plainly for the levels after it. The host
// writes the storage format in for ##TEXTURE_FORMAT##.
@group(0) @binding(0) var mip_in: texture_2d<f32>;
@group(0) @binding(1) var mip_out: texture_storage_2d<##TEXTURE_FORMAT##, write>;

fn luma(c: vec3<f32>) -> f32 {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

@compute @workgroup_size(8, 8, 1)
fn downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(mip_out)) {
        return;
    }
    let base = vec2<i32>(id.xy) * 2;
    var sum = vec3(0.0);
    var weight = 0.0;
    for (var k = 0; k < 4; k++) {
        let c = textureLoad(mip_in, base + vec2(k & 1, k >> 1), 0).rgb;
#ifdef FIRST_PASS
        let w = 1.0 / (1.0 + luma(c));
#else
        let w = 1.0;
#endif
        sum += c * w;
        weight += w;
    }
    textureStore(mip_out, id.xy, vec4(sum / weight, 1.0));
}
