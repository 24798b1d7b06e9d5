//! Every WGSL file composes and validates with naga alone (no device), and
//! every kernel's uniform block matches the `Params` struct naga reflects.

use vista_gpu::ShaderSet;
use vista_kernels::{Kind, Value};

mod common;

fn repo_shaders() -> ShaderSet {
    vista_render::shader_set(&common::project()).unwrap()
}

/// A set over the `.wgsl` files of a directory tree (paths relative to it).
fn set_of_dir(dir: &std::path::Path) -> ShaderSet {
    // The checkout's manifests generate each kernel file's vista::enums.
    set_with_enums(dir, vista_render::enum_modules(&common::project()).expect("the checkout's manifests"))
}

fn set_with_enums(dir: &std::path::Path, enums: Vec<(String, String, String)>) -> ShaderSet {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "wgsl") {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().replace('\\', "/");
                files.push((rel, std::fs::read_to_string(&p).unwrap(), p.display().to_string()));
            }
        }
    }
    ShaderSet::from_files(&dir.display().to_string(), files).with_enums(enums)
}

#[test]
fn every_kernel_shader_composes_and_validates_without_a_device() {
    let set = repo_shaders();
    let files = set.kernel_files();
    assert!(files.len() >= 2, "expected kernel shaders, found {files:?}");
    for f in &files {
        set.compose(f).unwrap_or_else(|e| panic!("{f}: {e}"));
    }
}

/// A set reuses its naga_oil composers from one kernel to the next (library
/// modules parsed once, the generated `vista::enums` swapped per kernel):
/// every shader variant the built-in kernels and presets use composes to
/// the same module as in a set of its own, in either order. Only the spans
/// differ, which carry naga_oil's module index for error messages.
#[test]
fn a_shared_composer_composes_each_kernel_as_a_fresh_one_does() {
    let mut names = std::collections::BTreeSet::new();
    for k in vista_kernels::registry() {
        for preset in std::iter::once(None).chain(k.presets().iter().map(|p| Some(p.name.as_str()))) {
            names.insert(k.shader_for(&k.resolve(preset, &[]).unwrap()));
        }
    }
    assert!(names.len() > vista_kernels::registry().len(), "expected shader-def variants: {names:?}");
    let text = |set: &vista_gpu::ShaderSet, n: &str| without_spans(&format!("{:?}", set.compose(n).unwrap()));
    let alone: Vec<String> = names.iter().map(|n| text(&repo_shaders(), n)).collect();
    for order in [names.iter().collect::<Vec<_>>(), names.iter().rev().collect()] {
        let shared = repo_shaders();
        for n in order {
            let i = names.iter().position(|m| m == n).unwrap();
            assert_eq!(text(&shared, n), alone[i], "{n} composed differently in a shared set");
        }
    }
}

/// `text` (a module's `Debug`) with every `Span { .. }` reduced to `Span`.
fn without_spans(text: &str) -> String {
    let (mut out, mut rest) = (String::new(), text);
    while let Some(i) = rest.find("Span {") {
        out.push_str(&rest[..i]);
        out.push_str("Span");
        rest = &rest[i + rest[i..].find('}').unwrap() + 1..];
    }
    out + rest
}

#[test]
fn every_registered_kernel_has_a_shader_file() {
    let set = repo_shaders();
    let files = set.kernel_files();
    for k in vista_kernels::registry() {
        assert!(files.iter().any(|f| f == k.shader()), "{}: shader {} missing", k.name(), k.shader());
    }
}

/// Every built-in kernel's `Params` struct passes the name-and-type check
/// against its manifest, and the packed bytes hold each param's value at
/// the offset naga reflects (vec3 fields included).
#[test]
fn uniform_blocks_are_packed_by_name_at_naga_offsets() {
    let set = repo_shaders();
    for k in vista_kernels::registry() {
        let module = set.compose(k.shader()).unwrap();
        let (_, mut layouts) = k.graph_layouts(&[(k.shader(), &module)]).unwrap_or_else(|e| panic!("{e}"));
        let layout = layouts.remove(0);
        let p = k.resolve(k.presets().last().map(|p| p.name.as_str()), &[]).unwrap();
        let bytes = k.uniforms(&layout, &p, 64, 32).remove(0);
        assert_eq!(bytes.len() % 16, 0);
        assert!(bytes.len() as u32 >= layout.blocks[0].size);
        let word = |at: u32| u32::from_le_bytes(bytes[at as usize..at as usize + 4].try_into().unwrap());
        let float = |at: u32| f32::from_bits(word(at));
        for f in &layout.fields {
            let expect: Vec<u32> = match f.name.as_str() {
                "width" => vec![64],
                "height" => vec![32],
                name => match p.value(name).unwrap() {
                    Value::Float(v) => vec![(*v as f32).to_bits()],
                    Value::Int(v) => vec![*v as u32],
                    Value::Bool(b) => vec![*b as u32],
                    Value::Vector(v) => v.iter().map(|c| (*c as f32).to_bits()).collect(),
                    Value::Enum(e) => {
                        let Kind::Enum(ref names) = k.params().iter().find(|s| s.name == name).unwrap().kind else {
                            unreachable!()
                        };
                        vec![names.iter().position(|n| n == e).unwrap() as u32]
                    }
                },
            };
            let got: Vec<u32> = (0..expect.len() as u32).map(|i| word(f.offset + 4 * i)).collect();
            assert_eq!(got, expect, "{}: field {} at offset {} ({})", k.name(), f.path, f.offset, float(f.offset));
        }
        // Every param but the host's exposure reaches the shader.
        for spec in k.params() {
            assert!(
                layout.fields.iter().any(|f| f.name == spec.name) || spec.name == "exposure",
                "{}: {} not in Params",
                k.name(),
                spec.name
            );
        }
    }
}

#[test]
fn a_broken_shader_reports_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    std::fs::create_dir_all(&lib).unwrap();
    std::fs::write(lib.join("x.wgsl"), "#define_import_path vista::x\nfn one() -> f32 { return 1.0; }\n").unwrap();
    std::fs::write(
        dir.path().join("bad.wgsl"),
        "#import vista::x::one\n\n@compute @workgroup_size(1)\nfn main() {\n    let a: f32 = one() + undefined_name;\n}\n",
    )
    .unwrap();
    let set = set_of_dir(dir.path());
    let err = set.compose("bad.wgsl").unwrap_err().to_string();
    assert!(err.contains("bad.wgsl"), "error does not name the file: {err}");
    assert!(err.contains(":5:") || err.contains("5 │") || err.contains("5 |"), "error does not name line 5: {err}");
}

/// The provenance hash follows imports: editing a module fbm reaches only
/// through fractal -> noise -> hash changes fbm's hash; editing a module it
/// never imports (geometry) does not.
#[test]
fn shader_hash_covers_transitive_imports_only() {
    let tmp = tempfile::tempdir().unwrap();
    let src = common::project().root().unwrap().join("shaders");
    for sub in ["", "lib"] {
        std::fs::create_dir_all(tmp.path().join(sub)).unwrap();
        for e in std::fs::read_dir(src.join(sub)).unwrap().flatten() {
            if e.path().extension().is_some_and(|x| x == "wgsl") {
                std::fs::copy(e.path(), tmp.path().join(sub).join(e.file_name())).unwrap();
            }
        }
    }
    let hash = |name: &str| set_of_dir(tmp.path()).source_hash(name).unwrap();
    let (fbm0, atmo0) = (hash("fbm.wgsl"), hash("atmosphere.wgsl"));
    let append = |file: &str| {
        let p = tmp.path().join(file);
        let s = std::fs::read_to_string(&p).unwrap();
        std::fs::write(&p, s + "\n// edited\n").unwrap();
    };
    // The manifest's enum values are part of what the kernel composes.
    let other_enums = vista_render::enum_modules(&common::project())
        .unwrap()
        .into_iter()
        .map(|(f, k, text)| (f, k, text.replace("= 0u", "= 7u")))
        .collect::<Vec<_>>();
    assert_ne!(
        set_with_enums(tmp.path(), other_enums).source_hash("atmosphere.wgsl").unwrap(),
        atmo0,
        "atmosphere imports vista::enums"
    );
    append("lib/geometry.wgsl");
    assert_eq!(hash("fbm.wgsl"), fbm0, "fbm does not import geometry");
    assert_ne!(hash("atmosphere.wgsl"), atmo0, "atmosphere imports geometry");
    append("lib/hash.wgsl");
    assert_ne!(hash("fbm.wgsl"), fbm0, "fbm reaches hash through fractal and noise");
}

/// A bevy-like module tree: modules that import each other with grouped,
/// nested, multi-line and aliased imports (the shapes naga_oil accepts).
fn module_tree(kernel: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let write = |rel: &str, text: &str| {
        let p = dir.path().join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    };
    write(
        "sky/types.wgsl",
        "#define_import_path mylib::sky::types\n\nconst R_GROUND: f32 = 6360.0;\nstruct Atmosphere {\n    bottom: f32,\n    top: f32,\n}\n",
    );
    write("math.wgsl", "#define_import_path mylib::math\n\nconst PI: f32 = 3.14159265;\n");
    // A module whose own grouped import reaches two others.
    write(
        "sky/functions.wgsl",
        "#define_import_path mylib::sky::functions\n\n#import mylib::{sky::types::{Atmosphere, R_GROUND}, math::PI}\n\n\
         fn thickness(a: Atmosphere) -> f32 {\n    return (a.top - a.bottom) / R_GROUND * PI;\n}\n",
    );
    write(
        "sky/bindings.wgsl",
        "#define_import_path mylib::sky::bindings\n\n#import mylib::sky::types::Atmosphere\n\n\
         @group(0) @binding(0) var<uniform> atmosphere: Atmosphere;\n",
    );
    write("k.wgsl", kernel);
    dir
}

/// Which modules a file imports comes from naga_oil's parser: a grouped
/// import names every module in the group, not the prefix before `::{`.
#[test]
fn grouped_nested_multiline_and_aliased_imports_reach_every_module() {
    let body = "\n@group(0) @binding(1) var out: texture_storage_2d<rgba32float, write>;\n\n\
                @compute @workgroup_size(8, 8)\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {\n    \
                textureStore(out, id.xy, vec4<f32>(USE, 0.0, 0.0, 1.0));\n}\n";
    let cases = [
        // grouped, across two modules (bevy's atmosphere kernels)
        ("#import mylib::sky::{types::R_GROUND, bindings::atmosphere}\n", "atmosphere.top / R_GROUND"),
        // nested groups
        ("#import mylib::{sky::{types::R_GROUND, bindings::atmosphere}, math::PI}\n", "atmosphere.top / R_GROUND * PI"),
        // multi-line
        ("#import mylib::sky::{\n    bindings::atmosphere,\n    functions::thickness,\n}\n", "thickness(atmosphere)"),
        // aliased module
        ("#import mylib::sky::functions as f\n#import mylib::sky::bindings::atmosphere\n", "f::thickness(atmosphere)"),
    ];
    for (imports, use_) in cases {
        let dir = module_tree(&format!("{imports}{}", body.replace("USE", use_)));
        let set = set_of_dir(dir.path());
        set.compose("k.wgsl").unwrap_or_else(|e| panic!("{imports}: {e}"));
        let closure = set.import_closure("k.wgsl").unwrap();
        for module in ["sky/types.wgsl", "sky/bindings.wgsl"] {
            assert!(closure.iter().any(|f| f == module), "{imports}: closure {closure:?} lacks {module}");
        }
        // Every module reached, directly or through another, is in the hash.
        let before = set.source_hash("k.wgsl").unwrap();
        let types = dir.path().join("sky/types.wgsl");
        let text = std::fs::read_to_string(&types).unwrap();
        std::fs::write(&types, text + "// edited\n").unwrap();
        assert_ne!(
            set_of_dir(dir.path()).source_hash("k.wgsl").unwrap(),
            before,
            "{imports}: types edit not in the hash"
        );
        // math is reached only by the nested and multi-line/aliased cases.
        let reaches_math = use_.contains("PI") || use_.contains("thickness");
        assert_eq!(closure.iter().any(|f| f == "math.wgsl"), reaches_math, "{imports}: {closure:?}");
    }
}

/// A module that no file declares is named with the file and line whose
/// `#import` names it, in a kernel and in a module.
#[test]
fn a_missing_module_names_the_importing_file_and_line() {
    let kernel = "// a kernel\n\n#import mylib::sky::{\n    types::R_GROUND,\n    missing::thing,\n}\n\n\
                  @compute @workgroup_size(1)\nfn main() {\n    let a = thing(R_GROUND);\n}\n";
    let dir = module_tree(kernel);
    let err = set_of_dir(dir.path()).compose("k.wgsl").unwrap_err().to_string();
    assert!(err.contains("k.wgsl:3:") && err.contains("mylib::sky::missing"), "{err}");
    // In a module: bindings imports a module that does not exist.
    let dir = module_tree(
        "#import mylib::sky::bindings::atmosphere\n@compute @workgroup_size(1)\nfn main() { let a = atmosphere.top; }\n",
    );
    std::fs::write(
        dir.path().join("sky/bindings.wgsl"),
        "#define_import_path mylib::sky::bindings\n\n#import mylib::sky::{types::Atmosphere, gone::G}\n\n\
         @group(0) @binding(0) var<uniform> atmosphere: Atmosphere;\nconst X: f32 = G;\n",
    )
    .unwrap();
    let err = set_of_dir(dir.path()).source_hash("k.wgsl").unwrap_err().to_string();
    assert!(err.contains("bindings.wgsl:3:") && err.contains("mylib::sky::gone"), "{err}");
}

/// Dual-source blending through naga_oil (an `#ifdef` makes the file go
/// through composition): `@blend_src` composes, and the `enable` directive
/// naga_oil drops is still declared, under the def that selects it.
#[test]
fn dual_source_blending_composes_and_its_enable_is_declared() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("sky.wgsl"),
        "#ifdef DUAL_SOURCE_BLENDING\nenable dual_source_blending;\n#endif\n\nstruct Out {\n#ifdef DUAL_SOURCE_BLENDING\n    \
         @location(0) @blend_src(0) colour: vec4<f32>,\n    @location(0) @blend_src(1) weight: vec4<f32>,\n#else\n    \
         @location(0) colour: vec4<f32>,\n#endif\n}\n\n@fragment\nfn shade() -> Out {\n    var o: Out;\n    \
         o.colour = vec4<f32>(0.5);\n#ifdef DUAL_SOURCE_BLENDING\n    o.weight = vec4<f32>(0.25);\n#endif\n    return o;\n}\n",
    )
    .unwrap();
    let set = set_of_dir(dir.path());
    set.compose("sky.wgsl?DUAL_SOURCE_BLENDING").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        set.declared_features("sky.wgsl?DUAL_SOURCE_BLENDING").unwrap(),
        [("dual-source-blending", "dual_source_blending")]
    );
    set.compose("sky.wgsl").unwrap_or_else(|e| panic!("{e}"));
    assert!(set.declared_features("sky.wgsl").unwrap().is_empty());
    // Unconditional, the directive counts though nothing uses the feature.
    std::fs::write(
        dir.path().join("plain.wgsl"),
        "enable f16;\n#ifdef NEVER\n#endif\n@compute @workgroup_size(1)\nfn main() {}\n",
    )
    .unwrap();
    let set = set_of_dir(dir.path());
    assert_eq!(set.declared_features("plain.wgsl").unwrap(), [("shader-f16", "f16")]);
}

/// A 5000-term constant overflowed naga's stack (exit 134): it is refused
/// before parsing, naming the file and line, in a kernel and in a module
/// it imports.
#[test]
fn expressions_past_the_parsers_depth_are_refused_not_a_stack_overflow() {
    let dir = tempfile::tempdir().unwrap();
    let long = format!("const TAU: f32 = 6.28{};\n", " + 0.0".repeat(5000));
    std::fs::write(dir.path().join("k.wgsl"), format!("{long}@compute @workgroup_size(1)\nfn main() {{}}\n")).unwrap();
    std::fs::create_dir_all(dir.path().join("lib")).unwrap();
    std::fs::write(dir.path().join("lib/deep.wgsl"), format!("#define_import_path my::deep\n{long}")).unwrap();
    std::fs::write(
        dir.path().join("uses.wgsl"),
        "#import my::deep::TAU\n@compute @workgroup_size(1)\nfn main() { let t = TAU; }\n",
    )
    .unwrap();
    let set = set_of_dir(dir.path());
    let e = set.compose("k.wgsl").unwrap_err().to_string();
    assert!(e.contains("k.wgsl:1: one statement chains more than 1024 operators"), "{e}");
    let e = set.compose("uses.wgsl").unwrap_err().to_string();
    assert!(e.contains("deep.wgsl") && e.contains("more than 1024 operators"), "{e}");
}

/// The conformance suite's expected values and input files are what
/// `tests/conformance/expected.py` derives from the specs (no device
/// needed, so it runs here, beside the other shader checks).
#[test]
fn conformance_expectations_are_what_expected_py_writes() {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/conformance/expected.py");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg("--check")
        .output()
        .unwrap_or_else(|e| panic!("python3 runs the spec-derived table's script: {e}"));
    assert!(out.status.success(), "{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
}
