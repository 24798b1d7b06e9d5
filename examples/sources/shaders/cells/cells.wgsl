// Value noise over a grid of cells, from files a project's loader splices
// in: the four #include spellings such loaders accept.
#include "common.wgsl"
#include <utility/frame>
#include rng.inc.wgsl
#include "noise/value.wgsl"
#include <noise/hash>

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_frame(id.xy) {
        return;
    }
    let v = value_noise(pixel_uv(id.xy) * frame.cells, frame.seed);
    textureStore(noise_out, id.xy, vec4(v, v * v, 1.0 - v, 1.0));
}
