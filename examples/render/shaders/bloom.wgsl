// A post chain as engines run it: a compute pass makes an HDR frame, a
// bright pass and two box down-samples halve it three times, three tent
// up-samples add each level onto the next larger one (additive blend), and
// a tonemap combines frame and glow into 8-bit colour.

struct Params {
    width: u32,
    height: u32,
    threshold: f32,
    intensity: f32,
    exposure: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var smp: sampler;
@group(0) @binding(3) var scene: texture_2d<f32>;
@group(0) @binding(4) var glow_tex: texture_2d<f32>;
@group(1) @binding(0) var hdr_out: texture_storage_2d<rgba16float, write>;

// A dim sky gradient with three small suns far above 1.
@compute @workgroup_size(8, 8)
fn source(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let p = (vec2<f32>(id.xy) + 0.5) / size.y;
    var c = vec3(0.05, 0.07, 0.12) * (1.2 - p.y);
    let suns = array(vec3(0.3, 0.3, 0.04), vec3(1.1, 0.55, 0.025), vec3(1.6, 0.2, 0.06));
    let colours = array(vec3(40.0, 30.0, 18.0), vec3(10.0, 25.0, 40.0), vec3(30.0, 12.0, 6.0));
    for (var i = 0; i < 3; i++) {
        let d = distance(p, suns[i].xy) / suns[i].z;
        c += colours[i] * exp(-d * d);
    }
    textureStore(hdr_out, id.xy, vec4(c, 1.0));
}

// Four bilinear taps one source texel off the centre: a 4x4 box.
fn box4(uv: vec2<f32>) -> vec3<f32> {
    let t = 1.0 / vec2<f32>(textureDimensions(src));
    let a = textureSample(src, smp, uv + vec2(-t.x, -t.y)).rgb;
    let b = textureSample(src, smp, uv + vec2(t.x, -t.y)).rgb;
    let c = textureSample(src, smp, uv + vec2(-t.x, t.y)).rgb;
    let d = textureSample(src, smp, uv + vec2(t.x, t.y)).rgb;
    return 0.25 * (a + b + c + d);
}

@fragment
fn bright_down(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    return vec4(max(box4(uv) - vec3(params.threshold), vec3(0.0)), 1.0);
}

@fragment
fn down(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    return vec4(box4(uv), 1.0);
}

// A tent over half a source texel each way, added onto the target.
@fragment
fn up(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let t = 0.5 / vec2<f32>(textureDimensions(src));
    let a = textureSample(src, smp, uv + vec2(-t.x, -t.y)).rgb;
    let b = textureSample(src, smp, uv + vec2(t.x, -t.y)).rgb;
    let c = textureSample(src, smp, uv + vec2(-t.x, t.y)).rgb;
    let d = textureSample(src, smp, uv + vec2(t.x, t.y)).rgb;
    return vec4(0.25 * (a + b + c + d), 0.0);
}

@fragment
fn tonemap(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let c = textureSample(scene, smp, uv).rgb + params.intensity * textureSample(glow_tex, smp, uv).rgb;
    return vec4(1.0 - exp(-params.exposure * c), 1.0);
}
