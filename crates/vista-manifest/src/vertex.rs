//! A draw's vertex buffers (SPEC 17): the `vertices` list as written, and
//! each `@location` input of the vertex entry matched with one attribute
//! of one buffer, reflected (packed by the buffer's element type) or as an
//! explicit stride/offset/format layout.

use vista_texel::VertexFormat;

use crate::bindings::VertexInput;
use crate::element::Element;

/// The keys of a `vertices` entry written as a table.
pub const VERTEX_BUFFER_KEYS: [&str; 4] = ["resource", "step", "stride", "attributes"];
/// The keys of one explicit attribute.
pub const ATTRIBUTE_KEYS: [&str; 3] = ["location", "format", "offset"];
/// WebGPU's `maxVertexBufferArrayStride` (its default limit).
const MAX_STRIDE: u32 = 2048;

/// One attribute of a vertex buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    /// The vertex entry input it feeds.
    pub location: u32,
    /// How the bytes read.
    pub format: VertexFormat,
    /// Bytes from the start of the element.
    pub offset: u32,
}

/// One entry of a render pass's `vertices`.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexBufferSpec {
    /// The buffer resource.
    pub resource: String,
    /// `step = "instance"`: advanced once per instance, not per vertex.
    pub instance: bool,
    /// Bytes from one element to the next (default: from the attributes).
    pub stride: Option<u32>,
    /// Explicit attributes; `None`: the inputs no other buffer feeds.
    pub attributes: Option<Vec<Attribute>>,
}

/// One vertex buffer as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexLayout {
    /// Bytes from one element to the next.
    pub stride: u32,
    /// Advanced per instance.
    pub instance: bool,
    /// Every attribute, in location order.
    pub attributes: Vec<Attribute>,
}

fn number(v: &toml::Value, what: &str) -> Result<u32, String> {
    v.as_integer()
        .and_then(|n| u32::try_from(n).ok())
        .ok_or_else(|| format!("{what} = {v} is not valid; expected a whole number >= 0"))
}

/// The `vertices` list: buffer names, or tables with `step`, `stride` and
/// `attributes`. `known` says whether a name is a buffer resource.
pub fn parse(v: &toml::Value, known: &dyn Fn(&str) -> Result<(), String>) -> Result<Vec<VertexBufferSpec>, String> {
    let Some(list) = v.as_array() else {
        return Err(format!("vertices = {v} is not valid; expected a list of buffer names or tables"));
    };
    let mut out = Vec::new();
    for (n, e) in list.iter().enumerate() {
        let at = |m: String| format!("vertices[{n}]: {m}");
        let spec = match e {
            toml::Value::String(name) => {
                VertexBufferSpec { resource: name.clone(), instance: false, stride: None, attributes: None }
            }
            toml::Value::Table(t) => {
                if let Some(k) = t.keys().find(|k| !VERTEX_BUFFER_KEYS.contains(&k.as_str())) {
                    return Err(at(format!("unknown key {k}; allowed: {}", VERTEX_BUFFER_KEYS.join(", "))));
                }
                let resource = t
                    .get("resource")
                    .and_then(|r| r.as_str())
                    .ok_or_else(|| at("needs resource = \"<buffer>\"".into()))?
                    .to_string();
                let instance = match t.get("step").map(|s| s.as_str()) {
                    None | Some(Some("vertex")) => false,
                    Some(Some("instance")) => true,
                    Some(_) => return Err(at(format!("step = {} is not valid; expected vertex|instance", t["step"]))),
                };
                let stride = t.get("stride").map(|s| number(s, "stride")).transpose().map_err(at)?;
                // WebGPU: arrayStride is a multiple of 4, at most maxVertexBufferArrayStride.
                if let Some(s) = stride.filter(|s| !s.is_multiple_of(4) || *s > 2048) {
                    return Err(at(format!("stride = {s} is not valid; expected a multiple of 4 from 0 to 2048")));
                }
                let attributes = match t.get("attributes") {
                    None => None,
                    Some(a) => Some(parse_attributes(a).map_err(at)?),
                };
                VertexBufferSpec { resource, instance, stride, attributes }
            }
            other => return Err(at(format!("{other} is not valid; expected a buffer name or a table"))),
        };
        known(&spec.resource).map_err(at)?;
        out.push(spec);
    }
    Ok(out)
}

fn parse_attributes(v: &toml::Value) -> Result<Vec<Attribute>, String> {
    let Some(list) = v.as_array() else {
        return Err(format!("attributes = {v} is not valid; expected [{{ location, format, offset }}, ...]"));
    };
    let mut out = Vec::new();
    for (k, a) in list.iter().enumerate() {
        let at = |m: String| format!("attributes[{k}]: {m}");
        let Some(t) = a.as_table() else { return Err(at("must be a table { location, format, offset }".into())) };
        if let Some(key) = t.keys().find(|key| !ATTRIBUTE_KEYS.contains(&key.as_str())) {
            return Err(at(format!("unknown key {key}; allowed: {}", ATTRIBUTE_KEYS.join(", "))));
        }
        let location = number(t.get("location").ok_or_else(|| at("needs location".into()))?, "location").map_err(at)?;
        let format = t
            .get("format")
            .and_then(|f| f.as_str())
            .ok_or_else(|| at("needs format = \"float32x3\" (a WebGPU vertex format)".into()))?;
        let format = VertexFormat::parse(format).map_err(at)?;
        let offset = number(t.get("offset").unwrap_or(&toml::Value::Integer(0)), "offset").map_err(at)?;
        // WebGPU: a multiple of min(4, the format's byte size).
        let align = format.bytes.min(4);
        if !offset.is_multiple_of(align) {
            return Err(at(format!("offset = {offset} is not a multiple of {align} (a {} attribute)", format.name)));
        }
        out.push(Attribute { location, format, offset });
    }
    if out.is_empty() {
        return Err("attributes is empty; leave it out to take the entry's inputs by reflection".into());
    }
    Ok(out)
}

/// WGSL's alignment of a 32-bit scalar or vector of `n` components.
fn align_of(n: u32) -> u32 {
    match n {
        1 => 4,
        2 => 8,
        _ => 16,
    }
}

/// Every buffer's layout for a vertex entry's `inputs`, and the element of
/// each buffer that has none from a binding (`elements[i]`: buffer i's
/// element where a binding gives one). Inputs no explicit attribute
/// feeds go to the one buffer without attributes: packed as the WGSL
/// struct of those inputs would be where a binding gives the buffer an
/// element (a compute pass writes the vertices), else tightly.
pub fn layouts(
    entry: &str,
    inputs: &[VertexInput],
    specs: &[VertexBufferSpec],
    elements: &[Option<&Element>],
) -> Result<Vec<(VertexLayout, Option<Element>)>, String> {
    let input = |l: u32| inputs.iter().find(|i| i.location == l);
    let mut fed: Vec<u32> = Vec::new();
    let mut out: Vec<Option<VertexLayout>> = vec![None; specs.len()];
    for (b, spec) in specs.iter().enumerate() {
        let Some(attrs) = &spec.attributes else { continue };
        let r = &spec.resource;
        for a in attrs {
            let Some(i) = input(a.location) else {
                let have: Vec<String> =
                    inputs.iter().map(|i| format!("@location({}) {}", i.location, i.name)).collect();
                return Err(format!(
                    "vertices {r}: attribute @location({}) feeds no input of {entry}; its inputs: {}",
                    a.location,
                    if have.is_empty() { "none".into() } else { have.join(", ") }
                ));
            };
            if (a.format.kind, a.format.components) != (i.kind, i.components) {
                return Err(format!(
                    "{entry}'s input @location({}) {} is {} but {r}'s attribute is {}; allowed: {}",
                    i.location,
                    i.name,
                    i.wgsl(),
                    a.format.name,
                    formats_for(i)
                ));
            }
            if fed.contains(&a.location) {
                return Err(format!("vertices: @location({}) is fed twice ({r} and another buffer)", a.location));
            }
            fed.push(a.location);
        }
        let end = attrs.iter().map(|a| a.offset + a.format.bytes).max().unwrap_or(0);
        let stride = spec.stride.unwrap_or(end.next_multiple_of(4));
        if end > stride {
            return Err(format!("vertices {r}: stride = {stride} but the attributes reach byte {end}"));
        }
        let mut attributes = attrs.clone();
        attributes.sort_by_key(|a| a.location);
        out[b] = Some(VertexLayout { stride, instance: spec.instance, attributes });
    }
    let reflected: Vec<usize> = (0..specs.len()).filter(|b| specs[*b].attributes.is_none()).collect();
    if reflected.len() > 1 {
        return Err(format!(
            "vertices {} and {} both take {entry}'s inputs by reflection; give all but one of them attributes",
            specs[reflected[0]].resource, specs[reflected[1]].resource
        ));
    }
    let rest: Vec<&VertexInput> = inputs.iter().filter(|i| !fed.contains(&i.location)).collect();
    if let Some(&b) = reflected.first() {
        out[b] = Some(reflect(&specs[b], &rest, elements[b])?);
    } else if let Some(i) = rest.first() {
        let given: Vec<String> = out
            .iter()
            .flatten()
            .flat_map(|l| &l.attributes)
            .map(|a| format!("@location({}) {}", a.location, a.format.name))
            .collect();
        return Err(format!(
            "{entry}'s input @location({}) {}: {} has no buffer attribute of its type; vertices give {}",
            i.location,
            i.name,
            i.wgsl(),
            if given.is_empty() { "none (add vertices = [\"<buffer>\"])".into() } else { given.join(", ") }
        ));
    }
    let mut result = Vec::new();
    for (b, layout) in out.into_iter().enumerate() {
        let layout = layout.expect("every buffer laid out");
        if layout.stride > MAX_STRIDE {
            return Err(format!(
                "vertices {}: stride {} is over WebGPU's limit of {MAX_STRIDE}",
                specs[b].resource, layout.stride
            ));
        }
        let synth = match elements[b] {
            Some(_) => None,
            None => Some(element_of(&layout, inputs, &specs[b].resource)),
        };
        result.push((layout, synth));
    }
    Ok(result)
}

/// The vertex formats an input reads.
fn formats_for(i: &VertexInput) -> String {
    let f: Vec<&str> =
        VertexFormat::ALL.iter().filter(|f| (f.kind, f.components) == (i.kind, i.components)).map(|f| f.name).collect();
    f.join("|")
}

/// The reflected buffer: `inputs` in location order, at the offsets of
/// the binding's element where it has one, else packed.
fn reflect(
    spec: &VertexBufferSpec,
    inputs: &[&VertexInput],
    element: Option<&Element>,
) -> Result<VertexLayout, String> {
    let r = &spec.resource;
    let fmt = |i: &VertexInput| VertexFormat::of_input(i.kind, i.components).expect("32-bit inputs have a format");
    let mut attributes = Vec::new();
    let mut at = 0u32;
    let mut max_align = 4;
    for i in inputs {
        let offset = match element {
            Some(_) => at.next_multiple_of(align_of(i.components)),
            None => at,
        };
        max_align = max_align.max(align_of(i.components));
        attributes.push(Attribute { location: i.location, format: fmt(i), offset });
        at = offset + 4 * i.components;
    }
    let stride = match (spec.stride, element) {
        (Some(s), _) => s,
        (None, Some(e)) => e.stride,
        (None, None) => at,
    };
    if let Some(e) = element {
        let fits = inputs
            .iter()
            .zip(&attributes)
            .all(|(i, a)| (0..i.components).all(|c| e.leaves.iter().any(|l| l.0 == a.offset + 4 * c && l.1 == i.kind)));
        if !fits || at > stride {
            let wanted: Vec<String> = inputs.iter().map(|i| format!("{}: {}", i.name, i.wgsl())).collect();
            return Err(format!(
                "vertices {r}: its binding's element is {} but the inputs need struct {{ {} }} (or give attributes)",
                e.wgsl,
                wanted.join(", ")
            ));
        }
    }
    if at > stride {
        return Err(format!("vertices {r}: stride = {stride} but the inputs take {at} bytes"));
    }
    Ok(VertexLayout { stride, instance: spec.instance, attributes })
}

/// The element a buffer read only as vertices holds: each attribute's
/// 32-bit words at their offsets (a four-byte 8-bit format as one u32).
fn element_of(layout: &VertexLayout, inputs: &[VertexInput], resource: &str) -> Element {
    let mut leaves = Vec::new();
    let mut fields = Vec::new();
    for a in &layout.attributes {
        let name = inputs.iter().find(|i| i.location == a.location).map_or("attribute".to_string(), |i| i.name.clone());
        if a.format.is_32bit() {
            for c in 0..a.format.components {
                let path = if a.format.components == 1 { name.clone() } else { format!("{name}[{c}]") };
                leaves.push((a.offset + 4 * c, a.format.kind, path));
            }
        } else if !leaves.iter().any(|l: &(u32, char, String)| l.0 == a.offset & !3) {
            // Packed formats as the 32-bit word holding them (two 16-bit
            // attributes may share one).
            leaves.push((a.offset & !3, 'u', name.clone()));
        }
        fields.push(format!("{name}: {} @ {}", a.format.name, a.offset));
    }
    Element {
        stride: layout.stride,
        header: 0,
        fixed: None,
        leaves,
        wgsl: format!("{resource}'s vertices {{ {} }} (stride {})", fields.join(", "), layout.stride),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(location: u32, name: &str, kind: char, components: u32) -> VertexInput {
        VertexInput { location, name: name.into(), kind, components }
    }

    fn spec(r: &str) -> VertexBufferSpec {
        VertexBufferSpec { resource: r.into(), instance: false, stride: None, attributes: None }
    }

    #[test]
    fn reflected_inputs_pack_tightly_or_as_the_binding_lays_them_out() {
        let inputs = [input(0, "position", 'f', 3), input(1, "uv", 'f', 2)];
        let l = layouts("vs", &inputs, &[spec("blades")], &[None]).unwrap();
        let (layout, el) = &l[0];
        assert_eq!((layout.stride, layout.attributes[1].offset), (20, 12));
        assert_eq!(el.as_ref().unwrap().leaves.len(), 5);
        // A compute pass's array<struct { position: vec3<f32>, uv: vec2<f32> }>: 32-byte stride.
        let bound = Element {
            stride: 32,
            header: 0,
            fixed: None,
            leaves: vec![
                (0, 'f', "p".into()),
                (4, 'f', "".into()),
                (8, 'f', "".into()),
                (16, 'f', "".into()),
                (20, 'f', "".into()),
            ],
            wgsl: "Blade".into(),
        };
        let l = layouts("vs", &inputs, &[spec("blades")], &[Some(&bound)]).unwrap();
        assert_eq!((l[0].0.stride, l[0].0.attributes[1].offset, l[0].1.is_none()), (32, 16, true));
        let ints = [input(0, "position", 'u', 3), input(1, "uv", 'f', 2)];
        let e = layouts("vs", &ints, &[spec("blades")], &[Some(&bound)]).unwrap_err();
        assert!(e.contains("the inputs need struct { position: vec3<u32>, uv: vec2<f32> }"), "{e}");
    }

    #[test]
    fn every_input_needs_an_attribute_of_its_type() {
        let inputs = [input(0, "position", 'f', 3), input(1, "uv", 'f', 2)];
        let explicit = VertexBufferSpec {
            attributes: Some(vec![Attribute {
                location: 0,
                format: VertexFormat::parse("float32x3").unwrap(),
                offset: 0,
            }]),
            ..spec("p")
        };
        let e = layouts("vs", &inputs, std::slice::from_ref(&explicit), &[None]).unwrap_err();
        assert!(e.contains("input @location(1) uv: vec2<f32> has no buffer attribute of its type"), "{e}");
        assert!(e.contains("vertices give @location(0) float32x3"), "{e}");
        let wrong = VertexBufferSpec {
            attributes: Some(vec![Attribute {
                location: 1,
                format: VertexFormat::parse("uint32x2").unwrap(),
                offset: 12,
            }]),
            ..spec("q")
        };
        let e = layouts("vs", &inputs, &[explicit.clone(), wrong], &[None, None]).unwrap_err();
        assert!(e.contains("@location(1) uv is vec2<f32> but q's attribute is uint32x2; allowed: unorm8x2|snorm8x2|unorm16x2|snorm16x2|float16x2|float32x2"), "{e}");
        let both = layouts("vs", &inputs, &[spec("a"), spec("b")], &[None, None]).unwrap_err();
        assert!(both.contains("both take vs's inputs by reflection"), "{both}");
        let mixed = layouts("vs", &inputs, &[explicit, spec("uvs")], &[None, None]).unwrap();
        assert_eq!((mixed[1].0.stride, mixed[1].0.attributes[0].location), (8, 1));
    }
}
