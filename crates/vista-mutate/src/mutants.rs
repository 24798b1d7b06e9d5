//! Single-token mutants of WGSL source, inside function bodies only (never
//! in comments, struct declarations, bindings or module-scope constants),
//! found by a small lexer: SPEC 12's operators.

/// One mutant: where, which operator, and the text it replaces.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Mutant {
    /// Shader file, relative to `shaders/`.
    pub file: String,
    /// 1-based line of the replaced text.
    pub line: u32,
    /// 1-based column of the replaced text.
    pub col: u32,
    /// SPEC 12's operator name.
    pub operator: String,
    /// The text replaced.
    pub before: String,
    /// Its replacement.
    pub after: String,
    /// Byte offset of `before` in the file.
    #[serde(skip)]
    pub start: usize,
    /// Byte offset just past `before`.
    #[serde(skip)]
    pub end: usize,
}

impl Mutant {
    /// The file's text with this mutant applied.
    pub fn apply(&self, text: &str) -> String {
        format!("{}{}{}", &text[..self.start], self.after, &text[self.end..])
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Ident,
    Number,
    Punct,
}

#[derive(Debug, Clone, Copy)]
struct Token {
    kind: Kind,
    start: usize,
    end: usize,
}

/// Operators longest first, so `<=` wins over `<`.
const PUNCT: &[&str] = &[
    "<<=", ">>=", "->", "&&", "||", "<=", ">=", "==", "!=", "+=", "-=", "*=", "/=", "%=", "&=", "|=", "^=", "++", "--",
    "<<", ">>",
];

fn lex(text: &str) -> Vec<Token> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if text[i..].starts_with("//") || (c == b'#' && (i == 0 || b[i - 1] == b'\n')) {
            // Comments and naga_oil directives (#import ...) run to the end of the line.
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if text[i..].starts_with("/*") {
            i = text[i + 2..].find("*/").map_or(b.len(), |j| i + 2 + j + 2);
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let s = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push(Token { kind: Kind::Ident, start: s, end: i });
        } else if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            let s = i;
            let hex = text[i..].starts_with("0x") || text[i..].starts_with("0X");
            i += if hex { 2 } else { 0 };
            while i < b.len() {
                let d = b[i];
                let exp_sign = (d == b'-' || d == b'+') && !hex && matches!(b[i - 1], b'e' | b'E');
                if d.is_ascii_alphanumeric() || d == b'.' || exp_sign {
                    i += 1;
                } else {
                    break;
                }
            }
            out.push(Token { kind: Kind::Number, start: s, end: i });
        } else {
            let len = PUNCT.iter().find(|p| text[i..].starts_with(**p)).map_or(1, |p| p.len());
            out.push(Token { kind: Kind::Punct, start: i, end: i + len });
            i += len;
        }
    }
    out
}

/// Identifiers whose `<` opens a template list, not a comparison.
const TEMPLATED: &[&str] = &[
    "vec2",
    "vec3",
    "vec4",
    "mat2x2",
    "mat2x3",
    "mat2x4",
    "mat3x2",
    "mat3x3",
    "mat3x4",
    "mat4x2",
    "mat4x3",
    "mat4x4",
    "array",
    "bitcast",
    "ptr",
    "atomic",
    "texture_storage_2d",
    "texture_2d",
];

const SWAPS: &[(&str, &str)] =
    &[("min", "max"), ("max", "min"), ("floor", "ceil"), ("ceil", "floor"), ("exp", "exp2"), ("exp2", "exp")];

fn line_col(text: &str, at: usize) -> (u32, u32) {
    let before = &text[..at];
    let line = before.matches('\n').count() as u32 + 1;
    let col = (before.len() - before.rfind('\n').map_or(0, |i| i + 1)) as u32 + 1;
    (line, col)
}

/// `1.5` -> `1.575`, `0.0` -> `0.05`, keeping a `f`/`h` suffix; None for a
/// literal this cannot scale.
fn scale_float(lit: &str) -> Option<String> {
    let (digits, suffix) = match lit.strip_suffix('f').or_else(|| lit.strip_suffix('h')) {
        Some(d) => (d, &lit[d.len()..]),
        None => (lit, ""),
    };
    let v: f64 = digits.parse().ok()?;
    let m = if v == 0.0 { 0.05 } else { v * 1.05 };
    // Shortest text that round-trips in f32, the precision WGSL has.
    let mut s = format!("{:?}", m as f32);
    if !s.contains('.') && !s.contains('e') {
        s.push_str(".0");
    }
    Some(s + suffix)
}

/// `7u` -> `8u`, `0x9E3779B9u` -> `0x9E3779BAu`; None past the range.
fn bump_int(lit: &str) -> Option<String> {
    let (body, suffix) = match lit.strip_suffix('u').or_else(|| lit.strip_suffix('i')) {
        Some(d) => (d, &lit[d.len()..]),
        None => (lit, ""),
    };
    if let Some(h) = body.strip_prefix("0x").or_else(|| body.strip_prefix("0X")) {
        let v = u64::from_str_radix(h, 16).ok()?.checked_add(1)?;
        return (v <= u32::MAX as u64).then(|| format!("0x{v:X}{suffix}"));
    }
    let v: u64 = body.parse().ok()?;
    (v < i32::MAX as u64).then(|| format!("{}{suffix}", v + 1))
}

/// One function of a WGSL file: its name, the byte range of its body and
/// the names it calls.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Function {
    /// The function's name.
    pub name: String,
    /// Byte range of the body, braces included.
    pub body: (usize, usize),
    /// Identifiers called in the body (`name(`), builtins included.
    pub calls: Vec<String>,
}

/// The functions of `text`, in source order.
pub fn functions(text: &str) -> Vec<Function> {
    let toks = lex(text);
    let s = |t: &Token| &text[t.start..t.end];
    let mut out = Vec::new();
    let mut i = 0;
    while i + 1 < toks.len() {
        if s(&toks[i]) == "fn" && toks[i + 1].kind == Kind::Ident {
            let name = s(&toks[i + 1]).to_string();
            let Some(open) = (i..toks.len()).find(|&k| s(&toks[k]) == "{") else { break };
            let mut depth = 0;
            let mut close = open;
            for (k, t) in toks.iter().enumerate().skip(open) {
                match s(t) {
                    "{" => depth += 1,
                    "}" => {
                        depth -= 1;
                        if depth == 0 {
                            close = k;
                            break;
                        }
                    }
                    _ => {}
                }
            }
            let calls = (open..close)
                .filter(|&k| toks[k].kind == Kind::Ident && toks.get(k + 1).is_some_and(|n| s(n) == "("))
                .map(|k| s(&toks[k]).to_string())
                .collect();
            out.push(Function { name, body: (toks[open].start, toks[close].end), calls });
            i = close;
        }
        i += 1;
    }
    out
}

/// Every mutant of `text` (the file `file`), in source order.
pub fn mutants(file: &str, text: &str) -> Vec<Mutant> {
    let toks = lex(text);
    let s = |t: &Token| &text[t.start..t.end];
    // Tokens inside function bodies; template brackets excluded.
    let (in_body, template) = body_and_template_tokens(&toks, text);
    let operand_before = |i: usize| {
        i > 0 && (matches!(toks[i - 1].kind, Kind::Ident | Kind::Number) || matches!(s(&toks[i - 1]), ")" | "]"))
    };
    let mut out = Vec::new();
    let mut push = |start: usize, end: usize, operator: &str, after: String| {
        let (line, col) = line_col(text, start);
        out.push(Mutant {
            file: file.to_string(),
            line,
            col,
            operator: operator.to_string(),
            before: text[start..end].to_string(),
            after,
            start,
            end,
        });
    };
    for (i, t) in toks.iter().enumerate() {
        if !in_body[i] || template[i] {
            continue;
        }
        let tx = s(t);
        match t.kind {
            Kind::Number => {
                let float = tx.contains('.')
                    || ((tx.contains('e') || tx.contains('E')) && !tx.starts_with("0x"))
                    || tx.ends_with('f');
                let m = if float {
                    scale_float(tx).map(|m| ("float literal x 1.05", m))
                } else {
                    bump_int(tx).map(|m| ("integer literal + 1", m))
                };
                if let Some((op, m)) = m {
                    push(t.start, t.end, op, m);
                }
            }
            Kind::Ident => {
                let call = toks.get(i + 1).is_some_and(|n| s(n) == "(");
                if call && let Some((_, to)) = SWAPS.iter().find(|(from, _)| *from == tx) {
                    push(t.start, t.end, "builtin swap", to.to_string());
                }
                if call && tx == "select" {
                    // select(f, t, c): swap the first two arguments.
                    let mut depth = 0;
                    let mut commas = Vec::new();
                    let mut close = None;
                    for (k, u) in toks.iter().enumerate().skip(i + 1) {
                        match s(u) {
                            "(" | "[" => depth += 1,
                            ")" | "]" => {
                                depth -= 1;
                                if depth == 0 {
                                    close = Some(k);
                                    break;
                                }
                            }
                            "," if depth == 1 => commas.push(k),
                            _ => {}
                        }
                    }
                    if let (Some(_), [c1, c2, ..]) = (close, commas.as_slice()) {
                        let a = &text[toks[i + 2].start..toks[*c1].start];
                        let b = &text[toks[c1 + 1].start..toks[*c2].start];
                        let (start, end) = (toks[i + 2].start, toks[*c2].start);
                        push(start, end, "swapped select arms", format!("{}, {}", b.trim(), a.trim()));
                    }
                }
            }
            Kind::Punct => {
                let binary = operand_before(i);
                let swap = match tx {
                    "+" if binary => Some(("arithmetic swap", "-")),
                    "-" if binary => Some(("arithmetic swap", "+")),
                    "*" if binary => Some(("arithmetic swap", "/")),
                    "/" if binary => Some(("arithmetic swap", "*")),
                    "&&" => Some(("&& ||", "||")),
                    "||" => Some(("&& ||", "&&")),
                    _ => None,
                };
                if let Some((op, to)) = swap {
                    push(t.start, t.end, op, to.into());
                }
                let (boundary, flip) = match tx {
                    "<" => (Some("<="), Some(">=")),
                    "<=" => (Some("<"), Some(">")),
                    ">" => (Some(">="), Some("<=")),
                    ">=" => (Some(">"), Some("<")),
                    "==" => (None, Some("!=")),
                    "!=" => (None, Some("==")),
                    _ => (None, None),
                };
                if let Some(to) = boundary {
                    push(t.start, t.end, "comparison boundary", to.into());
                }
                if let Some(to) = flip {
                    push(t.start, t.end, "comparison flip", to.into());
                }
                if matches!(tx, "+=" | "-=" | "*=" | "/=") {
                    // Drop the whole statement `lhs op= rhs;`.
                    let stmt_start =
                        (0..i).rev().find(|&k| matches!(s(&toks[k]), ";" | "{" | "}")).map_or(0, |k| k + 1);
                    let stmt_end = (i..toks.len()).find(|&k| s(&toks[k]) == ";");
                    let in_parens = toks[stmt_start..i].iter().any(|u| s(u) == "(");
                    if let Some(e) = stmt_end
                        && !in_parens
                    {
                        push(toks[stmt_start].start, toks[e].end, "dropped compound assignment", String::new());
                    }
                }
            }
        }
    }
    out
}

/// Which tokens lie inside a function body, and which inside a template's
/// angle brackets (`array<f32, 4>`: not comparisons to mutate).
fn body_and_template_tokens(toks: &[Token], text: &str) -> (Vec<bool>, Vec<bool>) {
    let s = |t: &Token| &text[t.start..t.end];
    let mut in_body = vec![false; toks.len()];
    let mut template = vec![false; toks.len()];
    let mut i = 0;
    while i < toks.len() {
        if toks[i].kind == Kind::Ident && s(&toks[i]) == "fn" {
            let mut j = i;
            while j < toks.len() && s(&toks[j]) != "{" {
                j += 1;
            }
            let mut depth = 0;
            let mut k = j;
            while k < toks.len() {
                match s(&toks[k]) {
                    "{" => depth += 1,
                    "}" => {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    _ => {}
                }
                in_body[k] = true;
                k += 1;
            }
            i = k;
        }
        i += 1;
    }
    for i in 1..toks.len() {
        if s(&toks[i]) == "<" && toks[i - 1].kind == Kind::Ident && TEMPLATED.contains(&s(&toks[i - 1])) {
            let mut depth = 0i32;
            for (k, t) in toks.iter().enumerate().skip(i) {
                match s(t) {
                    "<" => depth += 1,
                    ">" => depth -= 1,
                    ">>" => depth -= 2,
                    _ => {}
                }
                template[k] = true;
                if depth <= 0 {
                    break;
                }
            }
        }
    }
    (in_body, template)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = "// a + b in a comment\n#import vista::x\nconst K: f32 = 2.0;\nstruct P { a: f32, v: vec3<f32> }\n\
@group(0) @binding(0) var<uniform> p: P;\n\
fn f(x: f32) -> f32 {\n    var s = 0.0; /* 3.0 * 4.0 */\n    s += min(x, 1.5) * 2u;\n    if x < p.a && -x >= 0.0 {\n        return select(1.0, 2.0, x > 0.5);\n    }\n    let v = vec3<f32>(x) + bitcast<vec3<u32>>(vec3(1u)).x;\n    return s - x;\n}\n";

    fn ops(m: &[Mutant]) -> Vec<(String, String, String)> {
        m.iter().map(|m| (m.operator.clone(), m.before.clone(), m.after.clone())).collect()
    }

    #[test]
    fn mutants_come_only_from_function_bodies_and_every_operator_fires() {
        let m = mutants("k.wgsl", SRC);
        let o = ops(&m);
        let has = |op: &str, b: &str, a: &str| o.contains(&(op.to_string(), b.to_string(), a.to_string()));
        assert!(has("float literal x 1.05", "0.0", "0.05"), "{o:?}");
        assert!(has("float literal x 1.05", "1.5", "1.575"), "{o:?}");
        assert!(has("integer literal + 1", "2u", "3u"), "{o:?}");
        assert!(has("builtin swap", "min", "max"), "{o:?}");
        assert!(has("arithmetic swap", "*", "/"), "{o:?}");
        assert!(has("arithmetic swap", "-", "+"), "{o:?}");
        assert!(has("comparison boundary", "<", "<="), "{o:?}");
        assert!(has("comparison flip", ">=", "<"), "{o:?}");
        assert!(has("&& ||", "&&", "||"), "{o:?}");
        assert!(has("swapped select arms", "1.0, 2.0", "2.0, 1.0"), "{o:?}");
        assert!(has("dropped compound assignment", "s += min(x, 1.5) * 2u;", ""), "{o:?}");
        // Nothing from the comment, the directive, the const, the struct, the
        // binding, the block comment, the unary minus or the template lists.
        let lines: Vec<u32> = m.iter().map(|m| m.line).collect();
        assert!(lines.iter().all(|l| *l >= 7), "{m:?}");
        assert!(!o.iter().any(|(_, b, _)| b == "3.0" || b == "4.0"), "block comment mutated: {o:?}");
        assert!(!m.iter().any(|m| m.line == 9 && m.col == 24 && m.before == "-"), "unary minus mutated: {o:?}");
        let template_line = SRC.lines().position(|l| l.contains("bitcast")).unwrap() as u32 + 1;
        assert!(!m.iter().any(|m| m.line == template_line && (m.before == "<" || m.before == ">")), "{o:?}");
    }

    #[test]
    fn mutants_apply_at_their_place_and_report_line_and_column() {
        let m = mutants("k.wgsl", SRC);
        let min = m.iter().find(|m| m.operator == "builtin swap").unwrap();
        assert_eq!((min.line, min.col), (8, 10));
        let applied = min.apply(SRC);
        assert!(applied.contains("s += max(x, 1.5) * 2u;"));
        assert_eq!(applied.len(), SRC.len());
    }

    #[test]
    fn literal_rewrites() {
        assert_eq!(scale_float("2.0").as_deref(), Some("2.1"));
        assert_eq!(scale_float("1e-3").as_deref(), Some("0.00105"));
        assert_eq!(scale_float("0.5f").as_deref(), Some("0.525f"));
        assert_eq!(bump_int("0x9E3779B9u").as_deref(), Some("0x9E3779BAu"));
        assert_eq!(bump_int("255").as_deref(), Some("256"));
    }
}
