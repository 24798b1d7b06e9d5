//! Source assembly (SPEC 16): the WGSL text of one pass as a project's host
//! builds it before the compiler sees it — textual `#include`, files joined
//! before and after the shader, literal text replacements — with every
//! assembled line traced to the file and line it came from, so errors name
//! the file the user wrote.
//!
//! `.wesl` shaders compile through the `wesl` crate ([`compile_wesl`]).
//!
//! Not for: `#import` and shader defs (naga_oil's, in `vista-gpu`), or
//! reading files: the caller hands in a reader, so this crate does no
//! I/O and knows no project layout.
#![deny(missing_docs)]

mod assemble;
mod decoration;
mod spec;
mod wesl;
mod wesl_blocks;
mod wesl_lines;

pub use assemble::{Assembled, Part, assemble, unmatched_error};
pub use decoration::undecorate;
pub use spec::{DEFAULT_COMMAND_TIMEOUT_MS, Generator, Replacement, SourceSpec};
pub use wesl::compile_wesl;

/// How deep brackets may nest in a shader file, and how many binary
/// operators one statement may chain: naga's and the wesl crate's parsers
/// and naga's constant evaluator recurse on expressions, and a 5000-term
/// sum overflowed the stack (exit 134). Real shaders stay far below both.
pub const MAX_NESTING: usize = 256;

/// See [`MAX_NESTING`].
pub const MAX_OPERATORS_PER_STATEMENT: usize = 1024;

/// Refuses text whose expressions are deeper or longer than the parsers
/// can take ([`MAX_NESTING`], [`MAX_OPERATORS_PER_STATEMENT`]), naming the
/// file and line, before any parser sees it. Comments are skipped.
pub fn check_depth(text: &str, origin: &str) -> Result<(), String> {
    let (mut depth, mut operators, mut statement_line) = (0usize, 0usize, 1usize);
    let mut block_comments = 0usize;
    for (n, line) in text.lines().enumerate() {
        let mut chars = line.chars().peekable();
        while let Some(c) = chars.next() {
            let next = chars.peek().copied();
            if block_comments > 0 {
                match (c, next) {
                    ('*', Some('/')) => {
                        chars.next();
                        block_comments -= 1;
                    }
                    ('/', Some('*')) => {
                        chars.next();
                        block_comments += 1;
                    }
                    _ => {}
                }
                continue;
            }
            match (c, next) {
                ('/', Some('/')) => break,
                ('/', Some('*')) => {
                    chars.next();
                    block_comments += 1;
                }
                ('(' | '[', _) => {
                    depth += 1;
                    if depth > MAX_NESTING {
                        return Err(format!(
                            "{origin}:{}: brackets nested {depth} deep; allowed: {MAX_NESTING}",
                            n + 1
                        ));
                    }
                }
                (')' | ']', _) => depth = depth.saturating_sub(1),
                (';' | '{' | '}', _) => {
                    operators = 0;
                    statement_line = n + 1;
                }
                ('+' | '-' | '*' | '/' | '%' | '&' | '|' | '^', _) => {
                    operators += 1;
                    if operators > MAX_OPERATORS_PER_STATEMENT {
                        return Err(format!(
                            "{origin}:{statement_line}: one statement chains more than {MAX_OPERATORS_PER_STATEMENT} \
                             operators; allowed: {MAX_OPERATORS_PER_STATEMENT} (split it)"
                        ));
                    }
                }
                _ => {}
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod depth_tests {
    use super::*;

    #[test]
    fn long_sums_and_deep_brackets_are_refused_with_file_and_line() {
        let long = format!("const TAU: f32 = 6.28{};\n", " + 0.0".repeat(5000));
        let e = check_depth(&format!("// header\n{long}"), "k.wgsl").unwrap_err();
        assert!(e.starts_with("k.wgsl:1:") || e.starts_with("k.wgsl:2:"), "{e}");
        assert!(e.contains("more than 1024 operators"), "{e}");
        let deep = format!("const X: f32 = {}1.0{};\n", "(".repeat(300), ")".repeat(300));
        let e = check_depth(&deep, "k.wgsl").unwrap_err();
        assert!(e.contains("k.wgsl:1: brackets nested 257 deep; allowed: 256"), "{e}");
        // Comments do not count; ordinary shaders pass.
        assert!(
            check_depth(&format!("/* {} */\n// {}\nfn f() {{}}\n", "+".repeat(5000), "(".repeat(500)), "k").is_ok()
        );
        assert!(check_depth("fn f(a: f32) -> f32 { return (a + 1.0) * (a - 2.0) / 3.0; }\n", "k").is_ok());
    }
}
