//! A test file as vista runs it: its `@test` functions found, each
//! assertion call rewritten to carry its place (a site), and a compute
//! entry appended per test. Lines keep their numbers, so a compile error
//! names the user's line.

/// An assertion of `wgsl_test`, as a test file spells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Assertion {
    /// `expect(cond)`.
    Expect,
    /// `expectEq(a, b)`: i32.
    Eq,
    /// `expectEqU(a, b)`: u32.
    EqU,
    /// `expectNear(a, b[, tol])` over 1 to 4 float components.
    Near(u8),
    /// `expectUlp(a, b, n)`.
    Ulp,
}

impl Assertion {
    /// Every assertion by its name.
    const ALL: [(&'static str, Assertion); 8] = [
        ("expect", Assertion::Expect),
        ("expectEq", Assertion::Eq),
        ("expectEqU", Assertion::EqU),
        ("expectNear", Assertion::Near(1)),
        ("expectNearV2f", Assertion::Near(2)),
        ("expectNearV3f", Assertion::Near(3)),
        ("expectNearV4f", Assertion::Near(4)),
        ("expectUlp", Assertion::Ulp),
    ];

    /// The name a test file calls it by.
    pub fn name(self) -> &'static str {
        Assertion::ALL.iter().find(|(_, a)| *a == self).map(|(n, _)| *n).expect("every assertion is named")
    }

    fn of(name: &str) -> Option<Assertion> {
        Assertion::ALL.iter().find(|(n, _)| *n == name).map(|(_, a)| *a)
    }
}

/// One assertion call: where the user wrote it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Site {
    /// Which assertion.
    pub assertion: Assertion,
    /// 1-based line and column of its name.
    pub line: usize,
    /// 1-based column.
    pub col: usize,
}

/// One `@test` function.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TestFn {
    /// The function's name.
    pub name: String,
    /// 1-based line of its `fn`.
    pub line: usize,
}

/// A test file rewritten for the GPU.
#[derive(Debug, Clone)]
pub struct Rewritten {
    /// The text vista composes: same lines, calls carrying sites, entries appended.
    pub text: String,
    /// The file's tests, in file order; test i's entry is [`entry`]`(i)`.
    pub tests: Vec<TestFn>,
    /// Every assertion call; site id i is `sites[i - 1]` (0: none).
    pub sites: Vec<Site>,
    /// The `@buffer` storage variables: each test gets its own, zeroed.
    pub buffers: Vec<TestBuffer>,
    /// The `@test_texture` textures, filled once before the tests run.
    pub textures: Vec<TestTexture>,
    /// The `@sampler` samplers.
    pub samplers: Vec<TestSampler>,
    /// The `@fragment @snapshot` tests, in file order.
    pub snapshots: Vec<Snapshot>,
}

/// A `@fragment @snapshot` (or `@snapshot(W, H)`) function: a full-screen
/// pass drawn into a W x H rgba8unorm image judged against its golden.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Snapshot {
    /// The fragment entry's name.
    pub name: String,
    /// Width and height (default 64 x 64).
    pub size: (u32, u32),
}

/// What fills a `@test_texture`, in wgsl-test's words.
#[derive(Debug, Clone, PartialEq)]
pub enum Pattern {
    /// `checkerboard, W, H, CELL`: 1 on cells whose column + row is even, else 0.
    Checkerboard(u32),
    /// `gradient, W, H`: red (x + 0.5) / W, green (y + 0.5) / H.
    Gradient,
    /// `noise, W, H, SEED`: each channel a hash of (x, y, seed) in [0, 1).
    Noise(u32),
    /// `file, "path"`: a `.png` or `.exr` under the project root.
    File(String),
}

/// A `@test_texture(...) var name: texture_2d<f32>;` of a test file.
#[derive(Debug, Clone, PartialEq)]
pub struct TestTexture {
    /// The variable's name.
    pub name: String,
    /// What fills it.
    pub pattern: Pattern,
    /// Width and height in texels (a file's own when `None`).
    pub size: Option<(u32, u32)>,
}

/// A `@sampler(linear | nearest) var name: sampler;` of a test file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TestSampler {
    /// The variable's name.
    pub name: String,
    /// `linear` (else `nearest`) filtering.
    pub linear: bool,
}

/// The storage format generated test textures are filled in: storable and
/// filterable in WebGPU's core, so a test samples it with either filter.
pub const TEXTURE_FORMAT: &str = "rgba16float";

/// An attribute's parenthesised arguments from just after its name
/// (`@name(a, b, "c")`), trimmed, and the byte after its `)`; `None` when
/// no `(` follows the name.
fn parens(text: &str, after_name: usize) -> Result<Option<(Vec<String>, usize)>, String> {
    let rest = &text[after_name..];
    let Some(open) = rest.find('(').filter(|&o| rest[..o].trim().is_empty()) else { return Ok(None) };
    let close = rest[open..].find(')').map(|c| open + c).ok_or("its ( is not closed")?;
    let args = rest[open + 1..close].split(',').map(|a| a.trim().to_string()).filter(|a| !a.is_empty()).collect();
    Ok(Some((args, after_name + close + 1)))
}

/// The attribute's arguments, the byte after its `)`, and the declared
/// variable's name and type.
fn attribute_args(text: &str, after_name: usize) -> Result<(Vec<String>, usize, String, String), String> {
    let (args, close) = parens(text, after_name)?.ok_or("needs its arguments in ( )")?;
    let decl = text[close..].split(';').next().unwrap_or_default();
    let decl = decl.trim_start().strip_prefix("var").ok_or("is not followed by a var declaration")?;
    let (name, ty) = decl.split_once(':').ok_or("its variable has no type")?;
    Ok((args, close, name.trim().to_string(), ty.trim().to_string()))
}

/// The first function declared at or after byte `from`: where its `fn`
/// is and its name.
fn function_after(text: &str, from: usize) -> Option<(usize, String)> {
    let at = from + text[from..].find("fn ")?;
    let name = text[at + 3..].trim_start().bytes().take_while(|&c| is_ident(c)).map(char::from).collect();
    Some((at, name))
}

/// A `@test_texture(...)` declaration from just after the attribute's
/// name, and the byte after the attribute.
fn texture_decl(text: &str, after_name: usize) -> Result<(TestTexture, usize), String> {
    let (args, close, name, ty) = attribute_args(text, after_name)?;
    if ty.replace(' ', "") != "texture_2d<f32>" {
        return Err(format!("@test_texture {name}: a test texture is a texture_2d<f32>, not {ty}"));
    }
    let number = |i: usize, what: &str| -> Result<u32, String> {
        let a = args.get(i).ok_or_else(|| format!("@test_texture {name}: {} needs {what}", args[0]))?;
        a.trim_end_matches('u').parse().map_err(|_| format!("@test_texture {name}: {what} {a} is not a whole number"))
    };
    let kinds = "checkerboard, gradient, noise or file";
    let Some(kind) = args.first() else { return Err(format!("@test_texture {name}: name its kind: {kinds}")) };
    let (pattern, want) = match kind.as_str() {
        "checkerboard" => (Pattern::Checkerboard(number(3, "a cell size (checkerboard, W, H, CELL)")?), 4),
        "gradient" => (Pattern::Gradient, 3),
        "noise" => (Pattern::Noise(number(3, "a seed (noise, W, H, SEED)")?), 4),
        "file" => match args.get(1).and_then(|a| a.strip_prefix('"')).and_then(|a| a.strip_suffix('"')) {
            Some(path) if args.len() == 2 => (Pattern::File(path.to_string()), 2),
            _ => return Err(format!("@test_texture {name}: file takes one quoted path: file, \"inputs/rock.png\"")),
        },
        other => return Err(format!("@test_texture {name}: unknown kind {other}; kinds: {kinds}")),
    };
    if args.len() != want {
        return Err(format!("@test_texture {name}: {kind} takes {} arguments, not {}", want - 1, args.len() - 1));
    }
    let size = match pattern {
        Pattern::File(_) => None,
        _ => {
            let (w, h) = (number(1, "a width")?, number(2, "a height")?);
            if w == 0 || h == 0 || w > 4096 || h > 4096 {
                return Err(format!("@test_texture {name}: {w}x{h} is not a size from 1x1 to 4096x4096"));
            }
            Some((w, h))
        }
    };
    Ok((TestTexture { name, pattern, size }, close))
}

/// A `@sampler(...)` declaration from just after the attribute's name,
/// and the byte after the attribute.
fn sampler_decl(text: &str, after_name: usize) -> Result<(TestSampler, usize), String> {
    let (args, close, name, ty) = attribute_args(text, after_name)?;
    if ty != "sampler" {
        return Err(format!("@sampler {name}: declares a sampler, not {ty}"));
    }
    let linear = match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
        ["linear"] => true,
        ["nearest"] => false,
        _ => return Err(format!("@sampler {name}: takes linear or nearest, not ({})", args.join(", "))),
    };
    Ok((TestSampler { name, linear }, close))
}

/// `@snapshot` or `@snapshot(W, H)` from just after the name: the size
/// and the byte after the attribute.
fn snapshot_size(text: &str, after_name: usize) -> Result<((u32, u32), usize), String> {
    let found = parens(text, after_name).map_err(|_| "@snapshot's ( is not closed".to_string())?;
    let Some((args, close)) = found else { return Ok(((64, 64), after_name)) };
    let size = match &args[..] {
        [w, h] => (w.trim_end_matches('u').parse::<u32>(), h.trim_end_matches('u').parse::<u32>()),
        _ => return Err(format!("@snapshot takes a width and a height, not ({})", args.join(", "))),
    };
    match size {
        (Ok(w), Ok(h)) if (1..=4096).contains(&w) && (1..=4096).contains(&h) => Ok(((w, h), close)),
        _ => Err(format!("@snapshot({}) is not a size from 1x1 to 4096x4096", args.join(", "))),
    }
}

/// The fill entry and storage binding vista appends for test texture `i`.
pub fn fill_entry(i: usize) -> (String, String) {
    (format!("vista_fill_{i}"), format!("vista_fill_tex_{i}"))
}

/// The WGSL that fills generated texture `i` (bound at `binding` as a
/// storage texture): its global and its entry, one invocation per texel.
fn fill_code(i: usize, t: &TestTexture, binding: usize) -> String {
    let (entry, var) = fill_entry(i);
    let value = match t.pattern {
        Pattern::Checkerboard(cell) => format!(
            "let c = (p / max({cell}u, 1u)); let v = f32(((c.x + c.y) & 1u) == 0u); let rgba = vec4f(v, v, v, 1.0);"
        ),
        Pattern::Gradient => "let rgba = vec4f((vec2f(p) + 0.5) / vec2f(size), 0.0, 1.0);".into(),
        Pattern::Noise(seed) => format!(
            "var h = vec4u(p.x, p.y, {seed}u, 0x9e3779b9u) * 1664525u + 1013904223u; \
             h = h ^ (h >> vec4u(16u)); h = h * 0x45d9f3bu; h = h ^ (h >> vec4u(16u)); \
             h.x += h.y * h.w; h.y += h.z * h.x; h.z += h.x * h.y; h.w += h.y * h.z; \
             let rgba = vec4f(h >> vec4u(8u)) / 16777216.0;"
        ),
        Pattern::File(_) => return String::new(),
    };
    format!(
        "@group({BUFFER_GROUP}) @binding({binding}) var {var}: texture_storage_2d<{TEXTURE_FORMAT}, write>;\n\
         @compute @workgroup_size(8, 8) fn {entry}(@builtin(global_invocation_id) id: vec3u) {{ \
         let size = textureDimensions({var}); let p = id.xy; if any(p >= size) {{ return; }} \
         {value} textureStore({var}, p, rgba); }}\n"
    )
}

/// A `@buffer var<storage, read_write> name: T;` of a test file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TestBuffer {
    /// The variable's name.
    pub name: String,
    /// Elements: N of `array<E, N>`, else 1.
    pub length: u64,
}

/// The group vista binds a test file's `@buffer`s at, one binding each.
pub const BUFFER_GROUP: u32 = 2;

/// A `@buffer` declaration from just after the attribute: the variable's
/// name and length, or what is wrong with it.
fn buffer_decl(decl: &str) -> Result<TestBuffer, String> {
    let decl = decl.split(';').next().unwrap_or_default();
    let rest = decl.trim_start().strip_prefix("var<").ok_or("@buffer declares a var<storage, ...>")?;
    let (space, rest) = rest.split_once('>').ok_or("@buffer's var<...> is not closed")?;
    if !space.trim_start().starts_with("storage") {
        return Err(format!("@buffer declares a storage buffer, not var<{space}>"));
    }
    let (name, ty) = rest.split_once(':').ok_or("@buffer's variable has no type")?;
    let (name, ty) = (name.trim(), ty.trim());
    let length = match ty.strip_prefix("array<").and_then(|a| a.strip_suffix('>')) {
        None => 1,
        Some(inner) => match inner.rsplit_once(',').map(|(_, n)| n.trim().trim_end_matches(['u', 'i'])) {
            Some(n) => n.parse().map_err(|_| format!("@buffer {name}: array length {n} is not a number"))?,
            None => return Err(format!("@buffer {name}: {ty} has no size; give it one (array<T, N>)")),
        },
    };
    Ok(TestBuffer { name: name.to_string(), length })
}

/// A test file's name without its folders and `.test.wgsl` / `.test.wesl`:
/// what its test ids and snapshot goldens are named by.
pub(crate) fn stem(rel: &str) -> &str {
    let file = rel.rsplit('/').next().unwrap_or(rel);
    file.strip_suffix(".test.wgsl").or_else(|| file.strip_suffix(".test.wesl")).unwrap_or(file)
}

/// The compute entry vista appends for test `i`.
pub fn entry(i: usize) -> String {
    format!("vista_test_{i}")
}

/// Byte ranges of `text` that are comments (`//` to the line's end,
/// `/* */` nested as WGSL nests them).
fn comments(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let (mut out, mut i) = (Vec::new(), 0);
    while i + 1 < b.len() {
        if b[i] == b'/' && b[i + 1] == b'/' {
            let end = text[i..].find('\n').map_or(b.len(), |e| i + e);
            out.push((i, end));
            i = end;
        } else if b[i] == b'/' && b[i + 1] == b'*' {
            let (start, mut depth) = (i, 0usize);
            while i + 1 < b.len() {
                if b[i] == b'/' && b[i + 1] == b'*' {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && b[i + 1] == b'/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// 1-based line and column of byte `at`.
fn place(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = at - before.rfind('\n').map_or(0, |n| n + 1) + 1;
    (line, col)
}

/// The byte after the `)` that closes the `(` at `open`, and the count of
/// top-level arguments between them.
fn call_end(text: &str, open: usize) -> Option<(usize, usize)> {
    let (mut depth, mut args, mut any) = (0usize, 1usize, false);
    for (i, c) in text[open..].char_indices() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => {
                depth -= 1;
                if depth == 0 {
                    return Some((open + i + 1, if any { args } else { 0 }));
                }
            }
            ',' if depth == 1 => args += 1,
            c if !c.is_whitespace() && depth >= 1 => any = true,
            _ => {}
        }
    }
    None
}

/// Rewrites `text` (a `*.test.wgsl` file, or `*.test.wesl` when `wesl`):
/// `@test` attributes blanked, assertion calls `name(args)` made
/// `wgsl_test::name_at(site, args[, tol])`, `#import wgsl_test` (WGSL; in
/// WESL the qualified names reach the package) and one compute entry per
/// test appended. Errors name the place and what is wrong.
pub fn rewrite(text: &str, wesl: bool) -> Result<Rewritten, String> {
    let comments = comments(text);
    let in_comment = |at: usize| comments.iter().any(|&(s, e)| at >= s && at < e);
    let b = text.as_bytes();
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    let (mut tests, mut sites, mut buffers) = (Vec::new(), Vec::new(), Vec::<TestBuffer>::new());
    let (mut textures, mut samplers, mut bindings) = (Vec::new(), Vec::new(), 0usize);
    let mut snapshots = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if in_comment(i) || !(b[i] == b'@' || is_ident(b[i])) || (i > 0 && (is_ident(b[i - 1]) || b[i - 1] == b':')) {
            i += 1;
            continue;
        }
        let start = if b[i] == b'@' { i + 1 } else { i };
        let end = start + text[start..].bytes().take_while(|&c| is_ident(c)).count();
        let word = &text[start..end];
        if b[i] == b'@' {
            let at = |e: &str| {
                let (l, c) = place(text, i);
                format!("{l}:{c}: {e}")
            };
            // An attribute may span lines: its replacement keeps the line breaks.
            let breaks = |to: usize| "\n".repeat(text[i..to].matches('\n').count());
            let blank = |to: usize| {
                let keep = breaks(to);
                (i, to, format!("{}{keep}", " ".repeat(to - i - keep.len())))
            };
            match word {
                "test" => {
                    // `@test` before `fn name(`, possibly across other attributes.
                    let (fn_at, name) =
                        function_after(text, end).ok_or_else(|| at("@test is not followed by a function"))?;
                    tests.push(TestFn { name, line: place(text, fn_at).0 });
                    edits.push(blank(end));
                }
                "snapshot" => {
                    let (size, close) = snapshot_size(text, end).map_err(|e| at(&e))?;
                    let (fn_at, name) =
                        function_after(text, close).ok_or_else(|| at("@snapshot is not followed by a function"))?;
                    // The attributes of this declaration: from the end of the last one.
                    let decl_start = text[..i].rfind(['}', ';']).map_or(0, |p| p + 1);
                    if !text[decl_start..fn_at].contains("@fragment") {
                        return Err(at("@snapshot marks a @fragment function"));
                    }
                    snapshots.push(Snapshot { name, size });
                    edits.push(blank(close));
                    i = close;
                    continue;
                }
                "test_texture" | "sampler" => {
                    let close = if word == "sampler" {
                        let (s, close) = sampler_decl(text, end).map_err(|e| at(&e))?;
                        samplers.push(s);
                        close
                    } else {
                        let (t, close) = texture_decl(text, end).map_err(|e| at(&e))?;
                        textures.push(t);
                        close
                    };
                    edits.push((i, close, format!("@group({BUFFER_GROUP}) @binding({bindings}){}", breaks(close))));
                    bindings += 1;
                }
                "buffer" => {
                    buffers.push(buffer_decl(&text[end..]).map_err(|e| at(&e))?);
                    edits.push((i, end, format!("@group({BUFFER_GROUP}) @binding({bindings})")));
                    bindings += 1;
                }
                _ => {}
            }
            i = end;
            continue;
        }
        let after = text[end..].trim_start();
        let assertion = Assertion::of(word).filter(|_| after.starts_with('('));
        let declared = text[..i].trim_end().ends_with("fn");
        match assertion {
            Some(a) if !declared => {
                let open = text.len() - after.len();
                let (close, args) = call_end(text, open).ok_or_else(|| {
                    let (l, c) = place(text, i);
                    format!("{l}:{c}: {word}( is not closed")
                })?;
                let want: &[usize] = match a {
                    Assertion::Expect => &[1],
                    Assertion::Near(_) => &[2, 3],
                    Assertion::Ulp => &[3],
                    _ => &[2],
                };
                let (line, col) = place(text, i);
                if !want.contains(&args) {
                    return Err(format!(
                        "{line}:{col}: {word} takes {} arguments, not {args}",
                        want.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(" or ")
                    ));
                }
                sites.push(Site { assertion: a, line, col });
                let site = sites.len();
                // `expectNear(a, b)` at the default tolerance.
                let tol = if matches!(a, Assertion::Near(_)) && args == 2 { ", wgsl_test::NEAR_TOL" } else { "" };
                edits.push((close - 1, close - 1, tol.to_string()));
                edits.push((i, open + 1, format!("wgsl_test::{word}_at({site}u, ")));
            }
            _ => {}
        }
        i = end;
    }
    if tests.is_empty() && snapshots.is_empty() {
        return Err("no @test or @snapshot function".into());
    }
    edits.sort_by_key(|e| std::cmp::Reverse(e.0));
    let mut out = text.to_string();
    for (s, e, with) in edits {
        out.replace_range(s..e, &with);
    }
    out.push_str(if wesl { "\n" } else { "\n#import wgsl_test\n" });
    // Each entry reaches every buffer (a phony use), so that each pass binds
    // its test's own copies whether or not the test touches them.
    let reach: String = buffers.iter().map(|b| format!("_ = {}; ", b.name)).collect();
    for (n, t) in tests.iter().enumerate() {
        out.push_str(&format!(
            "@compute @workgroup_size(1) fn {}() {{ {reach}wgsl_test::begin({n}u); {}(); }}\n",
            entry(n),
            t.name
        ));
    }
    for (n, t) in textures.iter().enumerate() {
        out.push_str(&fill_code(n, t, bindings + n));
    }
    Ok(Rewritten { text: out, tests, sites, buffers, textures, samplers, snapshots })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calls_carry_their_place_and_lines_keep_their_numbers() {
        let text = "#import wgsl_test\n// expectNear(1.0, 2.0) in a comment\n@test\nfn a() {\n  expectNear(f(1.0, 2.0), 0.5);\n  expect(x > (1.0));\n}\n@test fn b() { expectNearV3f(v, w, 1e-3); }\nfn expectEq_like() {}\n";
        let r = rewrite(text, false).unwrap();
        assert_eq!(r.tests, [TestFn { name: "a".into(), line: 4 }, TestFn { name: "b".into(), line: 8 }]);
        assert_eq!(
            r.sites,
            [
                Site { assertion: Assertion::Near(1), line: 5, col: 3 },
                Site { assertion: Assertion::Expect, line: 6, col: 3 },
                Site { assertion: Assertion::Near(3), line: 8, col: 16 },
            ]
        );
        let lines: Vec<&str> = r.text.lines().collect();
        assert_eq!(lines[1], "// expectNear(1.0, 2.0) in a comment");
        assert_eq!(lines[2], "     ");
        assert_eq!(lines[4], "  wgsl_test::expectNear_at(1u, f(1.0, 2.0), 0.5, wgsl_test::NEAR_TOL);");
        assert_eq!(lines[5], "  wgsl_test::expect_at(2u, x > (1.0));");
        assert_eq!(lines[7], "      fn b() { wgsl_test::expectNearV3f_at(3u, v, w, 1e-3); }");
        assert!(r.text.ends_with("fn vista_test_1() { wgsl_test::begin(1u); b(); }\n"), "{}", r.text);
    }

    #[test]
    fn buffers_get_a_binding_and_their_length() {
        let text = "@buffer var<storage, read_write> data: array<f32, 4>;\n@buffer var<storage, read_write> n: u32;\n\
                    @test fn a() { data[0] = 1.0; }\n";
        let r = rewrite(text, false).unwrap();
        assert_eq!(
            r.buffers,
            [TestBuffer { name: "data".into(), length: 4 }, TestBuffer { name: "n".into(), length: 1 }]
        );
        assert!(r.text.starts_with("@group(2) @binding(0) var<storage, read_write> data"), "{}", r.text);
        assert!(r.text.contains("fn vista_test_0() { _ = data; _ = n; wgsl_test::begin(0u); a(); }"), "{}", r.text);
        let sizeless = rewrite("@buffer var<storage, read_write> d: array<f32>;\n@test fn a() {}", false).unwrap_err();
        assert_eq!(sizeless, "1:1: @buffer d: array<f32> has no size; give it one (array<T, N>)");
    }

    #[test]
    fn test_textures_and_samplers_get_bindings_patterns_and_fill_entries() {
        let text = "@buffer var<storage, read_write> d: array<f32, 2>;\n\
                    @test_texture(checkerboard, 64, 32, 8) var board: texture_2d<f32>;\n\
                    @test_texture(file, \"inputs/rock.png\") var rock: texture_2d<f32>;\n\
                    @sampler(linear) var s: sampler;\n@test fn a() {}\n";
        let r = rewrite(text, false).unwrap();
        assert_eq!(
            r.textures,
            [
                TestTexture { name: "board".into(), pattern: Pattern::Checkerboard(8), size: Some((64, 32)) },
                TestTexture { name: "rock".into(), pattern: Pattern::File("inputs/rock.png".into()), size: None },
            ]
        );
        assert_eq!(r.samplers, [TestSampler { name: "s".into(), linear: true }]);
        let lines: Vec<&str> = r.text.lines().collect();
        assert_eq!(lines[1], "@group(2) @binding(1) var board: texture_2d<f32>;");
        assert_eq!(lines[3], "@group(2) @binding(3) var s: sampler;");
        // A fill entry for the generated texture only, at the next binding.
        assert!(r.text.contains("@group(2) @binding(4) var vista_fill_tex_0: texture_storage_2d<rgba16float, write>;"));
        assert!(r.text.contains("fn vista_fill_0(") && !r.text.contains("vista_fill_1"), "{}", r.text);
        let bad = |t: &str| rewrite(&format!("{t}\n@test fn a() {{}}"), false).unwrap_err();
        assert_eq!(
            bad("@test_texture(plaid, 4, 4) var t: texture_2d<f32>;"),
            "1:1: @test_texture t: unknown kind plaid; kinds: checkerboard, gradient, noise or file"
        );
        assert_eq!(
            bad("@test_texture(gradient, 4, 4) var t: texture_3d<f32>;"),
            "1:1: @test_texture t: a test texture is a texture_2d<f32>, not texture_3d<f32>"
        );
        assert_eq!(
            bad("@test_texture(noise, 4, 4) var t: texture_2d<f32>;"),
            "1:1: @test_texture t: noise needs a seed (noise, W, H, SEED)"
        );
        assert_eq!(
            bad("@test_texture(gradient, 0, 4) var t: texture_2d<f32>;"),
            "1:1: @test_texture t: 0x4 is not a size from 1x1 to 4096x4096"
        );
        assert_eq!(
            bad("@sampler(bilinear) var s: sampler;"),
            "1:1: @sampler s: takes linear or nearest, not (bilinear)"
        );
    }

    #[test]
    fn a_wrong_argument_count_and_no_test_are_named() {
        assert_eq!(
            rewrite("@test fn a() {\n  expect(1, 2);\n}", false).unwrap_err(),
            "2:3: expect takes 1 arguments, not 2"
        );
        assert_eq!(rewrite("fn a() {}", false).unwrap_err(), "no @test or @snapshot function");
    }
}
