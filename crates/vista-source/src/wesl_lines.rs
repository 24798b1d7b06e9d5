//! Each line of the wesl crate's output traced to the module file and line
//! it came from. The compiled syntax tree keeps every declaration's and
//! statement's span in the text of the module it was parsed from, and the
//! output is that tree printed declaration by declaration, one statement
//! per line: so a declaration's lines are found from its span, and its
//! statements' lines by printing each and finding it, in order, among the
//! declaration's printed lines. Lines that are no statement's (closing
//! braces, `else {`, `case 1 {`) stay untraced.

use std::fmt::Display;

use wesl::syntax::{GlobalDeclaration, Statement, StatementNode, TranslationUnit};

/// A module: the index of its file among the parts, and the text the
/// compiler parsed (the file's lines, kept).
pub(crate) type ModuleText<'a> = (usize, &'a str);

/// For each line of `text` (`unit` printed): its module's part and 1-based
/// line. `module_of` finds a declaration's module by its (mangled) name.
/// `None` where `unit` does not print as `text` (nothing is traced then).
pub(crate) fn trace<'a>(
    unit: &TranslationUnit,
    text: &str,
    module_of: impl Fn(&str) -> Option<ModuleText<'a>>,
) -> Option<Vec<Option<(usize, usize)>>> {
    if !unit.imports.is_empty() {
        return None;
    }
    // As the syntax tree's own Display prints a translation unit.
    let mut printed = String::new();
    if !unit.global_directives.is_empty() {
        let directives: Vec<String> = unit.global_directives.iter().map(|d| d.to_string()).collect();
        printed.push_str(&directives.join("\n"));
        printed.push_str("\n\n");
    }
    let mut placed = Vec::new();
    for decl in unit.global_declarations.iter().filter(|d| !matches!(d.node(), GlobalDeclaration::Void)) {
        if !placed.is_empty() {
            printed.push_str("\n\n");
        }
        let first = printed.matches('\n').count();
        let own = decl.to_string();
        printed.push_str(&own);
        placed.push((first, own, decl));
    }
    printed.push('\n');
    if printed != text {
        return None;
    }
    let mut lines = vec![None; text.lines().count()];
    for (first, own, decl) in placed {
        let Some(name) = name_of(decl.node()) else { continue };
        let Some((part, source)) = module_of(&name) else { continue };
        let line_of = |offset: usize| source.get(..offset).map(|b| (part, b.matches('\n').count() + 1));
        let own_lines: Vec<&str> = own.lines().map(str::trim).collect();
        let start = decl.span().start;
        lines[first] = line_of(start);
        let GlobalDeclaration::Function(f) = decl.node() else { continue };
        // Attributes print on lines of their own before `fn name(`.
        let Some(header) = own_lines.iter().position(|l| l.starts_with("fn ")) else { continue };
        for line in &mut lines[first..first + header] {
            *line = line_of(start);
        }
        let item = crate::decoration::undecorate(&name).0;
        lines[first + header] = keyword_at(source, start, &item).and_then(line_of);
        let mut statements = Vec::new();
        collect(&f.body.statements, &mut statements);
        let mut cursor = header + 1;
        for (head, offset) in statements {
            if let Some(j) = (cursor..own_lines.len()).find(|&j| own_lines[j] == head) {
                lines[first + j] = line_of(offset);
                cursor = j + 1;
            }
        }
    }
    Some(lines)
}

fn name_of(decl: &GlobalDeclaration) -> Option<String> {
    let ident = match decl {
        GlobalDeclaration::Declaration(d) => &d.ident,
        GlobalDeclaration::TypeAlias(a) => &a.ident,
        GlobalDeclaration::Struct(s) => &s.ident,
        GlobalDeclaration::Function(f) => &f.ident,
        GlobalDeclaration::Void | GlobalDeclaration::ConstAssert(_) => return None,
    };
    Some(ident.name().to_string())
}

/// The offset of the `fn` of `fn item` at or after `start` in `source`.
fn keyword_at(source: &str, start: usize, item: &str) -> Option<usize> {
    let rest = source.get(start..)?;
    rest.match_indices("fn").find_map(|(at, _)| {
        let after = &rest[at + 2..];
        let named = after.starts_with(char::is_whitespace) && after.trim_start().starts_with(item);
        let word = rest[..at].chars().next_back().is_some_and(|c| c.is_alphanumeric() || c == '_');
        (named && !word).then_some(start + at)
    })
}

/// The first printed line of `x`, trimmed.
fn head(x: &impl Display) -> String {
    x.to_string().lines().next().unwrap_or("").trim().to_string()
}

/// Every statement under `block` in the order they print, each as its
/// first printed line and its span's start; an `else if` and a `break if`
/// (no statements of their own) by their condition's span.
fn collect(block: &[StatementNode], out: &mut Vec<(String, usize)>) {
    for s in block.iter().filter(|s| !matches!(s.node(), Statement::Void)) {
        out.push((head(s), s.span().start));
        match s.node() {
            Statement::Compound(c) => collect(&c.statements, out),
            Statement::If(i) => {
                collect(&i.if_clause.body.statements, out);
                for e in &i.else_if_clauses {
                    out.push((head(e), e.expression.span().start));
                    collect(&e.body.statements, out);
                }
                if let Some(e) = &i.else_clause {
                    collect(&e.body.statements, out);
                }
            }
            Statement::Switch(sw) => sw.clauses.iter().for_each(|c| collect(&c.body.statements, out)),
            Statement::Loop(l) => {
                collect(&l.body.statements, out);
                if let Some(c) = &l.continuing {
                    collect(&c.body.statements, out);
                    if let Some(b) = &c.break_if {
                        out.push((head(b), b.expression.span().start));
                    }
                }
            }
            Statement::For(f) => collect(&f.body.statements, out),
            Statement::While(w) => collect(&w.body.statements, out),
            _ => {}
        }
    }
}
