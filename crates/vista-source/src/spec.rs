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
}

/// The keys a `[source]` table may have.
pub const KEYS: [&str; 5] = ["include", "prepend", "append", "replace", "packages"];

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
        Ok(SourceSpec {
            include: paths("include")?,
            prepend: paths("prepend")?,
            append: paths("append")?,
            replace,
            packages,
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
        }
    }

    /// Whether the spec changes nothing (no `[source]` at all).
    pub fn is_empty(&self) -> bool {
        *self == SourceSpec::default()
    }

    /// A short stable name for this spec: composed names carry it, so one
    /// module is composed per distinct (file, defs, source) set.
    pub fn id(&self) -> String {
        blake3::hash(format!("{self:?}").as_bytes()).to_hex()[..8].to_string()
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
