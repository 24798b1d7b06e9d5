// A shaded height map from a sum of rotated sine ridges, laid out the way
// engine code lays out its uniforms: a model matrix, an integer tile count,
// an explicit padding field, twenty fields in all, in bind group 1; the
// map in group 0 at binding 3, read_write, as an erosion or stamping pass
// binds it: the shading is added onto what the map holds (zeros before the
// first pass); entry point `height`, 16 x 4 workgroups.
//
// h(p) = sum_i a g^i sin(f l^i (d_i . p) + 1.7 i + 0.37 s), d_i the unit
// vector at i times the golden angle; normalised to [0, 1] by the sum of
// the amplitudes; p = (model * (uv * tiles, 0, 1)).xy, warped by
// w (sin 1.3 y, cos 1.7 x). Bands: water, sand, rock, snow; Lambert shading
// with an ambient floor.
struct TerrainUniforms {
    width: u32,
    height: u32,
    model: mat4x4<f32>,
    tiles: vec2<u32>,
    _padding: vec2<u32>,
    amplitude: f32,
    frequency: f32,
    octaves: u32,
    gain: f32,
    lacunarity: f32,
    warp: f32,
    sea_level: f32,
    snow_line: f32,
    water: vec3<f32>,
    sand: vec3<f32>,
    rock: vec3<f32>,
    snow: vec3<f32>,
    light: vec3<f32>,
    ambient: f32,
    seed: u32,
}

@group(1) @binding(0) var<uniform> terrain: TerrainUniforms;
@group(0) @binding(3) var height_map: texture_storage_2d<rgba32float, read_write>;

const GOLDEN_ANGLE: f32 = 2.39996323;

fn field(uv: vec2<f32>) -> f32 {
    var p = (terrain.model * vec4(uv * vec2<f32>(terrain.tiles), 0.0, 1.0)).xy;
    p += terrain.warp * vec2(sin(1.3 * p.y), cos(1.7 * p.x));
    var sum = 0.0;
    var norm = 0.0;
    var amp = terrain.amplitude;
    var freq = terrain.frequency;
    for (var i = 0u; i < terrain.octaves; i++) {
        let angle = f32(i) * GOLDEN_ANGLE;
        let d = vec2(cos(angle), sin(angle));
        sum += amp * sin(freq * dot(d, p) + 1.7 * f32(i) + 0.37 * f32(terrain.seed));
        norm += amp;
        amp *= terrain.gain;
        freq *= terrain.lacunarity;
    }
    return 0.5 + 0.5 * sum / max(norm, 1e-6);
}

@compute @workgroup_size(16, 4)
fn height(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= terrain.width || id.y >= terrain.height {
        return;
    }
    let size = vec2(f32(terrain.width), f32(terrain.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size;
    let e = 1.0 / size;
    let h = field(uv);
    let dx = field(uv + vec2(e.x, 0.0)) - field(uv - vec2(e.x, 0.0));
    let dy = field(uv + vec2(0.0, e.y)) - field(uv - vec2(0.0, e.y));
    let n = normalize(vec3(-dx * 40.0, 1.0, -dy * 40.0));
    let to_light = terrain.light / max(length(terrain.light), 1e-6);
    let lambert = clamp(dot(n, to_light), 0.0, 1.0);
    var albedo = terrain.rock;
    if h < terrain.sea_level {
        albedo = terrain.water;
    } else if h < terrain.sea_level + 0.05 {
        albedo = terrain.sand;
    } else if h > terrain.snow_line {
        albedo = terrain.snow;
    }
    let lit = albedo * (terrain.ambient + (1.0 - terrain.ambient) * lambert);
    let below = textureLoad(height_map, id.xy);
    textureStore(height_map, id.xy, vec4(below.rgb + lit, 1.0));
}
