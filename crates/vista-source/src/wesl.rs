//! `.wesl` shaders, compiled by the `wesl` crate (pinned: 0.5 and later
//! need a newer Rust): `import package::...` resolves under `shaders/`,
//! another package's imports through `[source] packages`, `wgsl_test`
//! (the assertions of a `*.test.wesl` file) to vista's own module, and
//! bool defs are `@if` features. An imported module's declarations are
//! named as naga_oil names them ([`Decorated`]), so that a manifest binds an
//! imported global by its own name in either language.

use std::borrow::Cow;
use std::cell::RefCell;
use std::collections::HashMap;

use wesl::{Mangler, ModulePath, ResolveError, Resolver, syntax::PathOrigin};

use crate::{Assembled, Part, SourceSpec};

/// Resolves module paths to files through the caller's reader, and keeps
/// every file it read (the parts the shader hash covers).
struct Files<'a> {
    packages: &'a [(String, String)],
    read: &'a dyn Fn(&str) -> Option<(String, String)>,
    parts: RefCell<Vec<Part>>,
    /// Each module path (as the mangler spells it) with its file and the
    /// text handed to the compiler: what its spans point into.
    given: RefCell<HashMap<String, (String, String)>>,
}

/// The file vista's assertion module is read from (a built-in, unless the
/// project has its own), and the package name a test file imports it by.
const WGSL_TEST: (&str, &str) = ("shaders/lib/wgsl_test.wgsl", "wgsl_test");

impl Files<'_> {
    /// The folder a module path's first component is taken in.
    fn base(&self, path: &ModulePath) -> Result<String, String> {
        match &path.origin {
            PathOrigin::Absolute => Ok("shaders".into()),
            PathOrigin::Package(name) => {
                self.packages.iter().find(|(p, _)| p == name).map(|(_, dir)| dir.clone()).ok_or_else(|| {
                    let known: Vec<&str> = self.packages.iter().map(|(p, _)| p.as_str()).collect();
                    format!(
                        "package {name} is not in [source] packages ({}); add {name} = \"shaders/{name}\"",
                        if known.is_empty() { "none".into() } else { known.join(", ") }
                    )
                })
            }
            PathOrigin::Relative(_) => Err(format!("relative module path {path} reached the resolver")),
        }
    }

    /// The files a module path may be, in the order tried: `a/b.wesl`, then
    /// `a/b.wgsl`; a package's own root module (`constants::GROUP`) is
    /// package.wesl or mod.wesl in its folder, or the folder's name with .wesl.
    fn candidates(&self, path: &ModulePath) -> Result<Vec<String>, String> {
        let base = self.base(path)?;
        Ok(match path.components.is_empty() {
            true => vec![format!("{base}/package.wesl"), format!("{base}/mod.wesl"), format!("{base}.wesl")],
            false => {
                let stem = format!("{base}/{}", path.components.join("/"));
                vec![format!("{stem}.wesl"), format!("{stem}.wgsl")]
            }
        })
    }

    /// The file of the naga_oil module a package path may name where no
    /// `[source] packages` entry declares that package: vista's
    /// `wgsl_test` (the assertions of a `*.test.wesl` file), else a module
    /// the manifest's `[source] modules` generates (`import
    /// constants::GROUP` reads shaders/generated/constants.wgsl).
    fn naga_oil_module(&self, path: &ModulePath) -> Option<String> {
        let PathOrigin::Package(p) = &path.origin else { return None };
        if self.packages.iter().any(|(n, _)| n == p) {
            return None;
        }
        if p == WGSL_TEST.1 && path.components.is_empty() {
            return Some(WGSL_TEST.0.to_string());
        }
        let parts: Vec<&str> = std::iter::once(p.as_str()).chain(path.components.iter().map(String::as_str)).collect();
        Some(format!("shaders/generated/{}.wgsl", parts.join("/")))
    }

    /// Keeps the text handed to the compiler for module `path`.
    fn give(&self, path: &ModulePath, file: &str, text: String) -> String {
        self.given.borrow_mut().insert(path.to_string(), (file.to_string(), text.clone()));
        text
    }

    /// Keeps a file read as a part of the shader (its hash covers them).
    fn record(&self, file: &str, origin: String, text: &str) {
        let mut parts = self.parts.borrow_mut();
        if !parts.iter().any(|p| p.path == file) {
            parts.push(Part { path: file.to_string(), origin, text: text.to_string() });
        }
    }
}

impl Resolver for Files<'_> {
    fn resolve_source<'a>(&'a self, path: &ModulePath) -> Result<Cow<'a, str>, ResolveError> {
        if let Some(file) = self.naga_oil_module(path)
            && let Some((text, origin)) = (self.read)(&file)
        {
            self.record(&file, origin, &text);
            return Ok(Cow::Owned(self.give(path, &file, as_wesl(&text))));
        }
        let candidates = self.candidates(path).map_err(|e| ResolveError::ModuleNotFound(path.clone(), e))?;
        for file in &candidates {
            if let Some((text, origin)) = (self.read)(file) {
                self.record(file, origin, &text);
                return Ok(Cow::Owned(self.give(path, file, without_visibility(&text))));
            }
        }
        Err(ResolveError::ModuleNotFound(path.clone(), format!("tried {}", candidates.join(", "))))
    }

    fn display_name(&self, path: &ModulePath) -> Option<String> {
        let mut files = self.candidates(path).unwrap_or_default();
        files.extend(self.naga_oil_module(path));
        let parts = self.parts.borrow();
        parts.iter().find(|p| files.contains(&p.path)).map(|p| p.origin.clone())
    }
}

/// A naga_oil module (vista's own, a generated one) as WESL: its
/// `#define_import_path` line blanked, the lines kept.
fn as_wesl(text: &str) -> String {
    let lines: Vec<&str> = text.lines().map(|l| if l.starts_with("#define_import_path") { "" } else { l }).collect();
    lines.join("\n")
}

/// Compiles `.wesl` shader `main` (a root-relative path under `shaders/`)
/// with `features` (`@if` flags) and `spec.packages`, to WGSL. The result's
/// lines are not traced to files (its errors are the wesl crate's, which
/// name them); its parts are every module file read.
pub fn compile_wesl(
    main: &str,
    spec: &SourceSpec,
    features: &[(String, bool)],
    read: &dyn Fn(&str) -> Option<(String, String)>,
) -> Result<Assembled, String> {
    let Some(module) = main.strip_prefix("shaders/").and_then(|m| m.strip_suffix(".wesl")) else {
        return Err(format!("{main}: a .wesl shader lies under shaders/"));
    };
    let root = ModulePath { origin: PathOrigin::Absolute, components: module.split('/').map(str::to_string).collect() };
    // Every module file is checked for depth before the wesl crate parses
    // it (its parser recurses on expressions too); the first refusal wins.
    let refused = RefCell::new(None);
    let checked = |path: &str| {
        let mut found = read(path)?;
        if let Err(e) = crate::check_depth(&found.0, &found.1) {
            refused.borrow_mut().get_or_insert(e);
            return None;
        }
        // Module-scope `@if(X) { ... }` blocks, which this wesl crate cannot read.
        if path.ends_with(".wesl") {
            match crate::wesl_blocks::flatten_blocks(&found.0, &found.1) {
                Ok(text) => found.0 = text,
                Err(e) => {
                    refused.borrow_mut().get_or_insert(e);
                    return None;
                }
            }
        }
        Some(found)
    };
    let files =
        Files { packages: &spec.packages, read: &checked, parts: RefCell::new(Vec::new()), given: Default::default() };
    let mut compiler = wesl::Wesl::new("shaders").set_custom_resolver(files);
    compiler.set_custom_mangler(Decorated);
    for (name, on) in features {
        compiler.set_feature(name, *on);
    }
    let result = compiler.compile(&root);
    if let Some(e) = refused.take() {
        return Err(e);
    }
    let result = result.map_err(|e| located(&plain(&e.to_string())))?;
    let text = result.to_string();
    let parts = compiler.resolver().parts.take();
    let given = compiler.resolver().given.take();
    // A declaration's module: the one its decorated name spells, else the root.
    let module_of = |name: &str| {
        let path = crate::decoration::undecorate(name).1.unwrap_or_else(|| root.to_string());
        let (file, text) = given.get(&path)?;
        Some((parts.iter().position(|p| p.path == *file)?, text.as_str()))
    };
    let lines = crate::wesl_lines::trace(&result.syntax, &text, module_of).unwrap_or_default();
    Ok(Assembled::compiled(text, parts, lines))
}

/// Names an imported module's declaration as naga_oil does ([`crate::decoration`]),
/// `<item>X_naga_oil_mod_X<base32 of the module path>X`, where the wesl
/// crate's own mangler writes `package__1lut_bindings_t`: a manifest then
/// binds it by `t` (and knows its module), as it does a naga_oil import's.
/// Unique per (module, item), and a WGSL identifier.
struct Decorated;

impl Mangler for Decorated {
    fn mangle(&self, path: &ModulePath, item: &str) -> String {
        crate::decoration::decorate(item, &path.to_string())
    }
}

/// The wesl crate's diagnostic with its place first: its headline says
/// "error: chars 229..230: unexpected token" and the file, line and column
/// only on the `-->` line below, so the headline becomes
/// "WESL error: FILE:LINE:COL: unexpected token", the snippet kept below.
fn located(diagnostic: &str) -> String {
    let (head, rest) = diagnostic.split_once('\n').unwrap_or((diagnostic, ""));
    let mut reason = head.trim().trim_start_matches("error:").trim();
    // "chars 229..230: " is a byte range in the file; the place replaces it.
    if let Some(after) = reason.strip_prefix("chars ") {
        let range = after.chars().take_while(|c| c.is_ascii_digit() || *c == '.').count();
        if let Some(r) = after[range..].strip_prefix(": ") {
            reason = r;
        }
    }
    match rest.lines().find_map(|l| l.trim_start().strip_prefix("--> ")) {
        Some(place) => format!("WESL error: {}: {reason}\n{rest}", place.trim()),
        None => format!("WESL error: {reason}\n{rest}"),
    }
}

/// `text` without terminal colour codes (the wesl crate's diagnostics carry
/// them whatever the output is).
fn plain(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c == '\u{1b}' {
            // ESC [ ... final byte in @..~
            for d in chars.by_ref() {
                if ('@'..='~').contains(&d) && d != '[' {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// `text` with the `public` visibility keyword dropped before declarations
/// (`public fn`, `@binding(0) public var`): newer WESL marks what a module
/// exports with it, and this version of the wesl crate does not read it.
/// `public` is a reserved word in WGSL, so it names nothing else; every
/// declaration stays visible, which is what this version assumes anyway.
fn without_visibility(text: &str) -> String {
    const DECLARATIONS: [&str; 6] = ["fn", "var", "struct", "const", "alias", "override"];
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("public") {
        let before_ok = rest[..at].chars().next_back().is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
        let after = &rest[at + "public".len()..];
        let next = after.trim_start();
        let word: String = next.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
        let spaced = after.starts_with(char::is_whitespace);
        out.push_str(&rest[..at]);
        if before_ok && spaced && DECLARATIONS.contains(&word.as_str()) {
            // Keep the columns: the keyword becomes spaces.
            out.push_str("      ");
        } else {
            out.push_str("public");
        }
        rest = after;
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decoration::base32;

    #[test]
    fn public_is_dropped_only_before_declarations() {
        let src = "@group(0) @binding(1) public var t: f32;\npublic fn f() {}\nfn publicity() { let public_x = 1; }\n";
        assert_eq!(
            without_visibility(src),
            "@group(0) @binding(1)        var t: f32;\n       fn f() {}\nfn publicity() { let public_x = 1; }\n"
        );
    }

    /// Module-scope `@if(X) { ... } @else { ... }` blocks (newer WESL, which
    /// this crate's parser refuses) choose their declarations by feature,
    /// in the root module and an imported one.
    #[test]
    fn module_scope_if_blocks_choose_declarations() {
        let files: Vec<(&str, &str)> = vec![
            (
                "shaders/k.wesl",
                "import package::bits::BITS;\n@if(R16) {\n  fn tag() -> u32 { return 1u; }\n} @else {\n  fn tag() -> u32 { return 2u; }\n}\n@compute @workgroup_size(1) fn main() { let x = BITS + tag(); }\n",
            ),
            ("shaders/bits.wesl", "@if(R16) {\n  const BITS: u32 = 16u;\n}\n@else {\n  const BITS: u32 = 32u;\n}\n"),
        ];
        let read = |p: &str| files.iter().find(|(f, _)| *f == p).map(|(_, t)| (t.to_string(), format!("/p/{p}")));
        let spec = SourceSpec::default();
        let on = compile_wesl("shaders/k.wesl", &spec, &[("R16".into(), true)], &read).unwrap().text;
        assert!(on.contains("16u") && on.contains("1u") && !on.contains("32u") && !on.contains("2u"), "{on}");
        let off = compile_wesl("shaders/k.wesl", &spec, &[("R16".into(), false)], &read).unwrap().text;
        assert!(off.contains("32u") && off.contains("2u") && !off.contains("16u"), "{off}");
        let broken = |p: &str| match p {
            "shaders/k.wesl" => Some(("@else {\n fn f() {}\n}\n".to_string(), "/p/shaders/k.wesl".to_string())),
            _ => None,
        };
        let e = compile_wesl("shaders/k.wesl", &spec, &[], &broken).unwrap_err();
        assert_eq!(e, "/p/shaders/k.wesl:1: @else block without an @if block before it");
    }

    /// Each statement of the compiled text is traced to its own module's
    /// file and line (worked by hand below); braces and `else {` are not.
    #[test]
    fn compiled_lines_are_traced_to_their_modules_lines() {
        let files: Vec<(&str, &str)> = vec![
            (
                "shaders/k.wesl",
                "import package::m::scale;\n\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\n\
                 @compute @workgroup_size(1)\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {\n    \
                 var v = scale(f32(id.x));\n    if v > 2.0 {\n        v = 2.0;\n    } else if v < 0.5 {\n        \
                 v = 0.5;\n    }\n    out[id.x] = v;\n}\n",
            ),
            (
                "shaders/m.wesl",
                "// helper\nfn scale(x: f32) -> f32 {\n    var s = 0.0;\n    for (var i = 0u; i < 3u; i++) {\n        \
                 s += x;\n    }\n    return s;\n}\n",
            ),
        ];
        let read = |p: &str| files.iter().find(|(f, _)| *f == p).map(|(_, t)| (t.to_string(), format!("/p/{p}")));
        let a = compile_wesl("shaders/k.wesl", &SourceSpec::default(), &[], &read).unwrap();
        assert!(a.traced() && a.is_compiled());
        let expected = [
            ("@compute", "shaders/k.wesl", 5),
            ("fn main(", "shaders/k.wesl", 6),
            ("var v = ", "shaders/k.wesl", 7),
            ("if v > 2.0", "shaders/k.wesl", 8),
            ("v = 2.0;", "shaders/k.wesl", 9),
            ("else if v < 0.5", "shaders/k.wesl", 10),
            ("v = 0.5;", "shaders/k.wesl", 11),
            ("out[id.x] = v;", "shaders/k.wesl", 13),
            ("fn scaleX_naga_oil_mod_X", "shaders/m.wesl", 2),
            ("var s = 0.0;", "shaders/m.wesl", 3),
            ("for (", "shaders/m.wesl", 4),
            ("s += x;", "shaders/m.wesl", 5),
            ("return s;", "shaders/m.wesl", 7),
        ];
        let lines: Vec<&str> = a.text.lines().collect();
        for (start, file, line) in expected {
            let at = lines
                .iter()
                .position(|l| l.trim_start().starts_with(start))
                .unwrap_or_else(|| panic!("{start}: {}", a.text));
            assert_eq!(a.locate_path(at + 1), Some((file, line)), "{start}");
        }
        for (i, l) in lines.iter().enumerate() {
            if l.trim() == "}" || l.trim() == "else {" {
                assert_eq!(a.locate_path(i + 1), None, "{l}");
            }
        }
        // Errors keep naming the compiler's lines.
        assert_eq!(a.locate(1), None);
    }

    /// A package's root module, a module of this package, features, and
    /// the reached files as parts.
    #[test]
    fn packages_features_and_parts() {
        let files: Vec<(&str, &str)> = vec![
            (
                "shaders/k.wesl",
                "import package::m::half;\nimport consts::SCALE;\n@compute @workgroup_size(1) fn main() { let x = half() * SCALE; }\n",
            ),
            (
                "shaders/m.wesl",
                "@if(BIG) public fn half() -> f32 { return 5.0; }\n@if(!BIG) public fn half() -> f32 { return 0.5; }\n",
            ),
            ("vendor/consts/package.wesl", "public const SCALE: f32 = 2.0;\n"),
        ];
        let read = |p: &str| files.iter().find(|(f, _)| *f == p).map(|(_, t)| (t.to_string(), format!("/p/{p}")));
        let spec = SourceSpec { packages: vec![("consts".into(), "vendor/consts".into())], ..Default::default() };
        let small = compile_wesl("shaders/k.wesl", &spec, &[("BIG".into(), false)], &read).unwrap();
        assert!(small.text.contains("0.5") && !small.text.contains("5.0"), "{}", small.text);
        let big = compile_wesl("shaders/k.wesl", &spec, &[("BIG".into(), true)], &read).unwrap();
        assert!(big.text.contains("5.0"), "{}", big.text);
        let mut paths: Vec<&str> = big.parts.iter().map(|p| p.path.as_str()).collect();
        paths.sort();
        assert_eq!(paths, ["shaders/k.wesl", "shaders/m.wesl", "vendor/consts/package.wesl"]);
        let e = compile_wesl("shaders/k.wesl", &SourceSpec::default(), &[], &read).unwrap_err();
        assert!(e.contains("package consts is not in [source] packages (none)"), "{e}");
    }

    /// An imported global is named as naga_oil names one (its module's
    /// path in base32), so a manifest binds it by its own name; `wgsl_test`
    /// is vista's assertion module, its import path line blanked.
    #[test]
    fn imported_names_are_decorated_as_naga_oil_does_and_wgsl_test_is_vistas() {
        assert_eq!(base32(b"mylib::camera"), "NV4WY2LCHI5GGYLNMVZGC");
        assert_eq!(base32(b"f"), "MY");
        let files: Vec<(&str, &str)> = vec![
            (
                "shaders/k.wesl",
                "import package::lut::table;\nimport wgsl_test::expect;\n\
                 @compute @workgroup_size(1) fn main() { expect(table[0] > 0.0); }\n",
            ),
            ("shaders/lut.wesl", "@group(0) @binding(1) var<storage> table: array<f32, 4>;\n"),
            ("shaders/lib/wgsl_test.wgsl", "#define_import_path wgsl_test\nfn expect(c: bool) {}\n"),
        ];
        let read = |p: &str| files.iter().find(|(f, _)| *f == p).map(|(_, t)| (t.to_string(), format!("/p/{p}")));
        let out = compile_wesl("shaders/k.wesl", &SourceSpec::default(), &[], &read).unwrap().text;
        let table = format!("tableX_naga_oil_mod_X{}X", base32(b"package::lut"));
        assert!(out.contains(&format!("var<storage> {table}")), "{out}");
        assert!(out.contains(&format!("fn expectX_naga_oil_mod_X{}X", base32(b"wgsl_test"))), "{out}");
        assert!(!out.contains("#define_import_path"), "{out}");
    }

    /// `import constants::GROUP` reads the module `[source] modules`
    /// generates (shaders/generated/constants.wgsl), as bevy's WESL imports
    /// its generated constants; a declared package of that name wins.
    #[test]
    fn generated_modules_are_packages_of_their_own() {
        let files: Vec<(&str, &str)> = vec![
            (
                "shaders/k.wesl",
                "import constants::{GROUP, SCALE};\n@compute @workgroup_size(1) fn main() { let x = f32(GROUP) * SCALE; }\n",
            ),
            (
                "shaders/generated/constants.wgsl",
                "#define_import_path constants\nconst GROUP: u32 = 2u;\nconst SCALE: f32 = 0.5;\n",
            ),
        ];
        let read = |p: &str| files.iter().find(|(f, _)| *f == p).map(|(_, t)| (t.to_string(), format!("/p/{p}")));
        let out = compile_wesl("shaders/k.wesl", &SourceSpec::default(), &[], &read).unwrap();
        assert!(out.text.contains("2u") && out.text.contains("0.5"), "{}", out.text);
        assert!(out.parts.iter().any(|p| p.path == "shaders/generated/constants.wgsl"));
        let gone = |p: &str| (p != "shaders/generated/constants.wgsl").then(|| read(p)).flatten();
        let e = compile_wesl("shaders/k.wesl", &SourceSpec::default(), &[], &gone).unwrap_err();
        assert!(e.contains("package constants is not in [source] packages"), "{e}");
    }

    /// A syntax error in an imported module: the headline names its file,
    /// line and column (the wesl crate's says "chars 41..42").
    #[test]
    fn syntax_errors_name_the_file_line_and_column_first() {
        let files: Vec<(&str, &str)> = vec![
            ("shaders/k.wesl", "import package::m::half;\n@compute @workgroup_size(1) fn main() { let x = half(); }\n"),
            ("shaders/m.wesl", "// half\npublic fn half() -> f32 {\n    return 0.5; )\n}\n"),
        ];
        let read = |p: &str| files.iter().find(|(f, _)| *f == p).map(|(_, t)| (t.to_string(), format!("/p/{p}")));
        let e = compile_wesl("shaders/k.wesl", &SourceSpec::default(), &[], &read).unwrap_err();
        let head = e.lines().next().unwrap();
        assert!(head.starts_with("WESL error: /p/shaders/m.wesl:3:17: unexpected token `)`"), "{e}");
        assert!(!head.contains("chars "), "{head}");
    }
}
