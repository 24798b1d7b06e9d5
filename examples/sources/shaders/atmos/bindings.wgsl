#define_import_path atmos::bindings

#import atmos::types::{Atmosphere, LutSettings}

@group(0) @binding(0) var<uniform> atmosphere: Atmosphere;
@group(0) @binding(1) var<uniform> settings: LutSettings;
