//! The output texture as a resource (SPEC 14): its format, dimension,
//! access and size, from the storage texture the pass writes and, where the
//! manifest has them, a `[[resource]]` table and the pass's `bind`. So far
//! a kernel has one texture resource, its output; buffers, samplers and
//! sampled inputs are the second part of SPEC 14.

use crate::bindings::{Binding, Feed};
use crate::expr::Expr;
use crate::{ParamError, ParamSet};

pub use vista_texel::{Access, Dimension};

pub use crate::bindings::Storage;

/// A `[[resource]]` table of kind `texture`.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureResource {
    /// The resource's name, which `bind` refers to.
    pub name: String,
    /// Its format, if given (it must match the binding's).
    pub format: Option<&'static str>,
    /// Its dimension, if given (it must match the binding's).
    pub dimension: Option<Dimension>,
    /// `[w]`, `[w, h]` or `[w, h, layers or depth]`; default the case size.
    pub size: Option<Vec<Expr>>,
}

/// The output: the WGSL variable the pass writes, how it is declared, and
/// the resource that gives its size (none: the case size).
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// The WGSL variable the pass writes.
    pub var: String,
    /// How that variable is declared.
    pub storage: Storage,
    /// The `[[resource]]` that `bind` gives it, if any (its `size` sets the extent).
    pub resource: Option<TextureResource>,
}

/// An output's extent: width, height (1 for 1d) and layers or depth (1
/// for 1d and 2d).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Extent {
    /// Texels across.
    pub width: u32,
    /// Rows (1 for 1d).
    pub height: u32,
    /// Layers of a 2d-array or depth of a 3d texture (1 otherwise).
    pub layers: u32,
}

/// A pass's `bind`: WGSL variable name -> resource name.
pub type Binds = Vec<(String, String)>;

/// Parses the `[[resource]]` tables and a pass's `bind`; `fail` prefixes
/// the manifest and kernel.
pub(crate) fn parse(
    tables: &[toml::Value],
    bind: Option<&toml::Table>,
    params: &[crate::ParamSpec],
    fail: &dyn Fn(String) -> ParamError,
) -> Result<(Vec<TextureResource>, Binds), ParamError> {
    let mut out: Vec<TextureResource> = Vec::new();
    for t in tables {
        let Some(t) = t.as_table() else {
            return Err(fail("[[resource]] must be a table".into()));
        };
        let text = |k: &str| -> Result<Option<String>, ParamError> {
            match t.get(k) {
                None => Ok(None),
                Some(toml::Value::String(s)) => Ok(Some(s.clone())),
                Some(other) => Err(fail(format!("[[resource]] {k} = {other} is not valid; expected a string"))),
            }
        };
        let name = text("name")?.ok_or_else(|| fail("[[resource]] needs a name".into()))?;
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
            return Err(fail(format!("[[resource]] name \"{name}\" must use only letters, digits, '-' and '_'")));
        }
        if out.iter().any(|r| r.name == name) {
            return Err(fail(format!("[[resource]] name \"{name}\" is used twice")));
        }
        let at = |m: String| fail(format!("[[resource]] {name}: {m}"));
        for k in t.keys() {
            if !["name", "kind", "format", "dimension", "size"].contains(&k.as_str()) {
                let part2 = ["file", "data", "fill", "length", "filter", "address", "compare"];
                return Err(at(if part2.contains(&k.as_str()) {
                    format!("key {k} is not supported yet (inputs come with SPEC 14's second part)")
                } else {
                    format!("unknown key {k}; allowed: name, kind, format, dimension, size")
                }));
            }
        }
        match text("kind")?.as_deref() {
            Some("texture") => {}
            Some(k @ ("buffer" | "sampler")) => {
                return Err(at(format!(
                    "kind = \"{k}\" is not supported yet; so far a resource is the output texture (kind = \"texture\")"
                )));
            }
            Some(other) => return Err(at(format!("kind = \"{other}\" is not valid; expected texture|buffer|sampler"))),
            None => return Err(at("needs kind = \"texture\"".into())),
        }
        let format = match text("format")? {
            None => None,
            Some(f) => Some(crate::bindings::storage_format(&f).map_err(at)?),
        };
        let dimension = match text("dimension")? {
            None => None,
            Some(d) if d == "cube" => {
                return Err(at(
                    "dimension = \"cube\" is a sampled input, not supported yet; an output is 1d|2d|2d-array|3d".into(),
                ));
            }
            Some(d) => Some(Dimension::parse(&d).ok_or_else(|| {
                at(format!("dimension = \"{d}\" is not valid; expected {}", Dimension::STORAGE_NAMES))
            })?),
        };
        let size = match t.get("size") {
            None => None,
            Some(toml::Value::Array(list)) => {
                let want = dimension.unwrap_or(Dimension::D2).size_entries();
                if list.len() != want {
                    return Err(at(format!(
                        "size has {} entries; a {} texture takes {want}",
                        list.len(),
                        dimension.unwrap_or(Dimension::D2).name()
                    )));
                }
                let mut exprs = Vec::new();
                for v in list {
                    exprs.push(Expr::parse_entry(v, params).map_err(|e| at(format!("size {e}")))?);
                }
                Some(exprs)
            }
            Some(other) => return Err(at(format!("size = {other} is not valid; expected a list"))),
        };
        out.push(TextureResource { name: name.clone(), format, dimension, size });
    }
    let mut binds = Vec::new();
    for (var, res) in bind.into_iter().flatten() {
        let Some(res) = res.as_str() else {
            return Err(fail(format!("[[pass]] bind: {var} = {res} is not valid; expected a resource name")));
        };
        if !out.iter().any(|r| r.name == res) {
            let names: Vec<&str> = out.iter().map(|r| r.name.as_str()).collect();
            return Err(fail(format!(
                "[[pass]] bind: {var} = \"{res}\" names no resource; resources: {}",
                if names.is_empty() { "none ([[resource]] tables declare them)".into() } else { names.join(", ") }
            )));
        }
        binds.push((var.clone(), res.to_string()));
    }
    Ok((out, binds))
}

/// What a one-pass manifest declares about its output, for [`resolve`].
pub(crate) struct Declared<'a> {
    /// The kernel's name.
    pub name: &'a str,
    /// Its entry point.
    pub entry: &'a str,
    /// Its `[[resource]]` textures.
    pub resources: &'a [TextureResource],
    /// Its pass's `bind` (variable, resource).
    pub bind: &'a [(String, String)],
    /// Its `[[output]] resource`.
    pub output_resource: Option<&'a str>,
}

/// The output target of a pass: the storage texture it writes, checked
/// against the resource `bind` gives it (format, dimension) and the
/// `[[output]] resource`. Every other `bind` must name a storage texture
/// the pass reaches.
pub(crate) fn resolve(
    kernel: &Declared<'_>,
    bindings: &[Binding],
    module: &naga::Module,
) -> Result<Target, ParamError> {
    let bad = |message: String| ParamError::Layout { kernel: kernel.name.to_string(), message };
    let entry = kernel.entry;
    let describe = |b: &Binding| {
        format!(
            "{} (@group({}) @binding({}), {})",
            b.name,
            b.group,
            b.binding,
            crate::bindings::wgsl_type(module, &module.global_variables[b.global])
        )
    };
    let mut resource = None;
    for (var, res) in kernel.bind {
        let Some(b) = bindings.iter().find(|b| &b.name == var) else {
            let reached: Vec<&str> = bindings.iter().map(|b| b.name.as_str()).collect();
            return Err(bad(format!(
                "pass {entry}: bind names {var}, which the pass does not reach; it reaches: {}",
                reached.join(", ")
            )));
        };
        let r = kernel.resources.iter().find(|r| &r.name == res).expect("manifest checks bind targets");
        let Feed::Output(storage) = b.feed else {
            return Err(bad(format!(
                "pass {entry}: resource {res} (a texture) is bound to {}, which a texture cannot feed; it needs {}",
                describe(b),
                match b.feed {
                    Feed::Uniform => "params (leave it out of bind)",
                    _ => "a buffer resource",
                }
            )));
        };
        if let Some(f) = r.format
            && f != storage.format
        {
            return Err(bad(format!(
                "pass {entry}: resource {res} has format {f} but is bound to {}; would fit: format = \"{}\"",
                describe(b),
                storage.format
            )));
        }
        if let Some(d) = r.dimension
            && d != storage.dimension
        {
            return Err(bad(format!(
                "pass {entry}: resource {res} has dimension {} but is bound to {}; would fit: dimension = \"{}\"",
                d.name(),
                describe(b),
                storage.dimension.name()
            )));
        }
        if r.dimension.is_none()
            && let Some(size) = &r.size
            && size.len() != storage.dimension.size_entries()
        {
            return Err(bad(format!(
                "pass {entry}: resource {res} has a size of {} entries but is bound to {}, which takes {}",
                size.len(),
                describe(b),
                storage.dimension.size_entries()
            )));
        }
        resource = Some(r.clone());
    }
    let (out, storage) = crate::bindings::output(bindings);
    if let Some(named) = kernel.output_resource {
        let fits = resource.as_ref().map(|r| r.name == named).unwrap_or(named == out.name);
        if !fits {
            return Err(bad(format!(
                "[[output]] resource = \"{named}\" is not what pass {entry} writes; it writes {}{}",
                describe(out),
                resource.as_ref().map(|r| format!(", bound to resource {}", r.name)).unwrap_or_default()
            )));
        }
    }
    Ok(Target { var: out.name.clone(), storage, resource })
}

impl Target {
    /// The output's extent for `p` at the case size: the resource's `size`,
    /// else the case size (a 1d texture: its width; 1 layer).
    pub fn extent(&self, kernel: &str, p: &ParamSet, width: u32, height: u32) -> Result<Extent, ParamError> {
        let dim = self.storage.dimension;
        let Some(size) = self.resource.as_ref().and_then(|r| r.size.as_ref()) else {
            let height = if dim == Dimension::D1 { 1 } else { height };
            return Ok(Extent { width, height, layers: 1 });
        };
        let mut v = [1u32; 3];
        for (i, e) in size.iter().enumerate() {
            let fail = |m: String| ParamError::Layout {
                kernel: kernel.to_string(),
                message: format!(
                    "resource {} size[{i}] {m}",
                    self.resource.as_ref().map(|r| r.name.as_str()).unwrap_or_default()
                ),
            };
            let n = e.eval(p, width, height).map_err(&fail)?;
            v[i] = u32::try_from(n)
                .ok()
                .filter(|n| (1..=16384).contains(n))
                .ok_or_else(|| fail(format!("is {n} for these params; allowed: [1, 16384]")))?;
        }
        Ok(Extent { width: v[0], height: v[1], layers: v[2] })
    }
}
