//! Includes, joins and replacements, line by line, each line remembering
//! where it came from.

use crate::{Replacement, SourceSpec};

/// One file an assembled source reached.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Part {
    /// Path relative to the project root.
    pub path: String,
    /// What errors name (a real path).
    pub origin: String,
    /// Its text as read.
    pub text: String,
}

/// A pass's assembled WGSL.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Assembled {
    /// The text the compiler sees.
    pub text: String,
    /// Every file reached: prepended, the shader, included, appended, in
    /// the order first reached.
    pub parts: Vec<Part>,
    /// Each replacement applied: its key and the text put in its place.
    pub replaced: Vec<(String, String)>,
    /// The `replace` keys found in no line of this file's assembly: refused
    /// ([`unmatched_error`]) only when no other module of the pass holds them
    /// (a key of a separate vertex file).
    pub unmatched: Vec<String>,
    /// For each line of `text`: the index of its part and its 1-based line
    /// there (`None`: a line a compiler wrote that is no file's).
    lines: Vec<Option<(usize, usize)>>,
    /// A compiler's output (WESL): its declarations in the compiler's
    /// order, which need not repeat from one process to the next, and its
    /// lines traced for coverage only (its errors are the compiler's).
    compiled: bool,
}

impl Assembled {
    /// A compiler's output over `parts`, with what is known of each line's
    /// file and line (`lines` empty: nothing).
    pub(crate) fn compiled(text: String, parts: Vec<Part>, lines: Vec<Option<(usize, usize)>>) -> Assembled {
        Assembled { text, parts, replaced: Vec::new(), unmatched: Vec::new(), lines, compiled: true }
    }

    /// Whether lines are traced to the files they came from.
    pub fn traced(&self) -> bool {
        !self.lines.is_empty()
    }

    /// Whether a compiler wrote the text (WESL) rather than vista joining
    /// files line by line.
    pub fn is_compiled(&self) -> bool {
        self.compiled
    }

    /// The file (its origin) and 1-based line that line `line` (1-based)
    /// of the assembled text came from: what an error names. None for a
    /// compiler's output, whose errors name its own lines.
    pub fn locate(&self, line: usize) -> Option<(&str, usize)> {
        if self.compiled {
            return None;
        }
        let (part, at) = (*self.lines.get(line.checked_sub(1)?)?)?;
        Some((self.parts[part].origin.as_str(), at))
    }

    /// The file (its path relative to the project root) and 1-based line
    /// that line `line` of the assembled text came from: what a coverage
    /// report names.
    pub fn locate_path(&self, line: usize) -> Option<(&str, usize)> {
        self.locate_part(line).map(|(p, at)| (p.path.as_str(), at))
    }

    /// The part and 1-based line there that line `line` came from.
    pub fn locate_part(&self, line: usize) -> Option<(&Part, usize)> {
        let (part, at) = (*self.lines.get(line.checked_sub(1)?)?)?;
        Some((&self.parts[part], at))
    }
}

struct State<'a> {
    spec: &'a SourceSpec,
    read: &'a dyn Fn(&str) -> Option<(String, String)>,
    parts: Vec<Part>,
    lines: Vec<(String, usize, usize)>,
    /// Files being expanded, with the line of the `#include` that opened the next.
    stack: Vec<(usize, usize)>,
}

/// Assembles pass shader `main` (a path relative to the project root) as
/// `spec` says: `prepend` files, the shader, `append` files, each with its
/// `#include`s expanded when `spec.include` turns them on, then `replace`.
/// `values` holds the text of each `{ param = ... }` replacement, in
/// order. `read` gives a root-relative path's text and origin.
pub fn assemble(
    main: &str,
    spec: &SourceSpec,
    values: &[String],
    read: &dyn Fn(&str) -> Option<(String, String)>,
) -> Result<Assembled, String> {
    let mut st = State { spec, read, parts: Vec::new(), lines: Vec::new(), stack: Vec::new() };
    for p in spec.prepend.iter().flatten() {
        st.add(p, "[source] prepend")?;
    }
    st.add(main, "shader")?;
    for p in spec.append.iter().flatten() {
        st.add(p, "[source] append")?;
    }
    let mut params = values.iter();
    let mut replaced = Vec::new();
    let mut unmatched = Vec::new();
    for (key, value) in &spec.replace {
        let value = match value {
            Replacement::Text(t) => t.clone(),
            Replacement::Param(p) => {
                params.next().cloned().ok_or_else(|| format!("[source] replace: no value given for param {p}"))?
            }
        };
        if !st.lines.iter().any(|(l, _, _)| l.contains(key.as_str())) {
            unmatched.push(key.clone());
            continue;
        }
        let mut out = Vec::with_capacity(st.lines.len());
        for (line, part, at) in st.lines {
            let new = line.replace(key.as_str(), &value);
            // A multi-line value: every line it adds is the replaced line's.
            out.extend(new.split('\n').map(|l| (l.to_string(), part, at)));
        }
        st.lines = out;
        replaced.push((key.clone(), value));
    }
    let mut text = String::new();
    for (l, _, _) in &st.lines {
        text.push_str(l);
        text.push('\n');
    }
    Ok(Assembled {
        text,
        parts: st.parts,
        replaced,
        unmatched,
        lines: st.lines.into_iter().map(|(_, part, at)| Some((part, at))).collect(),
        compiled: false,
    })
}

/// The refusal of a `replace` key that no file of a pass holds: `files`,
/// every file the pass's modules reach.
pub fn unmatched_error(key: &str, files: &[&str]) -> String {
    format!(
        "[source] replace: \"{key}\" is found in no file the pass reaches ({}); keys match within one line",
        files.join(", ")
    )
}

/// How deep `#include`s may nest: expanding them recurses, and a chain
/// thousands of files deep overflowed the stack (exit 134). Real projects
/// nest a handful.
pub const MAX_INCLUDE_DEPTH: usize = 64;

impl State<'_> {
    /// Adds a joined file (or the shader) as a new part.
    fn add(&mut self, path: &str, what: &str) -> Result<(), String> {
        let Some((text, origin)) = (self.read)(path) else {
            return Err(format!("{what} {path} not found under the project root"));
        };
        self.expand(Part { path: path.to_string(), origin, text })
    }

    fn chain(&self) -> String {
        self.stack.iter().map(|(p, l)| format!("{}:{l}", self.parts[*p].origin)).collect::<Vec<_>>().join(" -> ")
    }

    /// Appends `part`'s lines, each `#include` replaced by the file it names.
    fn expand(&mut self, part: Part) -> Result<(), String> {
        let index = self.parts.len();
        let text = part.text.clone();
        self.parts.push(part);
        for (i, line) in text.lines().enumerate() {
            let directive = line.trim_start().strip_prefix("#include").filter(|_| self.spec.include.is_some());
            let Some(rest) = directive else {
                self.lines.push((line.to_string(), index, i + 1));
                continue;
            };
            self.stack.push((index, i + 1));
            if self.stack.len() > MAX_INCLUDE_DEPTH {
                return Err(format!(
                    "#include nested {} deep at {}; allowed: {MAX_INCLUDE_DEPTH} (a chain of files each including \
                     the next)",
                    self.stack.len(),
                    self.stack.last().map(|(p, l)| format!("{}:{l}", self.parts[*p].origin)).unwrap_or_default()
                ));
            }
            let name = include_name(rest).map_err(|e| format!("{}: #include{rest}: {e}", self.chain()))?;
            let found = self.resolve(&self.parts[index].path.clone(), &name)?;
            if let Some(on) = self.stack.iter().position(|(p, _)| self.parts[*p].path == found) {
                let loop_start = &self.parts[self.stack[on].0].origin;
                return Err(format!("#include cycle: {} -> {loop_start}", self.chain()));
            }
            if self.parts.iter().any(|p| p.path == found) {
                // Included once per module: a second #include is an empty line.
                self.lines.push((String::new(), index, i + 1));
            } else {
                let (text, origin) = (self.read)(&found).expect("resolve found it");
                self.expand(Part { path: found, origin, text })?;
            }
            self.stack.pop();
        }
        Ok(())
    }

    /// The root-relative path `#include name` in file `from` names: next
    /// to `from`, then in each include folder; as written, then with
    /// `.wgsl` appended.
    fn resolve(&self, from: &str, name: &str) -> Result<String, String> {
        let dir = from.rsplit_once('/').map_or("", |(d, _)| d);
        let mut tried = Vec::new();
        for base in std::iter::once(dir).chain(self.spec.include.iter().flatten().map(String::as_str)) {
            for candidate in [name.to_string(), format!("{name}.wgsl")] {
                let path = normalize(&if base.is_empty() { candidate } else { format!("{base}/{candidate}") });
                if (self.read)(&path).is_some() {
                    return Ok(path);
                }
                tried.push(path);
            }
        }
        Err(format!("{}: #include \"{name}\" not found; tried {}", self.chain(), tried.join(", ")))
    }
}

/// The name after `#include`: `"x"`, `<x>` or a bare `x`; nothing may follow.
fn include_name(rest: &str) -> Result<String, String> {
    let r = rest.trim();
    let (name, after) = match r.chars().next() {
        Some('"') => r[1..].split_once('"').ok_or("the name has no closing \"")?,
        Some('<') => r[1..].split_once('>').ok_or("the name has no closing >")?,
        Some(_) if rest.starts_with(char::is_whitespace) => r.split_once(char::is_whitespace).unwrap_or((r, "")),
        _ => return Err("expected a file name: \"x\", <x> or x".into()),
    };
    if name.is_empty() {
        return Err("the file name is empty".into());
    }
    if !after.trim().is_empty() {
        return Err(format!("unexpected text after the file name: {}", after.trim()));
    }
    Ok(name.to_string())
}

/// `a/./b/../c` as `a/c` (a name may climb out of its folder, never the root).
fn normalize(path: &str) -> String {
    let mut out: Vec<&str> = Vec::new();
    for c in path.split('/') {
        match c {
            "" | "." => {}
            ".." => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out.join("/")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn files(list: &[(&str, &str)]) -> BTreeMap<String, String> {
        list.iter().map(|(p, t)| (p.to_string(), t.to_string())).collect()
    }

    fn run(fs: &BTreeMap<String, String>, spec: &SourceSpec, values: &[String]) -> Result<Assembled, String> {
        let read = |p: &str| fs.get(p).map(|t| (t.clone(), format!("/proj/{p}")));
        assemble("shaders/k.wgsl", spec, values, &read)
    }

    /// A chain 3000 files deep is refused at the documented depth, naming
    /// it, instead of overflowing the stack.
    #[test]
    fn a_deep_include_chain_is_refused_at_the_depth_limit() {
        let files: Vec<(String, String)> =
            (0..3000).map(|i| (format!("shaders/f{i}.wgsl"), format!("#include \"f{}.wgsl\"\n", i + 1))).collect();
        let read = |p: &str| files.iter().find(|(f, _)| f == p).map(|(_, t)| (t.clone(), format!("/p/{p}")));
        let read = |p: &str| read(p).or_else(|| (p == "shaders/f3000.wgsl").then(|| (String::new(), p.into())));
        let e = assemble("shaders/f0.wgsl", &includes(&[]), &[], &read).unwrap_err();
        assert!(e.contains("#include nested 65 deep") && e.contains("allowed: 64"), "{e}");
    }

    fn includes(folders: &[&str]) -> SourceSpec {
        SourceSpec { include: Some(folders.iter().map(|s| s.to_string()).collect()), ..Default::default() }
    }

    /// The four spellings real projects use, searched next to the including
    /// file first, then in the folders, as written then with `.wgsl`.
    #[test]
    fn four_spellings_resolve_next_to_the_file_then_in_the_folders() {
        let fs = files(&[
            (
                "shaders/k.wgsl",
                "#include \"common.wgsl\"\n#include <utility/frame>\n#include types.inc.wgsl\n#include \"noise/fn_perlin_noise.wgsl\"\nfn main() {}\n",
            ),
            ("shaders/common.wgsl", "const A: f32 = 1.0;\n"),
            ("shaders/include/utility/frame.wgsl", "const F: f32 = 2.0;\n"),
            ("shaders/include/types.inc.wgsl", "const T: f32 = 3.0;\n"),
            ("lib/noise/fn_perlin_noise.wgsl", "fn perlin() -> f32 { return A; }\n"),
            // Next to the file wins over a folder.
            ("shaders/include/common.wgsl", "WRONG\n"),
        ]);
        let a = run(&fs, &includes(&["shaders/include", "lib"]), &[]).unwrap();
        assert_eq!(
            a.text,
            "const A: f32 = 1.0;\nconst F: f32 = 2.0;\nconst T: f32 = 3.0;\nfn perlin() -> f32 { return A; }\nfn main() {}\n"
        );
        let paths: Vec<&str> = a.parts.iter().map(|p| p.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "shaders/k.wgsl",
                "shaders/common.wgsl",
                "shaders/include/utility/frame.wgsl",
                "shaders/include/types.inc.wgsl",
                "lib/noise/fn_perlin_noise.wgsl"
            ]
        );
        assert_eq!(a.locate(4), Some(("/proj/lib/noise/fn_perlin_noise.wgsl", 1)));
        assert_eq!(a.locate(5), Some(("/proj/shaders/k.wgsl", 5)));
        // Without `include`, #include lines are the compiler's business.
        let plain = run(&fs, &SourceSpec::default(), &[]).unwrap();
        assert!(plain.text.starts_with("#include \"common.wgsl\"\n"));
    }

    #[test]
    fn a_file_is_included_once_and_cycles_and_missing_files_name_the_chain() {
        let mut fs = files(&[
            ("shaders/k.wgsl", "// k\n#include \"a.wgsl\"\n#include \"b\"\n"),
            ("shaders/a.wgsl", "#include \"b\"\nconst A: f32 = 1.0;\n"),
            ("shaders/b.wgsl", "const B: f32 = 2.0;\n"),
        ]);
        let a = run(&fs, &includes(&[]), &[]).unwrap();
        assert_eq!(a.text, "// k\nconst B: f32 = 2.0;\nconst A: f32 = 1.0;\n\n", "b once, then an empty line");
        fs.insert("shaders/b.wgsl".into(), "\n\n#include \"a.wgsl\"\n".into());
        let e = run(&fs, &includes(&[]), &[]).unwrap_err();
        assert_eq!(
            e,
            "#include cycle: /proj/shaders/k.wgsl:2 -> /proj/shaders/a.wgsl:1 -> /proj/shaders/b.wgsl:3 -> \
             /proj/shaders/a.wgsl"
        );
        fs.insert("shaders/b.wgsl".into(), "#include <gone>\n".into());
        let e = run(&fs, &includes(&["inc"]), &[]).unwrap_err();
        assert!(
            e.starts_with("/proj/shaders/k.wgsl:2 -> /proj/shaders/a.wgsl:1 -> /proj/shaders/b.wgsl:1: #include \"gone\" not found; tried shaders/gone, shaders/gone.wgsl, inc/gone, inc/gone.wgsl"),
            "{e}"
        );
        fs.insert("shaders/b.wgsl".into(), "#include \"x.wgsl\" // why\n".into());
        let e = run(&fs, &includes(&[]), &[]).unwrap_err();
        assert!(e.contains("b.wgsl:1: #include \"x.wgsl\" // why: unexpected text after the file name"), "{e}");
    }

    #[test]
    fn joins_and_replacements_keep_each_line_traced() {
        let fs = files(&[
            (
                "shaders/k.wgsl",
                "var t: texture_storage_2d<##FORMAT##, write>;\nfn h(x: f32, y: f32) -> f32 {\n#heightCode\n}\n",
            ),
            ("shaders/noise.wgsl", "fn n() -> f32 { return 0.5; }"),
            ("shaders/common.wgsl", "const C: u32 = 1u;\n"),
        ]);
        let spec = SourceSpec {
            prepend: Some(vec!["shaders/noise.wgsl".into()]),
            append: Some(vec!["shaders/common.wgsl".into()]),
            replace: vec![
                ("##FORMAT##".into(), Replacement::Param("format".into())),
                ("#heightCode".into(), Replacement::Text("let s = sin(x);\nreturn s * cos(y);".into())),
            ],
            ..Default::default()
        };
        let a = run(&fs, &spec, &["rgba16float".into()]).unwrap();
        assert_eq!(
            a.text,
            "fn n() -> f32 { return 0.5; }\nvar t: texture_storage_2d<rgba16float, write>;\nfn h(x: f32, y: f32) -> f32 {\n\
             let s = sin(x);\nreturn s * cos(y);\n}\nconst C: u32 = 1u;\n"
        );
        assert_eq!(a.locate(1), Some(("/proj/shaders/noise.wgsl", 1)));
        assert_eq!(a.locate(5), Some(("/proj/shaders/k.wgsl", 3)), "the generated code is the replaced line's");
        assert_eq!(a.locate(6), Some(("/proj/shaders/k.wgsl", 4)));
        assert_eq!(a.locate(7), Some(("/proj/shaders/common.wgsl", 1)));
        assert_eq!(a.replaced[0], ("##FORMAT##".into(), "rgba16float".into()));
        let typo = SourceSpec { replace: vec![("{OUTPUT_FORMAT}".into(), Replacement::Text("r".into()))], ..spec };
        let a = run(&fs, &typo, &["rgba16float".into()]).unwrap();
        assert_eq!(a.unmatched, ["{OUTPUT_FORMAT}"], "left for the pass to refuse if no other file holds it");
        let files: Vec<&str> = a.parts.iter().map(|p| p.path.as_str()).collect();
        let e = unmatched_error("{OUTPUT_FORMAT}", &files);
        assert!(e.contains("\"{OUTPUT_FORMAT}\" is found in no file the pass reaches (shaders/noise.wgsl, shaders/k.wgsl, shaders/common.wgsl)"), "{e}");
        let missing = SourceSpec { prepend: Some(vec!["shaders/nope.wgsl".into()]), ..Default::default() };
        assert_eq!(
            run(&fs, &missing, &[]).unwrap_err(),
            "[source] prepend shaders/nope.wgsl not found under the project root"
        );
    }

    #[test]
    fn specs_parse_merge_and_refuse_bad_keys() {
        let t: toml::Table = toml::from_str(
            "include = [\"shaders/include/\"]\nreplace = { \"##F##\" = { param = \"format\" }, \"X\" = \"1\" }\n",
        )
        .unwrap();
        let kernel = SourceSpec::parse(&t).unwrap();
        assert_eq!(kernel.include, Some(vec!["shaders/include".to_string()]));
        assert_eq!(kernel.params(), ["format"]);
        let pass: toml::Table = toml::from_str("replace = { \"X\" = \"2\" }\nprepend = [\"a.wgsl\"]\n").unwrap();
        let m = kernel.merged(&SourceSpec::parse(&pass).unwrap());
        assert_eq!(m.include, kernel.include);
        assert_eq!(m.prepend, Some(vec!["a.wgsl".to_string()]));
        assert_eq!(m.replace[1], ("X".into(), Replacement::Text("2".into())));
        assert_ne!(m.id(), kernel.id());
        for (bad, want) in [
            ("inlcude = []", "unknown key inlcude"),
            ("prepend = [\"../x.wgsl\"]", "without .."),
            ("replace = { \"A\" = 1 }", "expected a string or { param = \"name\" }"),
            ("include = \"shaders\"", "expected a list of paths"),
            ("unknown = 1", "allowed: include, prepend, append, replace, packages"),
            ("packages = { a = \"../x\" }", "expected a folder under the project root"),
        ] {
            let e = SourceSpec::parse(&toml::from_str(bad).unwrap()).unwrap_err();
            assert!(e.contains(want), "{bad}: {e}");
        }
    }
}
