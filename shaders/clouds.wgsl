// clouds kernel (SPEC 3.6): a cloud layer between cloud_base and cloud_top
// (km, y up; a flat slab or a shell around the planet), ray marched with a light march toward the sun at each sample.
// rgb = L_cloud + T * background (linear radiance), alpha = 1 - T.
// The f64 reference, written from the same formulas, is crates/vista-kernels/src/cpu/clouds.rs.
#import vista::cloud_slab::{CloudParams, CloudSlab, cloud_march, cloud_slab, jitter_offset, layer_segment}
#import vista::geometry::{direction, pinhole_looking, pinhole_ray}

// Packed by name from kernels/clouds.toml (exposure is the host's tone map).
// Everything derived from them (camera basis, sun direction and colour here;
// noise frequency, fBm normaliser, light-step layout in lib/cloud_slab.wgsl)
// is computed in WGSL.
struct Params {
    width: u32,
    height: u32,
    // The layer's params, by name (kernels/clouds.toml's [[group]]); its
    // coverage is replaced by coverage() below when coverage_oktas >= 0.
    cloud: CloudParams,
    jitter: u32,
    jitter_seed: u32,
    coverage_oktas: i32,
    okta_coverage_low: vec4<f32>,
    okta_coverage_high: vec4<f32>,
    yaw_deg: f32,
    pitch_deg: f32,
    camera_pos: vec3<f32>,
    fov_deg: f32,
    sun_color: vec3<f32>,
    sun_azimuth_deg: f32,
    sky_zenith: vec3<f32>,
    sun_elevation_deg: f32,
    sky_horizon: vec3<f32>,
    sun_intensity: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var output: texture_storage_2d<rgba32float, write>;

// `coverage`, or with coverage_oktas = n >= 0 the preset's calibrated
// coverage for n oktas (a table lookup; the CPU reads the same table).
fn coverage() -> f32 {
    let n = params.coverage_oktas;
    if n < 0 {
        return params.cloud.coverage;
    }
    if n == 0 {
        return 0.0;
    }
    if n <= 4 {
        return params.okta_coverage_low[n - 1];
    }
    return params.okta_coverage_high[n - 5];
}

fn slab() -> CloudSlab {
    var c = params.cloud;
    c.coverage = coverage();
    return cloud_slab(c, params.camera_pos);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let slab = slab();
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size;
    // pitch is within +-89 deg (manifest range), so forward is never vertical.
    let forward = direction(radians(params.yaw_deg), radians(params.pitch_deg));
    let d = pinhole_ray(pinhole_looking(params.camera_pos, forward, params.fov_deg, size.x / size.y), uv);
    let o = params.camera_pos;

    let zenith = params.sky_zenith;
    let horizon = params.sky_horizon;
    let background = horizon + (zenith - horizon) * clamp(d.y, 0.0, 1.0);

    // Segment of the ray inside the layer and within max_distance.
    let seg = layer_segment(slab, o, d);
    var cloud = vec4(0.0, 0.0, 0.0, 1.0);
    if seg.y > seg.x {
        let s = direction(radians(params.sun_azimuth_deg), radians(params.sun_elevation_deg));
        let xi = jitter_offset(params.jitter, params.jitter_seed, id.xy);
        cloud = cloud_march(slab, o, d, seg.x, seg.y, xi, s, params.sun_color * params.sun_intensity);
    }
    textureStore(output, id.xy, vec4(cloud.rgb + cloud.a * background, 1.0 - cloud.a));
}
