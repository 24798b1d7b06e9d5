// The planet and its air, shared by every sky pass: one module for the
// types, one for the bindings, one for the functions, as engines split them.
#define_import_path atmos::types

// naga_oil refuses `_`-prefixed names in modules, so the vec3 goes first
// and the scalars fill in behind it instead of padding fields.
struct Atmosphere {
    rayleigh_scattering: vec3<f32>,  // per km, at sea level
    bottom_radius: f32,              // km
    top_radius: f32,                 // km
    rayleigh_scale_height: f32,      // km
}

struct LutSettings {
    width: u32,
    height: u32,
}
