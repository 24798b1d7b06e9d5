//! TOML values as manifests and cases read them: shader defs, and a
//! value's text where a param or def takes it.

/// Text form of a TOML value as `--set` would take it (vectors comma-separated).
pub fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Array(items) => items.iter().map(value_text).collect::<Vec<_>>().join(","),
        other => other.to_string(),
    }
}

/// A `defs` table (the kernel's, a pass's or a case's) as `NAME=value`
/// strings: naga_oil shader defs, bool or integer.
pub fn parse_defs(table: &toml::Table) -> Result<Vec<String>, String> {
    let mut defs = Vec::new();
    for (k, v) in table {
        if k.is_empty() || !k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(format!("defs: '{k}' is not a shader def name (letters, digits and '_')"));
        }
        match v {
            toml::Value::Boolean(b) => defs.push(format!("{k}={b}")),
            toml::Value::Integer(i) if (i32::MIN as i64..=u32::MAX as i64).contains(i) => defs.push(format!("{k}={i}")),
            other => {
                return Err(format!(
                    "defs: {k} = {other} is not valid; expected true, false or an integer in [{}, {}]",
                    i32::MIN,
                    u32::MAX
                ));
            }
        }
    }
    Ok(defs)
}
