// A sky cube map the way an engine bakes one for image-based lighting: six
// square faces in the layers of an rgba16float 2d-array texture, bound in
// group 1 beside the sky's uniform; workgroups of 8 x 8 x 1, and the third
// dispatch coordinate is the face.
//
// Face f and texel centre (u, v) in [-1, 1]^2 give the view direction as
// cube maps define it (+x, -x, +y, -y, +z, -z; v grows downward). Above the
// horizon the radiance is single scattering in an optically thin slab seen
// along an air mass m = 1 / (cos(zenith) + 0.05):
//   L = E (b_r P_r(mu) + b_m P_m(mu)) / (b_r + b_m) (1 - exp(-(b_r + b_m) m))
// with P_r(mu) = 3 / (16 pi) (1 + mu^2), P_m the Henyey-Greenstein phase
// with asymmetry g, and mu the cosine to the sun; the sun's disc (cos >=
// sun_cos) adds E exp(-(b_r + b_m) m). Below the horizon: the ground's
// albedo lit by the sun's elevation plus a tenth of E as sky light.
struct SkyUniforms {
    sun_direction: vec3<f32>,
    sun_illuminance: f32,
    rayleigh: vec3<f32>,
    mie: f32,
    mie_asymmetry: f32,
    sun_cos: f32,
    _pad0: vec2<f32>,
    ground_albedo: vec3<f32>,
    _pad1: f32,
}

@group(1) @binding(0) var<uniform> sky: SkyUniforms;
@group(1) @binding(1) var sky_faces: texture_storage_2d_array<rgba16float, write>;

const PI: f32 = 3.14159265;

fn face_direction(face: u32, uv: vec2<f32>) -> vec3<f32> {
    let u = uv.x;
    let v = uv.y;
    switch face {
        case 0u: { return vec3(1.0, -v, -u); }
        case 1u: { return vec3(-1.0, -v, u); }
        case 2u: { return vec3(u, 1.0, v); }
        case 3u: { return vec3(u, -1.0, -v); }
        case 4u: { return vec3(u, -v, 1.0); }
        default: { return vec3(-u, -v, -1.0); }
    }
}

fn henyey_greenstein(mu: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * mu;
    return (1.0 - g * g) / (4.0 * PI * denom * sqrt(denom));
}

@compute @workgroup_size(8, 8, 1)
fn bake_faces(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(sky_faces);
    if id.x >= size.x || id.y >= size.y || id.z >= 6u {
        return;
    }
    let uv = 2.0 * (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size) - 1.0;
    let dir = normalize(face_direction(id.z, uv));
    let sun = normalize(sky.sun_direction);
    var radiance: vec3<f32>;
    if dir.y >= 0.0 {
        let mu = dot(dir, sun);
        let air_mass = 1.0 / (dir.y + 0.05);
        let extinction = sky.rayleigh + vec3(sky.mie);
        let phase = sky.rayleigh * (3.0 / (16.0 * PI)) * (1.0 + mu * mu)
            + vec3(sky.mie * henyey_greenstein(mu, sky.mie_asymmetry));
        radiance = sky.sun_illuminance * phase / extinction * (1.0 - exp(-extinction * air_mass));
        if mu >= sky.sun_cos {
            radiance += sky.sun_illuminance * exp(-extinction * air_mass);
        }
    } else {
        radiance = sky.ground_albedo * sky.sun_illuminance * (max(sun.y, 0.0) / PI + 0.1);
    }
    textureStore(sky_faces, id.xy, id.z, vec4(radiance, 1.0));
}
