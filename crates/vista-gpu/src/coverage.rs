//! A kernel file composed for a coverage run (SPEC 20): the module with
//! vista-coverage's counters, and each counted statement's file and line.
//!
//! naga's spans are byte offsets into the text it parsed. A file naga
//! parses directly (or an assembly of files) maps them through that text;
//! a file naga_oil composes puts each imported module's index in a span's
//! top bits and, below them, the offset into that module's own parse text:
//! a generated header, then the module's preprocessed source. The
//! preprocessor keeps every line (it blanks the ones it drops), so the
//! offset of the source within that text is found from one declaration
//! whose span and name are known (`fn name`, `var name`, `const name`).

use std::collections::HashMap;

use naga::Span;
use vista_coverage::{Counter, Counts, Place};

/// naga_oil's `SPAN_SHIFT`: a composed span's module index sits above it.
const SPAN_SHIFT: usize = 21;

/// A kernel file's counters and where each counted statement lies.
#[derive(Debug)]
pub struct Coverage {
    /// Counter i is element i of the counter buffer.
    pub counters: Vec<Counter>,
    /// The group the counter buffer binds at (binding 0): one past the
    /// highest the kernel binds.
    pub group: u32,
    /// Functions a vertex entry reaches, where the vertex stage may not
    /// write storage: not measured.
    pub not_measured: Vec<String>,
    places: HashMap<(usize, usize), Place>,
    /// Each counted function: its declaration, its name as written, the
    /// counter of its body's start.
    functions: Vec<(Place, String, usize)>,
}

impl Coverage {
    /// The counter buffer's size in bytes (at least one word).
    pub fn buffer_size(&self) -> u64 {
        4 * self.counters.len().max(1) as u64
    }

    /// Adds one run's counter values (the buffer's words) to `counts`.
    pub fn add(&self, counts: &mut Counts, values: &[u32]) {
        counts.add(&self.counters, values, &|s: Span| {
            s.to_range().and_then(|r| self.places.get(&(r.start, r.end))).cloned()
        });
        counts.add_functions(&self.functions, values);
    }

    /// Every measured line and arm of the file, none of them run: what a
    /// kernel no case reaches counts.
    pub fn unrun(&self) -> Counts {
        let mut counts = Counts::default();
        self.add(&mut counts, &vec![0; self.counters.len()]);
        counts
    }
}

/// Where the spans of a composed module point.
#[derive(Debug)]
pub(crate) enum Origins {
    /// naga parsed `text` directly: `file`'s own, or an assembly of files
    /// (a compiler's output traced to its modules' files; neither: a
    /// command's output, or a compiler's not traced: not measured).
    Direct { text: String, file: Option<String>, assembled: Option<vista_source::Assembled> },
    /// naga_oil composed it: each module index's file (none for a
    /// generated module) and preprocessed source (index 0: the kernel).
    Composed { modules: HashMap<usize, (Option<String>, String)> },
}

/// The end of a `.wesl` kernel's origin once compiled: its text is the
/// compiler's (coverage follows its lines back to the modules' files).
pub(crate) const COMPILED_BY_WESL: &str = " (as the wesl crate compiled it)";

/// Whether coverage measures the lines of a text of this origin: not a
/// command's or the wesl crate's output as a whole, a generated module, or
/// one of vista's built-in modules the project does not have (no file of
/// the project to show it in).
pub(crate) fn measured(origin: &str) -> bool {
    !(origin.ends_with("` generated it)")
        || origin.ends_with(COMPILED_BY_WESL)
        || origin.starts_with("<generated>")
        || origin.starts_with("<built-in>"))
}

/// `module` instrumented, and its counters placed through `origins`.
pub(crate) fn instrument(module: &naga::Module, origins: &Origins, vertex: bool) -> (naga::Module, Coverage) {
    let group = module.global_variables.iter().filter_map(|(_, g)| g.binding.as_ref().map(|b| b.group + 1)).max();
    let done = vista_coverage::instrument(module, group.unwrap_or(0), vertex);
    let spans = done.counters.iter().flat_map(|c| c.spans.iter().copied().chain(c.arm.map(|a| a.at)));
    let placer = Placer::new(module, origins);
    let places = spans
        .filter_map(|s| {
            let r = s.to_range()?;
            Some(((r.start, r.end), placer.place(r.start)?))
        })
        .collect();
    // A function's counters are contiguous, its body's start first; its
    // declaration is found in the text one of its statements lies in.
    let mut functions = Vec::new();
    for (i, c) in done.counters.iter().enumerate() {
        if i > 0 && done.counters[i - 1].function == c.function {
            continue;
        }
        let mine = done.counters[i..].iter().take_while(|d| d.function == c.function);
        let start = mine.flat_map(|d| d.spans.iter()).find_map(|s| s.to_range()).map(|r| r.start);
        let name = vista_source::undecorate(&c.function).0;
        // An imported function keeps its decorated name in a compiler's output (WESL).
        let declared = |s| placer.declaration_of(&name, s).or_else(|| placer.declaration_of(&c.function, s));
        if let Some(at) = start.and_then(declared) {
            functions.push((at, name, i));
        }
    }
    let coverage = Coverage {
        counters: done.counters,
        group: done.binding.group,
        not_measured: done.not_measured,
        places,
        functions,
    };
    (done.module, coverage)
}

/// Maps a span's start to a file, line and column.
struct Placer<'a> {
    origins: &'a Origins,
    /// Per module index: where its source starts in naga's parse text.
    starts: HashMap<usize, usize>,
}

impl<'a> Placer<'a> {
    fn new(module: &naga::Module, origins: &'a Origins) -> Placer<'a> {
        let mut starts = HashMap::new();
        if let Origins::Composed { modules } = origins {
            for (&index, (_, text)) in modules {
                if let Some(start) = source_start(module, index, text) {
                    starts.insert(index, start);
                }
            }
        }
        Placer { origins, starts }
    }

    /// Where `fn name` is declared in the text that span start `within`
    /// lies in.
    fn declaration_of(&self, name: &str, within: usize) -> Option<Place> {
        let at = match self.origins {
            Origins::Direct { text, .. } => declaration(text, "fn", name)?,
            Origins::Composed { modules } => {
                let index = within >> SPAN_SHIFT;
                declaration(&modules.get(&index)?.1, "fn", name)? + self.starts.get(&index)? + (index << SPAN_SHIFT)
            }
        };
        self.place(at)
    }

    fn place(&self, start: usize) -> Option<Place> {
        match self.origins {
            Origins::Direct { text, file, assembled } => {
                let (line, col) = line_col(text, start)?;
                match assembled {
                    None => Some(Place { file: file.clone()?, line, col }),
                    Some(a) => {
                        let (part, at) = a.locate_part(line as usize)?;
                        measured(&part.origin).then(|| Place { file: part.path.clone(), line: at as u32, col })
                    }
                }
            }
            Origins::Composed { modules } => {
                let index = start >> SPAN_SHIFT;
                let (file, text) = modules.get(&index)?;
                let offset = (start & ((1 << SPAN_SHIFT) - 1)).checked_sub(*self.starts.get(&index)?)?;
                let (line, col) = line_col(text, offset)?;
                Some(Place { file: file.clone()?, line, col })
            }
        }
    }
}

/// 1-based line and column of byte `offset` of `text`.
fn line_col(text: &str, offset: usize) -> Option<(u32, u32)> {
    let before = text.get(..offset)?;
    let line = before.matches('\n').count() + 1;
    let col = offset - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    Some((line as u32, col as u32))
}

/// Where module `index`'s source starts in naga's parse text: a
/// declaration's span start less the place of its keyword in `text`.
fn source_start(module: &naga::Module, index: usize, text: &str) -> Option<usize> {
    let ours =
        |s: Span| s.to_range().filter(|r| r.start >> SPAN_SHIFT == index).map(|r| r.start & ((1 << SPAN_SHIFT) - 1));
    let functions = module.functions.iter().map(|(h, f)| ("fn", f.name.as_deref(), module.functions.get_span(h)));
    let globals =
        module.global_variables.iter().map(|(h, g)| ("var", g.name.as_deref(), module.global_variables.get_span(h)));
    let constants = module.constants.iter().map(|(h, c)| ("const", c.name.as_deref(), module.constants.get_span(h)));
    functions.chain(globals).chain(constants).find_map(|(keyword, name, span)| {
        let at = ours(span)?;
        let found = declaration(text, keyword, &vista_source::undecorate(name?).0)?;
        at.checked_sub(found)
    })
}

/// The offset of `keyword` in the one declaration `keyword [<...>] name`
/// of `text` (none when the name is declared so twice: ambiguous).
fn declaration(text: &str, keyword: &str, name: &str) -> Option<usize> {
    let word = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut found = None;
    for (at, _) in text.match_indices(name) {
        let after = text[at + name.len()..].chars().next();
        if text[..at].ends_with(word) || after.is_some_and(word) {
            continue;
        }
        let mut before = text[..at].trim_end();
        if keyword == "var" && before.ends_with('>') {
            before = before[..before.rfind('<')?].trim_end();
        }
        if before.ends_with(keyword) && !before[..before.len() - keyword.len()].ends_with(word) {
            if found.is_some() {
                return None;
            }
            found = Some(before.len() - keyword.len());
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declarations_are_found_by_keyword_and_whole_name() {
        let text = "const K = 1.0;\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\nfn outer() {}\nfn out2() {}";
        assert_eq!(declaration(text, "const", "K"), Some(0));
        assert_eq!(declaration(text, "var", "out"), Some(text.find("var").unwrap()));
        assert_eq!(declaration(text, "fn", "outer"), Some(text.find("fn outer").unwrap()));
        assert_eq!(declaration(text, "fn", "out"), None, "no fn named out");
        assert_eq!(declaration("fn a() {}\nfn  a() {}", "fn", "a"), None, "two: ambiguous");
        assert_eq!(vista_source::undecorate("fbmX_naga_oil_mod_XNV4TUOTMNFRAX").0, "fbm");
        assert_eq!(line_col("ab\ncd", 4), Some((2, 2)));
        assert_eq!(line_col("ab", 9), None);
    }

    /// Each counted line of `name` in `set`, as (file, line) pairs, sorted.
    fn counted_lines(set: &crate::ShaderSet, name: &str) -> Vec<(String, u32)> {
        let cov = set.covered(false).coverage(name).unwrap();
        let mut counts = Counts::default();
        cov.add(&mut counts, &vec![1; cov.counters.len()]);
        let mut out: Vec<(String, u32)> = counts
            .files()
            .into_iter()
            .flat_map(|f| counts.lines(&f).into_iter().map(move |(l, _)| (f.clone(), l)))
            .collect();
        out.sort();
        out
    }

    const LIB: &str = "#define_import_path my::lib\n\nconst K: f32 = 2.0;\n// two\nfn helper(x: f32) -> f32 {\n    let y = x * K;\n    if y > 1.0 {\n        return y;\n    }\n    return 0.0;\n}\n";

    #[test]
    fn composed_statements_are_placed_on_their_own_files_lines() {
        // Statement lines worked by hand: the kernel's 6, 10 and 11, the
        // module's 6 (a let), 7 (the if), 8 and 10 (the returns).
        let kernel = "#import my::lib::helper\n\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\nfn local(v: f32) -> f32 {\n  return my::lib::helper(v) + 1.0;\n}\n@compute @workgroup_size(1)\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {\n    let v = local(f32(id.x));\n    out[id.x] = v;\n}\n";
        let set = crate::ShaderSet::from_files(
            "test",
            [
                ("lib/my.wgsl".to_string(), LIB.to_string(), "/p/shaders/lib/my.wgsl".to_string()),
                ("k.wgsl".to_string(), kernel.to_string(), "/p/shaders/k.wgsl".to_string()),
            ],
        );
        let lines = counted_lines(&set, "k.wgsl");
        let want: Vec<(String, u32)> = [("shaders/k.wgsl", 6), ("shaders/k.wgsl", 10), ("shaders/k.wgsl", 11)]
            .into_iter()
            .chain([
                ("shaders/lib/my.wgsl", 6),
                ("shaders/lib/my.wgsl", 7),
                ("shaders/lib/my.wgsl", 8),
                ("shaders/lib/my.wgsl", 10),
            ])
            .map(|(f, l)| (f.to_string(), l))
            .collect();
        assert_eq!(lines, want);
        let cov = set.covered(false).coverage("k.wgsl").unwrap();
        assert_eq!(cov.group, 1, "one past the kernel's highest group");
        assert!(set.coverage("k.wgsl").is_err(), "a judged set has no counters");
        assert_ne!(set.source_hash("k.wgsl").unwrap(), set.covered(false).source_hash("k.wgsl").unwrap());
    }

    #[test]
    fn directly_parsed_statements_are_placed_on_the_files_lines() {
        let kernel = "@group(2) @binding(0) var<storage, read_write> out: array<f32>;\n@compute @workgroup_size(1)\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {\n    if id.x > 3u {\n        out[id.x] = 1.0;\n    } else {\n        out[id.x] = 2.0;\n    }\n}\n";
        let set = crate::ShaderSet::from_files("test", [("k.wgsl".into(), kernel.into(), "/p/shaders/k.wgsl".into())]);
        let lines: Vec<u32> = counted_lines(&set, "k.wgsl").into_iter().map(|(_, l)| l).collect();
        assert_eq!(lines, [4, 5, 7]);
        assert_eq!(set.covered(false).coverage("k.wgsl").unwrap().group, 3);
    }

    /// A command's output is not the user's lines: nothing of it is
    /// measured. The wesl crate's output is traced back to each module's
    /// own lines (never a count on a line the file lacks).
    #[test]
    fn generated_text_is_not_measured_and_compiled_wesl_is_traced() {
        let kernel = "@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n@compute @workgroup_size(1)\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {\n    if id.x > 3u {\n        out[id.x] = 1.0;\n    }\n}\n";
        let origin = crate::generated_origin("/p/shaders/k.tmpl", "python3 t.py {shader}");
        let set = crate::ShaderSet::from_files("test", [("k.tmpl".into(), kernel.into(), origin)]);
        assert!(counted_lines(&set, "k.tmpl").is_empty());
        // The same text as WGSL and as WESL counts the same lines.
        let set = crate::ShaderSet::from_files("test", [("k.wgsl".into(), kernel.into(), "/p/shaders/k.wgsl".into())]);
        let wgsl: Vec<u32> = counted_lines(&set, "k.wgsl").into_iter().map(|(_, l)| l).collect();
        let set = crate::ShaderSet::from_files("test", [("k.wesl".into(), kernel.into(), "/p/shaders/k.wesl".into())]);
        let wesl = counted_lines(&set, "k.wesl");
        assert_eq!(wesl.iter().map(|(_, l)| *l).collect::<Vec<_>>(), wgsl);
        assert_eq!(wesl, [("shaders/k.wesl".to_string(), 4), ("shaders/k.wesl".to_string(), 5)]);
        // An imported module's statements on its own file's lines (worked
        // by hand: the kernel's 4 and 5, the module's 3, 5 and 6).
        let kernel = "import package::m::twice;\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n@compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {\n    let v = twice(f32(id.x));\n    out[id.x] = v;\n}\n";
        let module = "// doubles\nfn twice(x: f32) -> f32 {\n    var y = x;\n    // the other half\n    y += x;\n    return y;\n}\n";
        let set = crate::ShaderSet::from_files(
            "test",
            [
                ("k.wesl".into(), kernel.into(), "/p/shaders/k.wesl".into()),
                ("m.wesl".into(), module.into(), "/p/shaders/m.wesl".into()),
            ],
        );
        let k = |l: u32| ("shaders/k.wesl".to_string(), l);
        let m = |l: u32| ("shaders/m.wesl".to_string(), l);
        assert_eq!(counted_lines(&set, "k.wesl"), [k(4), k(5), m(3), m(5), m(6)]);
    }
}
