//! Named, typed, range-checked kernel parameters.
//!
//! Every kernel declares its parameters as data in its manifest
//! (`ParamSpec`: name, WGSL-facing type, kind with its allowed range,
//! default and a one-line doc). `vista list`, `--set`, presets, golden cases
//! and the manifest's params hash all go through this one table, so a value
//! is validated the same way wherever it comes from.

use std::collections::BTreeMap;
use std::fmt;

use crate::ParamError;

/// The kind of a parameter and its allowed range (inclusive unless noted).
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// A real number in `[min, max]`, or `(min, max]` when `open_min`.
    Float {
        /// The smallest value allowed (excluded when `open_min`).
        min: f64,
        /// The largest value allowed.
        max: f64,
        /// Whether `min` itself is excluded.
        open_min: bool,
    },
    /// An integer in `[min, max]`.
    Int {
        /// The smallest value allowed.
        min: i64,
        /// The largest value allowed.
        max: i64,
    },
    /// `n` comma-separated reals, each in `[min, max]`.
    Vector {
        /// The number of components.
        n: usize,
        /// The smallest value allowed for each component.
        min: f64,
        /// The largest value allowed for each component.
        max: f64,
    },
    /// `n` comma-separated integers, each in `[min, max]`.
    IntVector {
        /// The number of components.
        n: usize,
        /// The smallest value allowed for each component.
        min: i64,
        /// The largest value allowed for each component.
        max: i64,
    },
    /// One name out of a fixed list.
    Enum(Vec<String>),
    /// true | false (also 1 | 0).
    Bool,
}

/// The scalar of a WGSL leaf.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    /// WGSL `f32`.
    F32,
    /// WGSL `u32`.
    U32,
    /// WGSL `i32`.
    I32,
}

impl Scalar {
    /// The WGSL spelling: `f32`, `u32` or `i32`.
    pub fn wgsl(self) -> &'static str {
        match self {
            Scalar::F32 => "f32",
            Scalar::U32 => "u32",
            Scalar::I32 => "i32",
        }
    }
}

/// A uniform leaf spelled as WGSL spells it: `vec2<u32>`, `mat4x4<f32>`,
/// `array<vec4<f32>, 4>`: its scalar, its number of components, and its
/// normalised WGSL name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Leaf {
    /// The scalar of every component.
    pub scalar: Scalar,
    /// The number of scalar components (e.g. 16 for `mat4x4<f32>` or
    /// `array<vec4<f32>, 4>`).
    pub count: usize,
    /// The normalised WGSL type name, e.g. `vec2<u32>`.
    pub name: String,
}

/// Parses a WGSL type a uniform leaf may have: a scalar, `vecN<T>` (or
/// `vecNf|u|i`), `matCxR<f32>` (or `matCxRf`), or `array<T, N>` of those.
/// Returns the scalar, the component count and the normalised name.
pub fn wgsl_leaf(text: &str) -> Option<(Scalar, usize, String)> {
    let t: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    let scalar = |s: &str| match s {
        "f32" | "f" => Some(Scalar::F32),
        "u32" | "u" => Some(Scalar::U32),
        "i32" | "i" => Some(Scalar::I32),
        _ => None,
    };
    if let Some(sc) = scalar(&t).filter(|_| t.len() == 3) {
        return Some((sc, 1, sc.wgsl().to_string()));
    }
    if let Some(inner) = t.strip_prefix("array<").and_then(|r| r.strip_suffix('>')) {
        let (elem, n) = inner.rsplit_once(',')?;
        let n: usize = n.parse().ok().filter(|n| (1..=1024).contains(n))?;
        let (sc, c, name) = wgsl_leaf(elem)?;
        if name.starts_with("array") {
            return None;
        }
        return Some((sc, c * n, format!("array<{name}, {n}>")));
    }
    if let Some(rest) = t.strip_prefix("vec") {
        let n: usize = rest.get(..1)?.parse().ok().filter(|n| (2..=4).contains(n))?;
        let sc = match &rest[1..] {
            r if r.starts_with('<') && r.ends_with('>') => scalar(&r[1..r.len() - 1])?,
            r => scalar(r)?,
        };
        return Some((sc, n, format!("vec{n}<{}>", sc.wgsl())));
    }
    if let Some(rest) = t.strip_prefix("mat") {
        let c: usize = rest.get(..1)?.parse().ok().filter(|n| (2..=4).contains(n))?;
        let r: usize = rest.get(2..3)?.parse().ok().filter(|n| (2..=4).contains(n))?;
        if rest.get(1..2) != Some("x") || !matches!(&rest[3..], "<f32>" | "f") {
            return None;
        }
        return Some((Scalar::F32, c * r, format!("mat{c}x{r}<f32>")));
    }
    None
}

/// The manifest's `type`: what the WGSL `Params` field must be.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ParamType {
    /// WGSL `u32`.
    U32,
    /// WGSL `i32`.
    I32,
    /// WGSL `f32`.
    F32,
    /// Carried as u32 (0 or 1).
    Bool,
    /// `vecN<f32>`, N in 2..=4.
    Vec(u8),
    /// Carried as the u32 index of the value in its list.
    Enum,
    /// A leaf spelled in WGSL (integer vectors, matrices, arrays).
    Wgsl(Leaf),
}

impl ParamType {
    /// Parses the manifest's `type`: `u32`, `i32`, `f32`, `bool`, `vec2` to
    /// `vec4`, `enum`, or a WGSL leaf type ([`wgsl_leaf`]); `None` otherwise.
    pub fn from_name(name: &str) -> Option<ParamType> {
        Some(match name {
            "u32" => ParamType::U32,
            "i32" => ParamType::I32,
            "f32" => ParamType::F32,
            "bool" => ParamType::Bool,
            "vec2" => ParamType::Vec(2),
            "vec3" => ParamType::Vec(3),
            "vec4" => ParamType::Vec(4),
            "enum" => ParamType::Enum,
            other => {
                let (scalar, count, name) = wgsl_leaf(other)?;
                match (scalar, count, name.as_str()) {
                    (Scalar::F32, 1, "f32") => ParamType::F32,
                    (Scalar::U32, 1, "u32") => ParamType::U32,
                    (Scalar::I32, 1, "i32") => ParamType::I32,
                    (Scalar::F32, n, v) if v.starts_with("vec") => ParamType::Vec(n as u8),
                    _ => ParamType::Wgsl(Leaf { scalar, count, name }),
                }
            }
        })
    }

    /// The WGSL type of the field this param feeds.
    pub fn wgsl(&self) -> String {
        match self {
            ParamType::U32 | ParamType::Bool | ParamType::Enum => "u32".into(),
            ParamType::I32 => "i32".into(),
            ParamType::F32 => "f32".into(),
            ParamType::Vec(n) => format!("vec{n}<f32>"),
            ParamType::Wgsl(l) => l.name.clone(),
        }
    }

    /// The manifest's name of this type.
    pub fn name(&self) -> &str {
        match self {
            ParamType::U32 => "u32",
            ParamType::I32 => "i32",
            ParamType::F32 => "f32",
            ParamType::Bool => "bool",
            ParamType::Vec(2) => "vec2",
            ParamType::Vec(3) => "vec3",
            ParamType::Vec(_) => "vec4",
            ParamType::Enum => "enum",
            ParamType::Wgsl(l) => &l.name,
        }
    }
}

impl Kind {
    /// A real in `[min, max]`.
    pub const fn float(min: f64, max: f64) -> Kind {
        Kind::Float { min, max, open_min: false }
    }
    /// A real in `(min, max]` (the minimum itself not allowed).
    pub const fn float_open(min: f64, max: f64) -> Kind {
        Kind::Float { min, max, open_min: true }
    }
    /// An integer in `[min, max]`.
    pub const fn int(min: i64, max: i64) -> Kind {
        Kind::Int { min, max }
    }

    /// The allowed range as users read it in errors and in `vista list`.
    pub fn range_text(&self) -> String {
        match *self {
            Kind::Float { min, max, open_min } => {
                format!("{}{min}, {max}]", if open_min { "(" } else { "[" })
            }
            Kind::Int { min, max } => format!("integer in [{min}, {max}]"),
            Kind::Vector { n, min, max } => {
                format!("{n} comma-separated numbers each in [{min}, {max}]")
            }
            Kind::IntVector { n, min, max } => {
                format!("{n} comma-separated integers each in [{min}, {max}]")
            }
            Kind::Enum(ref names) => format!("one of {}", names.join("|")),
            Kind::Bool => "true|false".into(),
        }
    }
}

/// One declared parameter.
#[derive(Debug, Clone)]
pub struct ParamSpec {
    /// The parameter's name (`--set NAME=VALUE`); it also names the uniform
    /// leaf (bare or as `variable.path`) or `override` it feeds, if any.
    pub name: String,
    /// The manifest's `type`: what the WGSL field it feeds must be.
    pub ty: ParamType,
    /// What values it takes, with their allowed range.
    pub kind: Kind,
    /// The default value as text (validated when the manifest is parsed).
    pub default: String,
    /// One line for `vista list`.
    pub doc: String,
    /// An enum's values that also set a shader def: (value, def name),
    /// the manifest's `defs = { aces = "TONEMAP_METHOD_ACES" }`.
    pub defs: Vec<(String, String)>,
}

/// A named set of overrides on top of the defaults.
#[derive(Debug, Clone)]
pub struct Preset {
    /// The preset's name (`--preset`).
    pub name: String,
    /// One line saying what the preset is for.
    pub doc: String,
    /// `(param, value)` pairs as text, applied over the defaults.
    pub set: Vec<(String, String)>,
}

/// A parsed, validated parameter value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A real ([`Kind::Float`]).
    Float(f64),
    /// An integer ([`Kind::Int`]).
    Int(i64),
    /// The components of a [`Kind::Vector`] or [`Kind::IntVector`] (integers held as f64).
    Vector(Vec<f64>),
    /// The chosen name out of a [`Kind::Enum`] list.
    Enum(String),
    /// A [`Kind::Bool`] value.
    Bool(bool),
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Float(v) => write!(f, "{v}"),
            Value::Int(v) => write!(f, "{v}"),
            Value::Vector(v) => f.write_str(&v.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(",")),
            Value::Enum(s) => f.write_str(s),
            Value::Bool(b) => write!(f, "{b}"),
        }
    }
}

/// Parses `text` as a value of `spec`, checking its range.
pub fn parse_value(spec: &ParamSpec, text: &str) -> Result<Value, ParamError> {
    let t = text.trim();
    let bad =
        |expected: String| ParamError::BadValue { param: spec.name.to_string(), value: text.to_string(), expected };
    let out_of_range = || ParamError::OutOfRange {
        param: spec.name.to_string(),
        value: text.to_string(),
        range: spec.kind.range_text(),
    };
    let real = |s: &str| -> Result<f64, ParamError> {
        let v: f64 = s.trim().parse().map_err(|_| bad(format!("a number, {}", spec.kind.range_text())))?;
        if v.is_finite() { Ok(v) } else { Err(bad(format!("a finite number, {}", spec.kind.range_text()))) }
    };
    match spec.kind {
        Kind::Float { min, max, open_min } => {
            let v = real(t)?;
            let low_ok = if open_min { v > min } else { v >= min };
            if low_ok && v <= max { Ok(Value::Float(v)) } else { Err(out_of_range()) }
        }
        Kind::Int { min, max } => {
            let v: i64 = t.parse().map_err(|_| bad(spec.kind.range_text()))?;
            if (min..=max).contains(&v) { Ok(Value::Int(v)) } else { Err(out_of_range()) }
        }
        Kind::Vector { n, min, max } => {
            let parts: Vec<&str> = t.split(',').collect();
            if parts.len() != n {
                return Err(bad(spec.kind.range_text()));
            }
            let v = parts.into_iter().map(real).collect::<Result<Vec<f64>, _>>()?;
            if v.iter().all(|c| (min..=max).contains(c)) { Ok(Value::Vector(v)) } else { Err(out_of_range()) }
        }
        Kind::IntVector { n, min, max } => {
            let parts: Vec<&str> = t.split(',').collect();
            if parts.len() != n {
                return Err(bad(spec.kind.range_text()));
            }
            let v = parts
                .into_iter()
                .map(|p| p.trim().parse::<i64>().map_err(|_| bad(spec.kind.range_text())))
                .collect::<Result<Vec<i64>, _>>()?;
            match v.iter().all(|c| (min..=max).contains(c)) {
                true => Ok(Value::Vector(v.into_iter().map(|c| c as f64).collect())),
                false => Err(out_of_range()),
            }
        }
        Kind::Enum(ref names) => names
            .iter()
            .find(|n| n.eq_ignore_ascii_case(t))
            .map(|n| Value::Enum(n.clone()))
            .ok_or_else(|| bad(spec.kind.range_text())),
        Kind::Bool => match t {
            "true" | "1" => Ok(Value::Bool(true)),
            "false" | "0" => Ok(Value::Bool(false)),
            _ => Err(bad(spec.kind.range_text())),
        },
    }
}

/// A complete, validated assignment of every parameter of one kernel.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSet {
    kernel: String,
    values: BTreeMap<String, Value>,
    /// Shader defs a case sets (`NAME=value`), over the kernel's.
    defs: Vec<String>,
}

impl ParamSet {
    /// Defaults, then the preset's overrides, then `overrides` (later wins).
    pub fn resolve(
        kernel: &str,
        specs: &[ParamSpec],
        presets: &[Preset],
        preset: Option<&str>,
        overrides: &[(String, String)],
    ) -> Result<ParamSet, ParamError> {
        let mut set = ParamSet { kernel: kernel.to_string(), values: BTreeMap::new(), defs: Vec::new() };
        for spec in specs {
            // Manifests are validated when parsed, defaults included.
            let v = parse_value(spec, &spec.default)
                .unwrap_or_else(|e| panic!("kernel {kernel}: default of {} is invalid: {e}", spec.name));
            set.values.insert(spec.name.clone(), v);
        }
        // `default` always resolves: to the declared preset of that name, else the defaults.
        if let Some(name) = preset.filter(|n| *n != "default" || presets.iter().any(|p| p.name == *n)) {
            let p = presets.iter().find(|p| p.name == name).ok_or_else(|| ParamError::UnknownPreset {
                kernel: kernel.to_string(),
                name: name.to_string(),
                valid: presets.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", "),
            })?;
            for (k, v) in &p.set {
                set.apply(specs, k, v)?;
            }
        }
        for (k, v) in overrides {
            set.apply(specs, k, v)?;
        }
        Ok(set)
    }

    fn apply(&mut self, specs: &[ParamSpec], name: &str, text: &str) -> Result<(), ParamError> {
        let spec = specs.iter().find(|s| s.name == name).ok_or_else(|| ParamError::UnknownParam {
            kernel: self.kernel.to_string(),
            name: name.to_string(),
            valid: specs.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", "),
        })?;
        self.values.insert(spec.name.clone(), parse_value(spec, text)?);
        Ok(())
    }

    /// The name of the kernel these values belong to.
    pub fn kernel(&self) -> &str {
        &self.kernel
    }

    fn get(&self, name: &str) -> &Value {
        self.values.get(name).unwrap_or_else(|| panic!("kernel {} has no parameter {name}", self.kernel))
    }

    /// The value of number param `name` (an integer widened to f64).
    ///
    /// # Panics
    /// If the kernel has no such param or it is not a number.
    pub fn f64(&self, name: &str) -> f64 {
        match self.get(name) {
            Value::Float(v) => *v,
            Value::Int(v) => *v as f64,
            v => panic!("{}.{name} is {v:?}, not a number", self.kernel),
        }
    }
    /// [`ParamSet::f64`] narrowed to f32.
    pub fn f32(&self, name: &str) -> f32 {
        self.f64(name) as f32
    }
    /// The value of integer param `name`.
    ///
    /// # Panics
    /// If the kernel has no such param or it is not an integer.
    pub fn int(&self, name: &str) -> i64 {
        match self.get(name) {
            Value::Int(v) => *v,
            v => panic!("{}.{name} is {v:?}, not an integer", self.kernel),
        }
    }
    /// [`ParamSet::int`] cast to u32 (`as`: a negative value wraps).
    pub fn u32(&self, name: &str) -> u32 {
        self.int(name) as u32
    }
    /// The components of vector param `name` (integer vectors as f64).
    ///
    /// # Panics
    /// If the kernel has no such param or it is not a vector.
    pub fn vector(&self, name: &str) -> &[f64] {
        match self.get(name) {
            Value::Vector(v) => v,
            v => panic!("{}.{name} is {v:?}, not a vector", self.kernel),
        }
    }
    /// The first three components of vector param `name` (panics with fewer).
    pub fn vec3(&self, name: &str) -> [f64; 3] {
        let v = self.vector(name);
        [v[0], v[1], v[2]]
    }
    /// The first two components of vector param `name` (panics with fewer).
    pub fn vec2(&self, name: &str) -> [f64; 2] {
        let v = self.vector(name);
        [v[0], v[1]]
    }
    /// The chosen name of enum param `name`.
    ///
    /// # Panics
    /// If the kernel has no such param or it is not an enum.
    pub fn choice(&self, name: &str) -> &str {
        match self.get(name) {
            Value::Enum(s) => s,
            v => panic!("{}.{name} is {v:?}, not an enum", self.kernel),
        }
    }
    /// Enum param `name`'s value as the CPU reference means it: `table`
    /// maps every value the manifest lists. There is no default arm: a
    /// manifest value missing from `table` is a reference that does not know
    /// its own kernel, which `every_enum_value_has_a_meaning_in_the_cpu_reference`
    /// catches for every built-in, rather than a silent fallback.
    ///
    /// # Panics
    /// If the value is not in `table` (or `name` is not an enum param).
    pub fn choice_in<T: Copy>(&self, name: &str, table: &[(&str, T)]) -> T {
        let v = self.choice(name);
        match table.iter().find(|(n, _)| *n == v) {
            Some((_, t)) => *t,
            None => {
                let known: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
                panic!(
                    "{}.{name} = {v} has no meaning in the CPU reference (it knows {})",
                    self.kernel,
                    known.join("|")
                )
            }
        }
    }
    /// The value of bool param `name`.
    ///
    /// # Panics
    /// If the kernel has no such param or it is not a bool.
    pub fn flag(&self, name: &str) -> bool {
        match self.get(name) {
            Value::Bool(b) => *b,
            v => panic!("{}.{name} is {v:?}, not a bool", self.kernel),
        }
    }
    /// The value of `name`, if the kernel has that param.
    pub fn value(&self, name: &str) -> Option<&Value> {
        self.values.get(name)
    }

    /// Sets one value by text (validated), for sweeps and tests.
    pub fn with(mut self, specs: &[ParamSpec], name: &str, text: &str) -> Result<ParamSet, ParamError> {
        self.apply(specs, name, text)?;
        Ok(self)
    }

    /// `name=value` pairs sorted by name: the canonical text that is hashed
    /// into the golden manifest.
    pub fn canonical(&self) -> String {
        let values = self.values.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(";");
        // Defs join only where a case sets some: every older hash stands.
        match self.defs.is_empty() {
            true => values,
            false => format!("{values};defs:{}", self.defs.join("&")),
        }
    }

    /// These values with shader defs set by a case (`NAME=value`, sorted by
    /// name): they join every pass's composition, over the kernel's own.
    pub fn with_defs(mut self, mut defs: Vec<String>) -> ParamSet {
        defs.sort();
        self.defs = defs;
        self
    }

    /// The shader defs a case set ([`ParamSet::with_defs`]).
    pub fn defs(&self) -> &[String] {
        &self.defs
    }

    /// Every `(name, value)` pair, sorted by name.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &Value)> {
        self.values.iter().map(|(k, v)| (k.as_str(), v))
    }
}
