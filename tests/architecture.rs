//! ARCHITECTURE.md's claims marked *(tested)*, checked against the code:
//! the crate table against `cargo metadata`, and each "only these crates"
//! claim against a scan of every crate's non-test sources (as
//! `src/config.rs` scans for environment reads). A claim the code stops
//! keeping fails here, and so does a doc that stops telling the truth.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn architecture() -> String {
    std::fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md")
}

/// The `| crate | owns | uses |` rows of the Crates table.
fn documented_uses() -> BTreeMap<String, BTreeSet<String>> {
    let doc = architecture();
    let table = &doc[doc.find("## Crates").expect("a Crates section")..];
    table
        .lines()
        .skip_while(|l| !l.starts_with("| crate |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cells: Vec<&str> = l.trim_matches('|').split('|').map(str::trim).collect();
            let uses = match cells[2] {
                "none" => BTreeSet::new(),
                list => list.split(", ").map(str::to_string).collect(),
            };
            (cells[0].to_string(), uses)
        })
        .collect()
}

/// Every workspace package's normal dependencies, by `cargo metadata`.
fn metadata() -> BTreeMap<String, BTreeSet<String>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .current_dir(root())
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .output()
        .expect("cargo metadata");
    assert!(out.status.success(), "cargo metadata: {}", String::from_utf8_lossy(&out.stderr));
    let m: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    m["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .filter(|p| !p["manifest_path"].as_str().unwrap_or("").contains("/examples/"))
        .map(|p| {
            let deps = p["dependencies"]
                .as_array()
                .expect("dependencies")
                .iter()
                .filter(|d| d["kind"].is_null())
                .map(|d| d["name"].as_str().expect("name").to_string())
                .collect();
            (p["name"].as_str().expect("name").to_string(), deps)
        })
        .collect()
}

#[test]
fn the_crate_table_is_the_dependency_graph() {
    let doc = documented_uses();
    let packages = metadata();
    let names: BTreeSet<&String> = packages.keys().collect();
    assert_eq!(doc.keys().collect::<BTreeSet<_>>(), names, "one row per workspace package");
    let order: Vec<&String> = doc.keys().collect();
    let listed: Vec<String> = {
        let text = architecture();
        let table = &text[text.find("| crate |").expect("table")..];
        table
            .lines()
            .skip(2)
            .take_while(|l| l.starts_with('|'))
            .map(|l| l.split('|').nth(1).unwrap().trim().to_string())
            .collect()
    };
    for (name, uses) in &doc {
        let real: BTreeSet<String> = packages[name].iter().filter(|d| names.contains(d)).cloned().collect();
        assert_eq!(uses, &real, "ARCHITECTURE.md's uses of {name}");
        // "A crate never uses one listed below it."
        let at = listed.iter().position(|n| n == name).expect("listed");
        for u in uses {
            let used_at = listed.iter().position(|n| n == u).expect("a listed crate");
            assert!(used_at < at, "{name} uses {u}, listed below it");
        }
    }
    assert!(order.len() >= 15, "{order:?}");
}

/// Every `.rs` file under `crates/*/src` and `src/`, with its crate's name,
/// cut at its trailing test module, comment lines dropped.
fn non_test_sources() -> Vec<(String, PathBuf, String)> {
    let mut out = Vec::new();
    let mut dirs: Vec<(String, PathBuf)> = vec![("vista".into(), root().join("src"))];
    for e in std::fs::read_dir(root().join("crates")).expect("crates").flatten() {
        dirs.push((e.file_name().to_string_lossy().into_owned(), e.path().join("src")));
    }
    while let Some((krate, d)) = dirs.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                dirs.push((krate.clone(), p));
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = std::fs::read_to_string(&p).expect("source");
                let code: String = text
                    .split("#[cfg(test)]")
                    .next()
                    .unwrap()
                    .split("#[cfg(all(test")
                    .next()
                    .unwrap()
                    .lines()
                    .filter(|l| !l.trim_start().starts_with("//"))
                    .map(|l| format!("{l}\n"))
                    .collect();
                out.push((krate.clone(), p, code));
            }
        }
    }
    assert!(out.len() > 100, "found only {} sources", out.len());
    out
}

fn crates_matching(needles: &[&str]) -> BTreeSet<String> {
    non_test_sources()
        .into_iter()
        .filter(|(_, _, code)| needles.iter().any(|n| code.contains(n)))
        .map(|(k, _, _)| k)
        .collect()
}

/// The crate names in the invariant bullet that starts with `lead`.
fn crates_named_after(lead: &str) -> BTreeSet<String> {
    let doc = architecture();
    let at = doc.find(lead).unwrap_or_else(|| panic!("ARCHITECTURE.md has no {lead:?}"));
    let bullet = &doc[at..doc[at..].find("\n- ").map_or(doc.len(), |e| at + e)];
    let claim = &bullet[bullet.find("*(tested)*:").expect("a tested list") + "*(tested)*:".len()..];
    claim
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
        .filter(|w| *w == "vista" || w.starts_with("vista-"))
        .map(str::to_string)
        .collect()
}

#[test]
fn only_the_listed_crates_read_files() {
    let reading = crates_matching(&["fs::read", "read_to_string(", "File::open(", "read_dir("]);
    assert_eq!(reading, crates_named_after("Files are read by these crates only"), "crates that read files");
}

#[test]
fn only_vista_gpu_talks_to_wgpu_and_only_its_context_makes_pipelines() {
    let with_wgpu: Vec<String> =
        metadata().into_iter().filter(|(_, deps)| deps.contains("wgpu")).map(|(name, _)| name).collect();
    assert_eq!(with_wgpu, ["vista-gpu"], "packages depending on wgpu");
    let making: Vec<PathBuf> = non_test_sources()
        .into_iter()
        .filter(|(_, _, code)| code.contains("create_compute_pipeline(") || code.contains("create_render_pipeline("))
        .map(|(_, p, _)| p.strip_prefix(root()).unwrap().to_path_buf())
        .collect();
    assert_eq!(making, [PathBuf::from("crates/vista-gpu/src/context.rs")], "files that create pipelines");
}

#[test]
fn files_are_written_by_rename_but_for_the_two_named_exceptions() {
    let mut writers: Vec<String> = non_test_sources()
        .into_iter()
        .filter(|(k, _, code)| {
            // vista-image's own PngFile writes through a temp file too.
            let code = code.replace("PngFile::create(", "");
            k != "vista-image" && ["fs::write(", "File::create(", "OpenOptions"].iter().any(|n| code.contains(n))
        })
        .map(|(_, p, _)| p.strip_prefix(root()).unwrap().display().to_string())
        .collect();
    writers.sort();
    // Chromium's runner page in its own profile folder; render's probe of
    // its output folder.
    assert_eq!(writers, ["crates/vista-browser/src/lib.rs", "crates/vista-cli/src/render.rs"]);
    let doc = architecture();
    assert!(doc.contains("Chromium's page in its own") && doc.contains("`render`'s writability probe"), "named there");
}
