// One constant source colour drawn over targets cleared to one constant
// destination colour, each target with its own blend state: what lands in
// the rgba16float targets is WebGPU's blend equation (expected.py). Every
// value is a multiple of 1/64, so each product and sum is exact in f16.

struct Targets {
    @location(0) t0: vec4<f32>,
    @location(1) t1: vec4<f32>,
    @location(2) t2: vec4<f32>,
    @location(3) t3: vec4<f32>,
}

const SRC = vec4<f32>(0.75, 0.5, 0.25, 0.625);

@fragment
fn shade_four() -> Targets {
    return Targets(SRC, SRC, SRC, SRC);
}
