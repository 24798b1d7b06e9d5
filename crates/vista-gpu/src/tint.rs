//! What Chromium's Tint compiles for one kernel file: the project's own
//! WGSL where vista can hand it as written, else naga's rewrite of the
//! composed module, with each entry point's name in it ([`TintWgsl`]).

/// The WGSL the page hands Tint for one kernel file, each entry point's
/// name in it, the pipeline constants that go with it, and where its lines
/// came from.
#[derive(Debug)]
pub struct TintWgsl {
    /// The text the page hands Dawn.
    pub wgsl: String,
    /// (the module's entry name, the name the writer gave it): naga's
    /// namer renames some (`fill_f32` becomes `fill_f32_`), and Dawn must
    /// be asked for the name the text has. Empty for the project's text.
    entries: Vec<(String, String)>,
    /// WebGPU pipeline constants (the project's text keeps its `override`s;
    /// a rewrite has them resolved).
    pub constants: Vec<(String, f64)>,
    /// The project's text and its lines' files; `None` for naga's rewrite.
    pub source: Option<crate::SourceText>,
}

impl TintWgsl {
    /// The project's own text, its overrides set by `constants`.
    pub(crate) fn source(source: crate::SourceText, constants: &[(String, f64)]) -> TintWgsl {
        TintWgsl { wgsl: source.text.clone(), entries: Vec::new(), constants: constants.to_vec(), source: Some(source) }
    }

    /// `wgsl`, naga's rewrite of `module`, with the entry names `written`
    /// (that text parsed back) gives them.
    pub(crate) fn rewrite(module: &naga::Module, written: &naga::Module, wgsl: String) -> TintWgsl {
        TintWgsl { wgsl, entries: written_entries(module, written), constants: Vec::new(), source: None }
    }

    /// The name entry `name` has in the text (itself unless the writer renamed it).
    pub fn entry<'a>(&'a self, name: &'a str) -> &'a str {
        self.entries.iter().find(|(from, _)| from == name).map_or(name, |(_, to)| to.as_str())
    }

    /// Where line `line`, column `col` (1-based) of the text is, for an
    /// error: the project's file and line, or, in a rewrite or a
    /// compiler's untraced output, that line of the text printed.
    pub fn place(&self, line: usize, col: usize) -> String {
        let text = self.wgsl.lines().nth(line.wrapping_sub(1)).unwrap_or("").trim();
        match &self.source {
            Some(s) => match s.locate(line) {
                Some((file, at)) => format!("{file}:{at}:{col}"),
                None => format!("line {line}:{col} of {} `{text}`", s.origin()),
            },
            None => format!("line {line}:{col} of naga's rewrite of the composed module, `{text}`"),
        }
    }

    /// `message` (runner.js's `line L:C: ...` list for this text) with each
    /// place named by [`TintWgsl::place`].
    pub(crate) fn locate(&self, message: &str) -> String {
        let mut out = String::new();
        let mut rest = message;
        while let Some(at) = rest.find("line ") {
            out.push_str(&rest[..at]);
            let after = &rest[at + "line ".len()..];
            match leading_number(after).and_then(|(l, t)| Some((l, leading_number(t.strip_prefix(':')?)?))) {
                Some((line, (col, tail))) if tail.starts_with(':') => {
                    out.push_str(&self.place(line, col));
                    rest = tail;
                }
                _ => {
                    out.push_str("line ");
                    rest = after;
                }
            }
        }
        out.push_str(rest);
        out
    }
}

/// The number `t` starts with, and what follows it.
fn leading_number(t: &str) -> Option<(usize, &str)> {
    let d = t.chars().take_while(char::is_ascii_digit).count();
    t[..d].parse::<usize>().ok().map(|n| (n, &t[d..]))
}

/// Each entry point of `module` renamed in `back`, the writer's text of it
/// parsed back: the writer keeps their order, so the n-th entry of the text
/// is the n-th of the module.
fn written_entries(module: &naga::Module, back: &naga::Module) -> Vec<(String, String)> {
    module
        .entry_points
        .iter()
        .zip(back.entry_points.iter())
        .filter(|(a, b)| a.name != b.name)
        .map(|(a, b)| (a.name.clone(), b.name.clone()))
        .collect()
}
