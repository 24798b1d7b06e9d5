//! Module-scope conditional blocks of newer WESL (`@if(X) { decls }`,
//! `@elif(Y) { ... }`, `@else { ... }`, as bevy main writes them), which
//! the pinned wesl crate 0.4 refuses with `unexpected token '{'`: rewritten
//! before it parses into one `@if(...)` attribute per declaration, the
//! conditions of a chain made exclusive (`@elif(Y)` is `@if(!(X) && (Y))`).
//! Lines stay where they were, so the crate's errors name the user's lines.

/// `text` with every module-scope conditional block turned into per-declaration
/// `@if` attributes; an error names the line of a block vista cannot read.
pub(crate) fn flatten_blocks(text: &str, origin: &str) -> Result<String, String> {
    if !text.contains("@if") && !text.contains("@el") {
        return Ok(text.to_string());
    }
    let mut out = String::with_capacity(text.len() + 64);
    let mut s = Scanner { chars: text.char_indices().peekable(), text, line: 1 };
    // The chain of the last block at this level: its conditions so far.
    let mut chain: Vec<String> = Vec::new();
    flatten_level(&mut s, &mut out, None, &mut chain, origin, false)?;
    Ok(out)
}

struct Scanner<'a> {
    chars: std::iter::Peekable<std::str::CharIndices<'a>>,
    text: &'a str,
    line: usize,
}

impl Scanner<'_> {
    fn peek(&mut self) -> Option<char> {
        self.chars.peek().map(|(_, c)| *c)
    }

    fn next(&mut self) -> Option<char> {
        let c = self.chars.next().map(|(_, c)| c)?;
        if c == '\n' {
            self.line += 1;
        }
        Some(c)
    }

    fn rest(&mut self) -> &str {
        let at = self.chars.peek().map(|(i, _)| *i).unwrap_or(self.text.len());
        &self.text[at..]
    }

    /// Copies whitespace and comments into `out` (newlines kept).
    fn trivia(&mut self, out: &mut String) {
        loop {
            match self.peek() {
                Some(c) if c.is_whitespace() => {
                    out.push(c);
                    self.next();
                }
                Some('/') if self.rest().starts_with("//") => {
                    while let Some(c) = self.peek() {
                        if c == '\n' {
                            break;
                        }
                        out.push(c);
                        self.next();
                    }
                }
                Some('/') if self.rest().starts_with("/*") => {
                    let mut depth = 0;
                    while let Some(c) = self.next() {
                        out.push(c);
                        if c == '/' && self.peek() == Some('*') {
                            out.push('*');
                            self.next();
                            depth += 1;
                        } else if c == '*' && self.peek() == Some('/') {
                            out.push('/');
                            self.next();
                            depth -= 1;
                            if depth == 0 {
                                break;
                            }
                        }
                    }
                }
                _ => return,
            }
        }
    }

    /// A balanced `( ... )` at the cursor, without the parentheses.
    fn parenthesized(&mut self) -> Option<String> {
        if self.peek() != Some('(') {
            return None;
        }
        self.next();
        let (mut depth, mut inner) = (1, String::new());
        while let Some(c) = self.next() {
            match c {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        return Some(inner);
                    }
                }
                _ => {}
            }
            inner.push(c);
        }
        None
    }
}

/// Blanks `text` but its newlines: the lines a rewritten header took.
fn blank(text: &str) -> String {
    text.chars().map(|c| if c == '\n' { '\n' } else { ' ' }).collect()
}

/// One level of declarations (the file, or a block's inside, `cond` its
/// condition), up to the block's `}` (`inside`) or the end of the text.
fn flatten_level(
    s: &mut Scanner,
    out: &mut String,
    cond: Option<&str>,
    chain: &mut Vec<String>,
    origin: &str,
    inside: bool,
) -> Result<(), String> {
    loop {
        s.trivia(out);
        let Some(c) = s.peek() else {
            return match inside {
                true => Err(format!("{origin}:{}: a module-scope @if block is not closed", s.line)),
                false => Ok(()),
            };
        };
        if c == '}' && inside {
            s.next();
            out.push(' ');
            return Ok(());
        }
        // A conditional block: `@if(X) {`, `@elif(Y) {`, `@else {`.
        let head = ["@if", "@elif", "@else"].into_iter().find(|h| {
            s.rest().starts_with(h) && !s.rest()[h.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
        });
        if let Some(head) = head {
            let line = s.line;
            let save = (s.chars.clone(), s.line);
            let mut header = String::new();
            for _ in 0..head.len() {
                header.push(s.next().unwrap_or_default());
            }
            let expr = match head {
                "@else" => Some(String::new()),
                _ => {
                    let mut gap = String::new();
                    s.trivia(&mut gap);
                    header.push_str(&gap);
                    s.parenthesized().inspect(|e| header.push_str(&format!("({e})")))
                }
            };
            let mut gap = String::new();
            s.trivia(&mut gap);
            header.push_str(&gap);
            if let (Some(expr), Some('{')) = (expr, s.peek()) {
                s.next();
                header.push('{');
                let own = match head {
                    "@if" => {
                        chain.clear();
                        format!("({})", expr.trim())
                    }
                    _ if chain.is_empty() => {
                        return Err(format!("{origin}:{line}: {head} block without an @if block before it"));
                    }
                    "@elif" => {
                        format!("{} && ({})", negated(chain), expr.trim())
                    }
                    _ => negated(chain),
                };
                if head != "@else" {
                    chain.push(expr.trim().to_string());
                } else {
                    chain.clear();
                }
                let full = match cond {
                    Some(outer) => format!("({outer}) && {own}"),
                    None => own,
                };
                out.push_str(&blank(&header));
                let mut inner_chain = Vec::new();
                flatten_level(s, out, Some(&full), &mut inner_chain, origin, true)?;
                continue;
            }
            // A declaration's own attribute: back to where it started.
            (s.chars, s.line) = save;
        }
        chain.clear();
        // A declaration: its condition in front, then it whole.
        if c == ';' {
            s.next();
            out.push(';');
            continue;
        }
        if let Some(cond) = cond {
            if s.rest().starts_with("@elif") || s.rest().starts_with("@else") {
                return Err(format!(
                    "{origin}:{}: @elif or @else on a declaration inside a module-scope @if block; write the \
                     condition on the block or as @if",
                    s.line
                ));
            }
            out.push_str(&format!("@if({cond}) "));
        }
        declaration(s, out);
    }
}

/// `!(a) && !(b)`: none of a chain's conditions.
fn negated(chain: &[String]) -> String {
    chain.iter().map(|c| format!("!({c})")).collect::<Vec<_>>().join(" && ")
}

/// Copies one declaration: up to a `;` outside brackets, or the `}` that
/// closes its body (and a `;` right after it).
fn declaration(s: &mut Scanner, out: &mut String) {
    let mut depth = 0i32;
    while let Some(c) = s.peek() {
        if c == '/' && (s.rest().starts_with("//") || s.rest().starts_with("/*")) {
            s.trivia(out);
            continue;
        }
        s.next();
        out.push(c);
        match c {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' => depth -= 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return;
                }
            }
            ';' if depth == 0 => return,
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_become_attributes_on_the_same_lines() {
        let src = "const A: u32 = 1u;\n@if(R16) {\n  fn f() -> u32 { return 16u; }\n  const B: u32 = 2u;\n}\n@elif(R32) {\n  fn f() -> u32 { return 32u; }\n} @else {\n  // fallback\n  fn f() -> u32 { return 8u; }\n}\n@if(X) fn g() {}\n";
        let out = flatten_blocks(src, "k.wesl").unwrap();
        assert_eq!(out.lines().count(), src.lines().count());
        let lines: Vec<&str> = out.lines().map(str::trim).collect();
        assert_eq!(lines[0], "const A: u32 = 1u;");
        assert_eq!(lines[2], "@if((R16)) fn f() -> u32 { return 16u; }");
        assert_eq!(lines[3], "@if((R16)) const B: u32 = 2u;");
        assert_eq!(lines[6], "@if(!(R16) && (R32)) fn f() -> u32 { return 32u; }");
        assert_eq!(lines[8], "// fallback");
        assert_eq!(lines[9], "@if(!(R16) && !(R32)) fn f() -> u32 { return 8u; }");
        assert_eq!(lines[11], "@if(X) fn g() {}", "a declaration's own @if is left alone");
    }

    #[test]
    fn nested_blocks_and_errors() {
        let src = "@if(A) {\n @if(B) {\n  fn f() {}\n }\n}\n";
        let out = flatten_blocks(src, "k.wesl").unwrap();
        assert!(out.contains("@if(((A)) && (B)) fn f() {}"), "{out}");
        let e = flatten_blocks("@else {\n fn f() {}\n}\n", "k.wesl").unwrap_err();
        assert_eq!(e, "k.wesl:1: @else block without an @if block before it");
        let e = flatten_blocks("@if(A) {\n fn f() {}\n", "k.wesl").unwrap_err();
        assert!(e.contains("k.wesl:3: a module-scope @if block is not closed"), "{e}");
        // Statements' @if inside a function are not blocks of declarations.
        let f = "fn f() {\n  @if(A) {\n    let x = 1;\n  }\n}\n";
        assert_eq!(flatten_blocks(f, "k.wesl").unwrap(), f);
    }
}
