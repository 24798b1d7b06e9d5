//! What the browser backend hands Tint (`Context::wgsl_for_tint`): the
//! project's own text wherever naga parses it directly, and naga's rewrite
//! only for a module naga_oil composes, whose names and literals must then
//! round-trip. No GPU: this is the text, before any page sees it.

use proptest::prelude::*;
use vista_gpu::{Context, Reader, ShaderSet};

const PLAIN: &str = "// a user's comment, kept\n\
override GAIN: f32 = 1.0;\n\
@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\
@compute @workgroup_size(8, 8)\n\
fn fill_f32(@builtin(global_invocation_id) id: vec3<u32>) {\n\
    var far = 3.402823466e+38;\n\
    out[id.x] = min(far, GAIN);\n\
}\n";

fn set(files: &[(&str, &str)]) -> ShaderSet {
    ShaderSet::from_files(
        "test",
        files.iter().map(|(rel, text)| (rel.to_string(), text.to_string(), format!("/p/shaders/{rel}"))),
    )
}

#[test]
fn a_plain_file_reaches_tint_as_written_with_its_overrides_as_pipeline_constants() {
    let shaders = set(&[("k.wgsl", PLAIN)]);
    let constants = vec![("GAIN".to_string(), 2.0)];
    let t = Context::wgsl_for_tint(&shaders, "k.wgsl", "fill_f32", &constants).unwrap();
    assert_eq!(t.wgsl, PLAIN, "byte for byte, comments and literal spelling included");
    assert_eq!(t.entry("fill_f32"), "fill_f32", "the entry keeps its name");
    assert_eq!(t.constants, constants, "the override goes to WebGPU, not into the text");
    assert_eq!(t.place(6, 15), "/p/shaders/k.wgsl:6:15", "Tint's line is the file's");
}

#[test]
fn an_assembled_source_reaches_tint_as_assembled_and_its_lines_name_their_files() {
    let main = "#include \"common.wgsl\"\n@compute @workgroup_size(1)\nfn main() { out[0] = half(1.0); }\n";
    let common =
        "@group(0) @binding(0) var<storage, read_write> out: array<f32>;\nfn half(x: f32) -> f32 { return x * 0.5; }\n";
    let spec = vista_source::SourceSpec { include: Some(Vec::new()), ..Default::default() };
    let shaders =
        set(&[("k.wgsl", main), ("common.wgsl", common)]).with_sources([("a".to_string(), spec)], Reader::default());
    let t = Context::wgsl_for_tint(&shaders, "k.wgsl|a", "main", &[]).unwrap();
    assert!(t.source.is_some(), "an assembly is the project's text");
    assert_eq!(t.wgsl, format!("{common}{}", &main[main.find('\n').unwrap() + 1..]), "the assembly, not a rewrite");
    assert_eq!(t.place(2, 4), "/p/shaders/common.wgsl:2:4", "line 2 came from the include");
    assert_eq!(t.place(4, 1), "/p/shaders/k.wgsl:3:1", "line 4 is the shader's third");
}

/// naga's WGSL of a module, to compare two modules.
fn written(module: &naga::Module) -> String {
    let info = vista_gpu::validate("m", module).unwrap();
    naga::back::wgsl::write_string(module, &info, naga::back::wgsl::WriterFlags::empty()).unwrap()
}

#[test]
fn wgpu_engines_get_naga_s_module_of_the_same_text_tint_gets() {
    let shaders = set(&[("k.wgsl", PLAIN)]);
    let t = Context::wgsl_for_tint(&shaders, "k.wgsl", "fill_f32", &[]).unwrap();
    let parsed = naga::front::wgsl::parse_str(&t.wgsl).unwrap();
    assert_eq!(written(&shaders.compose("k.wgsl").unwrap()), written(&parsed), "the module wgpu is handed");
}

#[test]
fn a_naga_oil_module_is_rewritten_with_entry_names_mapped_and_f32_max_exact() {
    let text = PLAIN.replace("// a user's comment, kept\n", "#ifdef NEVER_SET\n#endif\n");
    let shaders = set(&[("k.wgsl", &text)]);
    let t = Context::wgsl_for_tint(&shaders, "k.wgsl", "fill_f32", &[("GAIN".to_string(), 2.0)]).unwrap();
    assert!(t.source.is_none(), "naga_oil's composition leaves only the IR");
    assert!(t.constants.is_empty(), "a rewrite has its overrides resolved: {:?}", t.constants);
    let entry = t.entry("fill_f32");
    assert!(t.wgsl.contains(&format!("fn {entry}(")), "the mapped entry is in the text:\n{}", t.wgsl);
    assert!(t.wgsl.contains("0x1.fffffep+127f"), "f32::MAX written exactly:\n{}", t.wgsl);
    assert!(t.place(1, 1).contains("naga's rewrite"), "{}", t.place(1, 1));
}

/// Every decimal f32 literal of `text` (digits, a `.` or an exponent,
/// then `f`: how naga's writer spells them), as the value its digits spell.
fn decimal_literals(text: &str) -> Vec<(String, f64)> {
    let mut found = Vec::new();
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let starts =
            bytes[i].is_ascii_digit() && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_'));
        if starts && text[i..].starts_with("0x") {
            // A hex float is exact; skip it whole.
            i += 2 + text[i + 2..].find(|c: char| !(c.is_ascii_hexdigit() || ".pP+-".contains(c))).unwrap_or(0);
            continue;
        }
        if !starts {
            i += 1;
            continue;
        }
        let end = i + text[i..].find(|c: char| !(c.is_ascii_digit() || "._eE+-".contains(c))).unwrap_or(text.len() - i);
        let token = text[i..end].trim_end_matches(['+', '-']);
        if text[i + token.len()..].starts_with('f') {
            found.push((token.to_string(), token.parse::<f64>().unwrap()));
        }
        i = end.max(i + 1);
    }
    found
}

/// An identifier that is no WGSL keyword or reserved word (naga refuses
/// those in the source, so they are filtered by parsing).
fn identifier() -> impl Strategy<Value = String> {
    "[a-z]([a-z0-9]|_[a-z0-9]){0,6}[0-9]?"
}

/// A finite f32 and a way the source spells it.
fn literal() -> impl Strategy<Value = (f32, String)> {
    let value = prop_oneof![
        // WGSL lets an implementation ignore the sign of a zero (`-0e0`
        // composes to +0.0 here), so -0.0 is no value a source can rely
        // on; subnormals may be flushed likewise.
        any::<f32>().prop_filter("finite, normal or +0", |v| v.is_finite() && (v.is_normal() || v.to_bits() == 0)),
        Just(f32::MAX),
        Just(f32::MIN_POSITIVE),
        Just(-f32::MAX),
    ];
    (value, 0..3u8).prop_map(|(v, spelling)| {
        let digits = match spelling {
            0 => format!("{:e}", v.abs()),
            1 => format!("{:.9e}f", v.abs()),
            _ => format!("{}", v.abs()),
        };
        let digits = if digits.contains(['.', 'e']) { digits } else { format!("{digits}.0") };
        (v, if v.is_sign_negative() { format!("-{digits}") } else { digits })
    })
}

proptest! {
    // A failure prints its minimal input; nothing is kept on disk.
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    /// naga_oil's path: every f32 literal the source wrote within range
    /// comes back from the rewrite as the same f32, and within Tint's range
    /// (no decimal above f32::MAX); every entry point is found by the name
    /// the rewrite gives it, with its stage and workgroup size.
    #[test]
    fn the_rewrite_keeps_literals_and_entry_points(
        literals in prop::collection::vec(literal(), 1..6),
        entries in prop::collection::btree_set(identifier(), 1..4),
    ) {
        let mut text = String::from("#ifdef NEVER_SET\n#endif\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n");
        for (i, (_, spelled)) in literals.iter().enumerate() {
            text.push_str(&format!("const value_{i}: f32 = {spelled};\n"));
        }
        let stores: String = (0..literals.len()).map(|i| format!("    out[{i}] = value_{i};\n")).collect();
        for (k, name) in entries.iter().enumerate() {
            text.push_str(&format!("@compute @workgroup_size({}, 1, 1)\nfn {name}() {{\n{stores}}}\n", k + 1));
        }
        let wgsl: String = text.lines().filter(|l| !l.starts_with('#')).map(|l| format!("{l}\n")).collect();
        prop_assume!(naga::front::wgsl::parse_str(&wgsl).is_ok(), "a reserved word");
        let shaders = set(&[("k.wgsl", &text)]);
        let first = entries.iter().next().unwrap();
        let t = Context::wgsl_for_tint(&shaders, "k.wgsl", first, &[]).unwrap();
        let back = naga::front::wgsl::parse_str(&t.wgsl).map_err(|e| TestCaseError::fail(format!("{e}\n{}", t.wgsl)))?;
        for (token, value) in decimal_literals(&t.wgsl) {
            prop_assert!(value.abs() <= f32::MAX as f64, "{token} is out of f32's range for Tint:\n{}", t.wgsl);
        }
        // The namer may rename a constant (`value_1` ends in a digit); each
        // keeps its value, in declaration order.
        let in_order: Vec<u32> = back.constants.iter().filter_map(|(_, c)| match back.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::F32(v)) => Some(v.to_bits()),
            _ => None,
        }).collect();
        prop_assert_eq!(in_order, literals.iter().map(|(v, _)| v.to_bits()).collect::<Vec<_>>(), "{}", t.wgsl);
        for (k, name) in entries.iter().enumerate() {
            let written_name = t.entry(name);
            let ep = back.entry_points.iter().find(|e| e.name == written_name);
            prop_assert!(ep.is_some(), "entry {} written as {} is missing:\n{}", name, written_name, t.wgsl);
            let ep = ep.unwrap();
            prop_assert_eq!(ep.stage, naga::ShaderStage::Compute);
            prop_assert_eq!(ep.workgroup_size, [k as u32 + 1, 1, 1]);
        }
    }
}

#[test]
fn the_literal_scanner_finds_what_the_property_test_checks() {
    let found = decimal_literals(
        "const a: f32 = 340282350000000000000000000000000000000f; let b = 1.5e-3f + x1.0 + 2f; c[0.5f] = 0x1.fffffep+127f;",
    );
    let tokens: Vec<&str> = found.iter().map(|(t, _)| t.as_str()).collect();
    assert_eq!(tokens, ["340282350000000000000000000000000000000", "1.5e-3", "2", "0.5"]);
}
