// Every colour-renderable format vista has, written by a fragment shader
// (full-screen, 1 x 1 targets) and read back: what lands is the attachment
// format's conversion (unorm: clamp to [0, 1], scale by 2^n - 1, round to
// nearest; float16 and the packed unsigned floats: round to nearest;
// 32-bit floats and integers as written). expected.py reads each constant
// below (named after its target's format) and converts it by hand; every
// normalized value scales to within 0.25 of an integer, and every rounded
// float's nearest neighbour is also the one toward zero, so the spec's
// rounding latitude leaves one answer. Targets are grouped so that each
// pass stays within 32 bytes of colour attachments per sample.

const R8UNORM = vec4<f32>(0.75, 0.0, 0.0, 0.0);
const RG8UNORM = vec4<f32>(0.2, 0.125, 0.0, 0.0);
const RGBA8UNORM = vec4<f32>(0.25, 1.5, -0.25, 0.6);
const BGRA8UNORM = vec4<f32>(0.25, 0.6, 0.75, 0.2);
const RGB10A2UNORM = vec4<f32>(0.25, 0.6, 1.0, 0.4);
const R16FLOAT = vec4<f32>(0.1, 0.0, 0.0, 0.0);

const RG16FLOAT = vec4<f32>(-2.5, 1000.1, 0.0, 0.0);
const RGBA16FLOAT = vec4<f32>(0.33333334, -0.33333334, 65504.0, 0.00000095367431640625);
const R32FLOAT = vec4<f32>(0.1, 0.0, 0.0, 0.0);
const RG32FLOAT = vec4<f32>(-12345.678, 1e30, 0.0, 0.0);

const RGBA32FLOAT = vec4<f32>(1.17549435e-38, -3.4028234663852886e38, 0.3, 16777216.0);
const RGBA8UINT = vec4<u32>(0u, 255u, 7u, 128u);
const RGBA8SINT = vec4<i32>(-128, 127, -1, 5);
const RGBA16UINT = vec4<u32>(0u, 65535u, 1234u, 40000u);

const RGBA32UINT = vec4<u32>(1u, 4294967040u, 2147483648u, 16777216u);
const RGBA16SINT = vec4<i32>(-32768, 32767, -300, 1);
const R32UINT = vec4<u32>(4000000000u, 0u, 0u, 0u);
const R32SINT = vec4<i32>(-2147483648, 0, 0, 0);

const RGBA32SINT = vec4<i32>(-16777216, 2147483520, -2147483648, 7);
const RG32UINT = vec4<u32>(4294967040u, 2147483904u, 0u, 0u);
const RG32SINT = vec4<i32>(2147483520, -7, 0, 0);

const RG11B10UFLOAT = vec4<f32>(0.1, 60000.0, 0.3, 0.0);

struct Normalized {
    @location(0) r8unorm: vec4<f32>,
    @location(1) rg8unorm: vec4<f32>,
    @location(2) rgba8unorm: vec4<f32>,
    @location(3) bgra8unorm: vec4<f32>,
    @location(4) rgb10a2unorm: vec4<f32>,
    @location(5) r16float: vec4<f32>,
}

@fragment
fn normalized() -> Normalized {
    return Normalized(R8UNORM, RG8UNORM, RGBA8UNORM, BGRA8UNORM, RGB10A2UNORM, R16FLOAT);
}

struct Floats {
    @location(0) rg16float: vec4<f32>,
    @location(1) rgba16float: vec4<f32>,
    @location(2) r32float: vec4<f32>,
    @location(3) rg32float: vec4<f32>,
}

@fragment
fn floats() -> Floats {
    return Floats(RG16FLOAT, RGBA16FLOAT, R32FLOAT, RG32FLOAT);
}

struct Mixed {
    @location(0) rgba32float: vec4<f32>,
    @location(1) rgba8uint: vec4<u32>,
    @location(2) rgba8sint: vec4<i32>,
    @location(3) rgba16uint: vec4<u32>,
}

@fragment
fn mixed() -> Mixed {
    return Mixed(RGBA32FLOAT, RGBA8UINT, RGBA8SINT, RGBA16UINT);
}

struct Wide {
    @location(0) rgba32uint: vec4<u32>,
    @location(1) rgba16sint: vec4<i32>,
    @location(2) r32uint: vec4<u32>,
    @location(3) r32sint: vec4<i32>,
}

@fragment
fn wide() -> Wide {
    return Wide(RGBA32UINT, RGBA16SINT, R32UINT, R32SINT);
}

struct Signed {
    @location(0) rgba32sint: vec4<i32>,
    @location(1) rg32uint: vec4<u32>,
    @location(2) rg32sint: vec4<i32>,
}

@fragment
fn signed() -> Signed {
    return Signed(RGBA32SINT, RG32UINT, RG32SINT);
}

@fragment
fn packed() -> @location(0) vec4<f32> {
    return RG11B10UFLOAT;
}
