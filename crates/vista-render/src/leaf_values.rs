//! Struct data by leaf path from a TOML or JSON file, or a case's inline
//! table (SPEC 19): `"view.viewport" = [0, 0, 64, 64]`, or nested tables
//! (`[view] viewport = [...]`) and arrays of tables
//! (`directional_lights = [{ direction_to_light = [0, 1, 0] }]`), flattened
//! to the paths a `fields` table takes. Matrices are nested lists, column
//! by column; booleans are 0 and 1.

/// A case's inline values (`inputs = { view = { "view.exposure" = 2 } }`)
/// travel among the case's input files as this prefix and their JSON text.
pub const INLINE: &str = "inline:";

/// Whether a buffer's `file` (or a case's replacement) holds leaf values.
pub fn is_leaf_file(file: &str) -> bool {
    file.starts_with(INLINE) || file.ends_with(".toml") || file.ends_with(".json")
}

/// `(leaf path, numbers)` from `text`, a TOML or JSON document (`file`
/// names it in errors and by its extension says which; an [`INLINE`]
/// value is JSON).
pub fn parse(file: &str, text: &str) -> Result<Vec<(String, Vec<f64>)>, String> {
    let value: serde_json::Value = if file.ends_with(".toml") {
        let t: toml::Table =
            toml::from_str(text).map_err(|e| format!("{file}: {}", e.message().lines().next().unwrap_or("")))?;
        serde_json::to_value(t).map_err(|e| format!("{file}: {e}"))?
    } else {
        serde_json::from_str(text).map_err(|e| format!("{file}: {e}"))?
    };
    let serde_json::Value::Object(top) = value else {
        return Err(format!("{file}: expected a table of leaf paths, e.g. {{ \"view.viewport\" = [0, 0, 64, 64] }}"));
    };
    let mut out = Vec::new();
    for (k, v) in &top {
        flatten(file, k, v, &mut out)?;
    }
    Ok(out)
}

/// `v` at path `at` into `out`: a table's keys join with `.`, an array of
/// tables' items index `[i]`, numbers (nested lists of them) are one leaf's.
fn flatten(file: &str, at: &str, v: &serde_json::Value, out: &mut Vec<(String, Vec<f64>)>) -> Result<(), String> {
    use serde_json::Value;
    match v {
        Value::Object(o) => {
            for (k, v) in o {
                flatten(file, &format!("{at}.{k}"), v, out)?;
            }
        }
        Value::Array(items) if !items.is_empty() && items.iter().all(Value::is_object) => {
            for (i, v) in items.iter().enumerate() {
                flatten(file, &format!("{at}[{i}]"), v, out)?;
            }
        }
        _ => {
            let mut numbers = Vec::new();
            numbers_of(v, &mut numbers).ok_or_else(|| {
                format!("{file}: \"{at}\" = {v} is not valid; expected a number or a (nested) list of numbers")
            })?;
            if numbers.is_empty() {
                return Err(format!("{file}: \"{at}\" is an empty list; expected its leaf's numbers"));
            }
            out.push((at.to_string(), numbers));
        }
    }
    Ok(())
}

fn numbers_of(v: &serde_json::Value, out: &mut Vec<f64>) -> Option<()> {
    match v {
        serde_json::Value::Number(n) => out.push(n.as_f64()?),
        serde_json::Value::Bool(b) => out.push(f64::from(u8::from(*b))),
        serde_json::Value::Array(a) => {
            for v in a {
                numbers_of(v, out)?;
            }
        }
        _ => return None,
    }
    Some(())
}

/// The leaf paths the manifest gives resource `name` of `kernel` (its
/// `fields` and its `.toml`/`.json` file's, read under `root`); `None` for
/// a resource that is not given by leaf path.
pub fn manifest_leaves(
    root: Option<&std::path::Path>,
    kernel: &vista_manifest::Kernel,
    name: &str,
) -> Result<Option<Vec<String>>, String> {
    use vista_manifest::graph::ResourceKind;
    let Some(r) = kernel.graph().resources.iter().find(|r| r.name == name) else { return Ok(None) };
    let ResourceKind::Buffer { file, fields, .. } = &r.kind else { return Ok(None) };
    let leaf_file = file.as_deref().filter(|f| is_leaf_file(f));
    if leaf_file.is_none() && fields.is_none() {
        return Ok(None);
    }
    let mut out: Vec<String> = fields.iter().flatten().map(|(k, _)| k.clone()).collect();
    if let Some(f) = leaf_file {
        let root = root.ok_or_else(|| format!("file {f} needs a project root (vista.toml) to be found under"))?;
        let text = vista_project::guard::read_text(root, &root.join(f)).map_err(|e| e.to_string())?;
        out.extend(parse(f, &text)?.into_iter().map(|(k, _)| k));
    }
    Ok(Some(out))
}

/// Whether the leaf at `leaf` (a `vista list --layout` path) is among
/// `given` (a given path names it or a struct or array above it).
pub fn is_given(leaf: &str, given: &[String]) -> bool {
    given.iter().any(|g| {
        leaf == g || leaf.strip_prefix(g.as_str()).is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
    })
}

/// Up to three of `known` closest to `path` (edit distance), for "names no
/// leaf" errors.
pub fn nearest<'a>(path: &str, known: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut scored: Vec<(usize, &str)> = known.map(|k| (distance(path, k), k)).collect();
    scored.sort();
    scored.dedup_by(|a, b| a.1 == b.1);
    scored.into_iter().take(3).map(|(_, k)| k).collect()
}

fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let here = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(here + 1);
            prev = here;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toml_and_json_flatten_to_the_same_paths() {
        let toml = "\"view.exposure\" = 2.0\n[view]\nviewport = [0, 0, 64, 64]\nclip_from_world = [[1, 0], [0, 1]]\n\n\
                    [[lights]]\ncolor = [1, 0.5, 0]\non = true\n[[lights]]\ncolor = [0, 0, 1]\non = false\n";
        let json = r#"{ "view.exposure": 2.0, "view": { "viewport": [0, 0, 64, 64], "clip_from_world": [[1, 0], [0, 1]] },
                       "lights": [{ "color": [1, 0.5, 0], "on": true }, { "color": [0, 0, 1], "on": false }] }"#;
        let mut a = parse("v.toml", toml).unwrap();
        let mut b = parse("v.json", json).unwrap();
        a.sort_by(|x, y| x.0.cmp(&y.0));
        b.sort_by(|x, y| x.0.cmp(&y.0));
        assert_eq!(a, b);
        let paths: Vec<&str> = a.iter().map(|(p, _)| p.as_str()).collect();
        assert_eq!(
            paths,
            [
                "lights[0].color",
                "lights[0].on",
                "lights[1].color",
                "lights[1].on",
                "view.clip_from_world",
                "view.exposure",
                "view.viewport"
            ]
        );
        assert_eq!(a[4].1, [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(a[1].1, [1.0]);
    }

    #[test]
    fn bad_values_and_nearest_paths() {
        assert!(parse("v.json", "[1, 2]").unwrap_err().contains("expected a table of leaf paths"));
        let e = parse("v.toml", "a = \"x\"").unwrap_err();
        assert!(e.contains("v.toml: \"a\" = \"x\" is not valid"), "{e}");
        assert!(parse("v.toml", "a = []").unwrap_err().contains("\"a\" is an empty list"));
        assert!(parse("v.toml", "a = ").unwrap_err().starts_with("v.toml: "));
        let known = ["view.viewport", "view.exposure", "view.world_from_clip", "lights[0].color"];
        assert_eq!(nearest("view.viewprt", known.into_iter()), ["view.viewport", "view.exposure", "lights[0].color"]);
    }
}
