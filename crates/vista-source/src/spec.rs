//! The manifest's `[source]` table (kernel level, and per `[[pass]]`).

/// What a `replace` entry puts in place of its key.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Replacement {
    /// Literal text.
    Text(String),
    /// The value of a param: an enum's value name, a number's decimal text.
    Param(String),
}

/// How a pass's source is assembled. Every path is relative to the project
/// root, like a resource's `file`.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct SourceSpec {
    /// Turns on textual `#include` and lists the folders searched after the
    /// including file's own (`None`: `#include` is left to the compiler).
    pub include: Option<Vec<String>>,
    /// Files joined before the shader, in order.
    pub prepend: Option<Vec<String>>,
    /// Files joined after it.
    pub append: Option<Vec<String>>,
    /// Literal replacements applied after includes and joins, in order.
    pub replace: Vec<(String, Replacement)>,
    /// WESL packages: an import's first name -> its folder
    /// (`bevy_render = "shaders/bevy_render"`).
    pub packages: Vec<(String, String)>,
    /// Modules the host generates (`modules = { constants = { N = 3 } }`):
    /// each import path with its WGSL text, one `const` per entry.
    pub modules: Vec<(String, String)>,
    /// The project's own generator (`command = ["python3", "tools/t.py",
    /// "{shader}", "{out}"]`), run on the shader file before anything else;
    /// its output is the WGSL assembled and composed.
    pub command: Option<Vec<String>>,
    /// Files the command reads besides the shader (root-relative): they
    /// join the cache key and `--changed`/`watch` follow them.
    pub inputs: Option<Vec<String>>,
    /// How long the command may run, in milliseconds (default
    /// [`DEFAULT_COMMAND_TIMEOUT_MS`]).
    pub timeout_ms: Option<u64>,
}

/// The keys a `[source]` table may have.
pub const KEYS: [&str; 9] =
    ["include", "prepend", "append", "replace", "packages", "modules", "command", "inputs", "timeout"];

/// How long a `[source] command` may run unless `timeout` says: 30 s.
pub const DEFAULT_COMMAND_TIMEOUT_MS: u64 = 30_000;

/// The longest `timeout` allowed: 10 minutes.
const MAX_COMMAND_TIMEOUT_S: f64 = 600.0;

/// A `[source] command` with its inputs and timeout: how one shader file's
/// WGSL is generated.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Generator {
    /// The program and its arguments; `{shader}` becomes the shader's
    /// root-relative path, `{out}` the file the output is to be written to
    /// (without `{out}`, the command's standard output is the WGSL).
    pub command: Vec<String>,
    /// Root-relative files it reads besides the shader.
    pub inputs: Vec<String>,
    /// How long it may run.
    pub timeout_ms: u64,
}

impl Generator {
    /// The command as one line, for messages: `python3 tools/t.py {shader} {out}`.
    pub fn display(&self) -> String {
        self.command.join(" ")
    }

    /// The command, its inputs and its timeout, for telling two generators
    /// apart: `python3 t.py {shader} {out}, inputs a.json, timeout 60 s`.
    pub fn describe(&self) -> String {
        let inputs =
            if self.inputs.is_empty() { "no inputs".to_string() } else { format!("inputs {}", self.inputs.join(" ")) };
        format!("{}, {inputs}, timeout {} s", self.display(), self.timeout_ms as f64 / 1000.0)
    }
}

/// A `modules` entry: `name = { CONST = value, ... }` as the WGSL module
/// `#define_import_path name` of typed `const`s: a non-negative integer a
/// u32 (an engine's binding index), a negative one an i32, a number an
/// f32, a bool a bool. (naga drops abstract-typed consts from a module, so
/// an importer would not find them.)
fn module_text(name: &str, v: &toml::Value) -> Result<String, String> {
    let ident = |w: &str| {
        w.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
            && w.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
    };
    if !name.split("::").all(ident) {
        return Err(format!("[source] modules: {name} is not a module path (names joined by ::)"));
    }
    let table = v.as_table().ok_or_else(|| {
        format!("[source] modules: {name} = {v} is not valid; expected a table {{ NAME = number or bool }}")
    })?;
    let mut text = format!("#define_import_path {name}\n");
    for (key, value) in table {
        if !ident(key) {
            return Err(format!("[source] modules: {name}.{key} is not a WGSL name"));
        }
        let literal = match value {
            toml::Value::Integer(i) if u32::try_from(*i).is_ok() => format!("u32 = {i}u"),
            toml::Value::Integer(i) if i32::try_from(*i).is_ok() => format!("i32 = {i}i"),
            toml::Value::Float(f) if f.is_finite() && (f.abs() as f32).is_finite() => format!("f32 = {f:?}"),
            toml::Value::Boolean(b) => format!("bool = {b}"),
            other => {
                return Err(format!(
                    "[source] modules: {name}.{key} = {other} is not valid; expected an integer (i32 or u32), a \
                     number an f32 holds, or a bool"
                ));
            }
        };
        text.push_str(&format!("const {key}: {literal};\n"));
    }
    Ok(text)
}

impl SourceSpec {
    /// Parses a `[source]` table; errors name the key and what is allowed.
    pub fn parse(t: &toml::Table) -> Result<SourceSpec, String> {
        for k in t.keys() {
            if !KEYS.contains(&k.as_str()) {
                return Err(format!("[source]: unknown key {k}; allowed: {}", KEYS.join(", ")));
            }
        }
        let paths = |k: &str| -> Result<Option<Vec<String>>, String> {
            let Some(v) = t.get(k) else { return Ok(None) };
            let bad = || format!("[source] {k} = {v} is not valid; expected a list of paths under the project root");
            let list = v.as_array().ok_or_else(bad)?;
            let mut out = Vec::new();
            for item in list {
                let p = item.as_str().ok_or_else(bad)?;
                if p.is_empty() || p.starts_with('/') || p.split(['/', '\\']).any(|c| c == "..") {
                    return Err(format!(
                        "[source] {k}: \"{p}\" is not valid; expected a path relative to the project root, without .."
                    ));
                }
                out.push(p.trim_end_matches('/').to_string());
            }
            Ok(Some(out))
        };
        let mut replace = Vec::new();
        match t.get("replace") {
            None => {}
            Some(toml::Value::Table(r)) => {
                for (key, v) in r {
                    if key.is_empty() {
                        return Err("[source] replace: an empty key would match everywhere".into());
                    }
                    let value = match v {
                        toml::Value::String(s) => Replacement::Text(s.clone()),
                        toml::Value::Table(p) if p.len() == 1 && p.get("param").is_some_and(|n| n.is_str()) => {
                            Replacement::Param(p["param"].as_str().unwrap_or_default().to_string())
                        }
                        other => {
                            return Err(format!(
                                "[source] replace: \"{key}\" = {other} is not valid; expected a string or \
                                 {{ param = \"name\" }}"
                            ));
                        }
                    };
                    replace.push((key.clone(), value));
                }
            }
            Some(other) => {
                return Err(format!(
                    "[source] replace = {other} is not valid; expected a table {{ \"text\" = \"replacement\" }}"
                ));
            }
        }
        let mut packages = Vec::new();
        match t.get("packages") {
            None => {}
            Some(toml::Value::Table(p)) => {
                for (name, dir) in p {
                    let dir = dir.as_str().filter(|d| !d.is_empty() && !d.starts_with('/') && !d.contains(".."));
                    let Some(dir) = dir else {
                        return Err(format!(
                            "[source] packages: {name} = {} is not valid; expected a folder under the project root",
                            p[name]
                        ));
                    };
                    packages.push((name.clone(), dir.trim_end_matches('/').to_string()));
                }
            }
            Some(other) => {
                return Err(format!("[source] packages = {other} is not valid; expected {{ name = \"folder\" }}"));
            }
        }
        let modules = match t.get("modules") {
            None => Vec::new(),
            Some(toml::Value::Table(m)) => {
                m.iter().map(|(name, v)| Ok((name.clone(), module_text(name, v)?))).collect::<Result<_, String>>()?
            }
            Some(other) => {
                return Err(format!("[source] modules = {other} is not valid; expected {{ module = {{ NAME = 1 }} }}"));
            }
        };
        let command = match t.get("command") {
            None => None,
            Some(v) => {
                let words: Option<Vec<String>> =
                    v.as_array().and_then(|a| a.iter().map(|w| w.as_str().map(str::to_string)).collect());
                match words {
                    Some(w) if !w.is_empty() && !w[0].is_empty() => Some(w),
                    _ => {
                        return Err(format!(
                            "[source] command = {v} is not valid; expected a list of strings, the program first \
                             ([\"python3\", \"tools/render.py\", \"{{shader}}\", \"{{out}}\"])"
                        ));
                    }
                }
            }
        };
        let timeout_ms = match t.get("timeout") {
            None => None,
            Some(v) => {
                let s = v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
                match s {
                    Some(s) if s > 0.0 && s <= MAX_COMMAND_TIMEOUT_S => Some((s * 1000.0).ceil() as u64),
                    _ => {
                        return Err(format!(
                            "[source] timeout = {v} is not valid; expected seconds, more than 0 and at most \
                             {MAX_COMMAND_TIMEOUT_S}"
                        ));
                    }
                }
            }
        };
        let inputs = paths("inputs")?;
        if command.is_none() && (inputs.is_some() || timeout_ms.is_some()) {
            return Err("[source] inputs and timeout belong to a command; add command = [...]".into());
        }
        Ok(SourceSpec {
            include: paths("include")?,
            prepend: paths("prepend")?,
            append: paths("append")?,
            replace,
            packages,
            modules,
            command,
            inputs,
            timeout_ms,
        })
    }

    /// `pass` over `self` (the kernel's): a key the pass gives replaces the
    /// kernel's, and `replace` tables merge, the pass's entries winning.
    pub fn merged(&self, pass: &SourceSpec) -> SourceSpec {
        let mut replace: Vec<(String, Replacement)> =
            self.replace.iter().filter(|(k, _)| !pass.replace.iter().any(|(p, _)| p == k)).cloned().collect();
        replace.extend(pass.replace.iter().cloned());
        SourceSpec {
            include: pass.include.clone().or_else(|| self.include.clone()),
            prepend: pass.prepend.clone().or_else(|| self.prepend.clone()),
            append: pass.append.clone().or_else(|| self.append.clone()),
            replace,
            packages: if pass.packages.is_empty() { self.packages.clone() } else { pass.packages.clone() },
            modules: if pass.modules.is_empty() { self.modules.clone() } else { pass.modules.clone() },
            command: pass.command.clone().or_else(|| self.command.clone()),
            inputs: pass.inputs.clone().or_else(|| self.inputs.clone()),
            timeout_ms: pass.timeout_ms.or(self.timeout_ms),
        }
    }

    /// Whether the spec assembles nothing (no `[source]` at all, or only a
    /// `command`, which runs before assembly: [`SourceSpec::generator`]).
    pub fn is_empty(&self) -> bool {
        SourceSpec { command: None, inputs: None, timeout_ms: None, ..self.clone() } == SourceSpec::default()
    }

    /// The `command` that generates the shader's text, if any.
    pub fn generator(&self) -> Option<Generator> {
        Some(Generator {
            command: self.command.clone()?,
            inputs: self.inputs.clone().unwrap_or_default(),
            timeout_ms: self.timeout_ms.unwrap_or(DEFAULT_COMMAND_TIMEOUT_MS),
        })
    }

    /// A short stable name for this spec: composed names carry it, so one
    /// module is composed per distinct (file, defs, source) set.
    pub fn id(&self) -> String {
        // The text hashed before `modules` existed, so that a spec without
        // them keeps its id (and its composed name).
        // A command runs before assembly and is not part of it.
        let SourceSpec { include, prepend, append, replace, packages, modules, .. } = self;
        let mut text = format!(
            "SourceSpec {{ include: {include:?}, prepend: {prepend:?}, append: {append:?}, replace: {replace:?}, \
             packages: {packages:?} }}"
        );
        if !modules.is_empty() {
            text.push_str(&format!("{modules:?}"));
        }
        blake3::hash(text.as_bytes()).to_hex()[..8].to_string()
    }

    /// The params its replacements read, in order.
    pub fn params(&self) -> Vec<&str> {
        self.replace
            .iter()
            .filter_map(|(_, v)| match v {
                Replacement::Param(p) => Some(p.as_str()),
                Replacement::Text(_) => None,
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spec as it was before `modules`: its derived Debug text is what
    /// ids hashed then.
    mod before {
        #[derive(Debug)]
        #[allow(dead_code)]
        pub struct SourceSpec {
            pub include: Option<Vec<String>>,
            pub prepend: Option<Vec<String>>,
            pub append: Option<Vec<String>>,
            pub replace: Vec<(String, super::Replacement)>,
            pub packages: Vec<(String, String)>,
        }
    }

    #[test]
    fn a_spec_without_modules_keeps_its_id_and_modules_change_it() {
        let t: toml::Table = toml::from_str("include = [\"shaders/inc\"]\nreplace = { \"{N}\" = \"4\" }\n").unwrap();
        let spec = SourceSpec::parse(&t).unwrap();
        let old = before::SourceSpec {
            include: spec.include.clone(),
            prepend: None,
            append: None,
            replace: spec.replace.clone(),
            packages: Vec::new(),
        };
        assert_eq!(spec.id(), blake3::hash(format!("{old:?}").as_bytes()).to_hex()[..8].to_string());
        let t: toml::Table = toml::from_str(
            "include = [\"shaders/inc\"]\nreplace = { \"{N}\" = \"4\" }\nmodules = { constants = { LUT = 3, GAIN = 0.5, ON = true } }\n",
        )
        .unwrap();
        let with = SourceSpec::parse(&t).unwrap();
        assert_ne!(with.id(), spec.id());
        assert_eq!(
            with.modules,
            [(
                "constants".to_string(),
                "#define_import_path constants\nconst LUT: u32 = 3u;\nconst GAIN: f32 = 0.5;\nconst ON: bool = true;\n"
                    .to_string()
            )]
        );
    }

    #[test]
    fn bad_modules_are_named() {
        let err = |text: &str| SourceSpec::parse(&toml::from_str(text).unwrap()).unwrap_err();
        assert!(err("modules = { c = { X = \"a\" } }").contains("modules: c.X = \"a\" is not valid"));
        assert!(err("modules = { c = { X = 5000000000 } }").contains("expected an integer (i32 or u32)"));
        assert!(err("modules = { \"a b\" = { X = 1 } }").contains("a b is not a module path"));
        assert!(err("modules = { c = { \"1x\" = 1 } }").contains("c.1x is not a WGSL name"));
    }
}

#[cfg(test)]
mod command_tests {
    use super::*;

    fn parse(text: &str) -> Result<SourceSpec, String> {
        SourceSpec::parse(&toml::from_str(text).unwrap())
    }

    #[test]
    fn a_command_runs_before_assembly_and_merges_per_key() {
        let kernel =
            parse("command = [\"python3\", \"tools/t.py\", \"{shader}\"]\ninputs = [\"tools/blur.json\"]\n").unwrap();
        // Only a command: nothing to assemble, and no new assembly id.
        assert!(kernel.is_empty());
        assert_eq!(kernel.id(), SourceSpec::default().id());
        let g = kernel.generator().unwrap();
        assert_eq!(g.inputs, ["tools/blur.json"]);
        assert_eq!(g.timeout_ms, DEFAULT_COMMAND_TIMEOUT_MS);
        assert_eq!(g.display(), "python3 tools/t.py {shader}");
        let pass = parse("timeout = 2.5").unwrap_err();
        assert!(pass.contains("inputs and timeout belong to a command"), "{pass}");
        let pass = parse("command = [\"sh\", \"gen.sh\"]\ntimeout = 2.5").unwrap();
        let m = kernel.merged(&pass);
        let g = m.generator().unwrap();
        assert_eq!((g.command[0].as_str(), g.inputs.len(), g.timeout_ms), ("sh", 1, 2500));
        assert!(SourceSpec::default().generator().is_none());
    }

    #[test]
    fn bad_commands_are_named() {
        assert!(parse("command = []").unwrap_err().contains("[source] command = [] is not valid"));
        assert!(parse("command = \"python3 t.py\"").unwrap_err().contains("expected a list of strings"));
        assert!(parse("command = [\"a\"]\ntimeout = 0").unwrap_err().contains("[source] timeout = 0 is not valid"));
        assert!(parse("command = [\"a\"]\ntimeout = 601").unwrap_err().contains("at most 600"));
        assert!(parse("command = [\"a\"]\ninputs = [\"../x\"]").unwrap_err().contains("[source] inputs: \"../x\""));
    }
}
