//! A `.npy` file's structured dtype read against the struct a buffer's
//! elements are (SPEC 19): each named field must be the member of that
//! name, at its offset, of its scalar type and count, and every member
//! must have a field, so that a file written for another layout (fields
//! reordered, a vec3 without its padding) is refused by name instead of
//! read as the wrong bytes. Fields named `_...` or of a void type (`|V4`)
//! are padding. A nested dtype is checked by its size alone.

use vista_manifest::element::{Element, leaf_numpy};

/// One field of a structured dtype: name, NumPy type, element count, offset.
#[derive(Debug, PartialEq)]
struct Field {
    name: String,
    ty: String,
    count: u64,
    offset: u64,
}

/// Checks `descr` (a structured dtype, `[('pos', '<f4', (2,)), ...]`)
/// against element `e`; the error names the field and what `e` has.
pub(crate) fn check_structured(file: &str, descr: &str, e: &Element) -> Result<(), String> {
    // A form this reader does not take apart (nested dtypes, an offsets
    // dict) is taken by its size alone, as before names were read.
    let Some(fields) = parse(descr) else { return Ok(()) };
    let member = |path: &str| path.split('.').next().unwrap_or(path).to_string();
    let mut covered = vec![false; e.leaves.len()];
    for f in &fields {
        let padding = f.name.starts_with('_') || f.ty.contains('V');
        let leaves: Vec<usize> = (0..e.leaves.len())
            .filter(|&i| {
                let p = &e.leaves[i].2;
                *p == f.name || p.starts_with(&format!("{}.", f.name))
            })
            .collect();
        if leaves.is_empty() {
            if padding {
                continue;
            }
            let mut members: Vec<String> = e.leaves.iter().map(|l| member(&l.2)).collect();
            members.dedup();
            return Err(format!(
                "file {file}: field '{}' names no member of {}; members: {}",
                f.name,
                e.wgsl,
                members.join(", ")
            ));
        }
        let first = &e.leaves[leaves[0]];
        if u64::from(first.0) != f.offset {
            return Err(format!(
                "file {file}: field '{}' lies at byte {} of each element but {} has it at byte {}",
                f.name, f.offset, e.wgsl, first.0
            ));
        }
        let (kind, size) = leaf_numpy(first.1);
        let want = format!("{kind}{size}");
        if !f.ty.ends_with(&want) || f.count != leaves.len() as u64 {
            return Err(format!(
                "file {file}: field '{}' is {} x {} but {} has {} x {}",
                f.name,
                f.ty,
                f.count,
                e.wgsl,
                want,
                leaves.len()
            ));
        }
        leaves.iter().for_each(|&i| covered[i] = true);
    }
    if let Some(i) = (0..e.leaves.len()).find(|&i| !covered[i] && !e.leaves[i].2.starts_with('_')) {
        return Err(format!("file {file}: no field holds member '{}' of {}", member(&e.leaves[i].2), e.wgsl));
    }
    Ok(())
}

/// The fields of a structured dtype as NumPy writes it in a header, with
/// offsets packed in order (NumPy's default, which `tofile` and `save`
/// keep); `None` for another form (an `offsets` dict).
fn parse(descr: &str) -> Option<Vec<Field>> {
    let inner = descr.trim().strip_prefix('[')?.strip_suffix(']')?;
    let mut fields = Vec::new();
    let mut offset = 0u64;
    let mut rest = inner.trim();
    while !rest.is_empty() {
        // ('name', 'type'[, (shape,)])
        let body = rest.strip_prefix('(')?;
        let (name, after) = quoted(body)?;
        let after = after.trim_start().strip_prefix(',')?.trim_start();
        let (ty, after) = quoted(after)?;
        let mut after = after.trim_start();
        let mut count = 1u64;
        if let Some(shape) = after.strip_prefix(',') {
            let shape = shape.trim_start().strip_prefix('(')?;
            let end = shape.find(')')?;
            for d in shape[..end].split(',').map(str::trim).filter(|d| !d.is_empty()) {
                count = count.checked_mul(d.parse().ok()?)?;
            }
            after = shape[end + 1..].trim_start();
        }
        rest = after.strip_prefix(')')?.trim_start();
        rest = rest.strip_prefix(',').unwrap_or(rest).trim_start();
        let size: u64 = ty.trim_start_matches(['<', '>', '|', '=']).get(1..)?.parse().ok()?;
        fields.push(Field { name: name.to_string(), ty: ty.to_string(), count, offset });
        offset += size * count;
    }
    Some(fields)
}

/// The text of a quoted string at the start of `s` ('…' or "…"), and what follows it.
fn quoted(s: &str) -> Option<(&str, &str)> {
    let q = s.chars().next().filter(|c| *c == '\'' || *c == '"')?;
    let end = s[1..].find(q)? + 1;
    Some((&s[1..end], &s[end + 1..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `struct Boid { position: vec2<f32>, velocity: vec2<f32>, flock: u32, _pad0: u32 }`.
    fn boid() -> Element {
        let mut leaves = Vec::new();
        for (i, p) in ["position.x", "position.y", "velocity.x", "velocity.y"].iter().enumerate() {
            leaves.push((4 * i as u32, 'f', p.to_string()));
        }
        leaves.push((16, 'u', "flock".into()));
        leaves.push((20, 'u', "_pad0".into()));
        Element { stride: 24, header: 0, fixed: None, leaves, wgsl: "array<Boid>".into() }
    }

    #[test]
    fn matching_fields_pass_and_others_are_named() {
        let ok = "[('position', '<f4', (2,)), ('velocity', '<f4', (2,)), ('flock', '<u4'), ('_pad0', '<u4')]";
        assert_eq!(check_structured("b.npy", ok, &boid()), Ok(()));
        let void_pad = "[('position', '<f4', (2,)), ('velocity', '<f4', (2,)), ('flock', '<u4'), ('', '|V4')]";
        assert_eq!(check_structured("b.npy", void_pad, &boid()), Ok(()));
        let swapped = "[('velocity', '<f4', (2,)), ('position', '<f4', (2,)), ('flock', '<u4'), ('_pad0', '<u4')]";
        assert_eq!(
            check_structured("b.npy", swapped, &boid()).unwrap_err(),
            "file b.npy: field 'velocity' lies at byte 0 of each element but array<Boid> has it at byte 8"
        );
        let float_flock = "[('position', '<f4', (2,)), ('velocity', '<f4', (2,)), ('flock', '<f4'), ('_pad0', '<u4')]";
        assert_eq!(
            check_structured("b.npy", float_flock, &boid()).unwrap_err(),
            "file b.npy: field 'flock' is <f4 x 1 but array<Boid> has u4 x 1"
        );
        let renamed = "[('pos', '<f4', (2,)), ('velocity', '<f4', (2,)), ('flock', '<u4'), ('_pad0', '<u4')]";
        assert_eq!(
            check_structured("b.npy", renamed, &boid()).unwrap_err(),
            "file b.npy: field 'pos' names no member of array<Boid>; members: position, velocity, flock, _pad0"
        );
        let missing = "[('position', '<f4', (2,)), ('velocity', '<f4', (2,)), ('_rest', '|V8')]";
        assert_eq!(
            check_structured("b.npy", missing, &boid()).unwrap_err(),
            "file b.npy: no field holds member 'flock' of array<Boid>"
        );
        assert_eq!(check_structured("b.npy", "{'names': ['a']}", &boid()), Ok(()), "by its size alone");
    }
}
