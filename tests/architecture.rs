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

/// The first identifier of `text`.
fn ident(text: &str) -> &str {
    let end = text.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(text.len());
    &text[..end]
}

/// The first segment of each path a `use` group `{a, b::C, d::{e, f}}` names
/// (`text` starts after the `{`).
fn group_heads(text: &str) -> Vec<&str> {
    let (mut depth, mut heads, mut start) = (0, Vec::new(), 0);
    for (i, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                heads.push(ident(text[start..i].trim_start()));
                break;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                heads.push(ident(text[start..i].trim_start()));
                start = i + 1;
            }
            _ => {}
        }
    }
    heads.into_iter().filter(|h| !h.is_empty()).collect()
}

/// One crate's module graph: a node per top-level module (a file or folder
/// under `src/`) and `crate` for the root file; an edge where a module's
/// code names another's items (`crate::m::..`, `use crate::{m, ..}`,
/// `super::` from a top-level file, a root item re-exported from `m`). The
/// root's own `mod` and `pub use` lines declare and re-export; they are not
/// uses.
fn module_graph(files: &[(PathBuf, String)], src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let node = |p: &Path| {
        let rel = p.strip_prefix(src).unwrap();
        let first = rel.components().next().unwrap().as_os_str().to_string_lossy().into_owned();
        match first.as_str() {
            "lib.rs" | "main.rs" => "crate".to_string(),
            _ => first.trim_end_matches(".rs").to_string(),
        }
    };
    let nodes: BTreeSet<String> = files.iter().map(|(p, _)| node(p)).collect();
    let root = files.iter().find(|(p, _)| node(p) == "crate").map(|(_, c)| c.as_str()).unwrap_or("");
    // Root items re-exported from a module: `pub use m::{A, B};`, `pub use m::A;`.
    let mut reexported: BTreeMap<String, String> = BTreeMap::new();
    for line in root.lines().map(str::trim) {
        let Some(rest) = line.strip_prefix("pub use ").or_else(|| line.strip_prefix("pub(crate) use ")) else {
            continue;
        };
        let m = ident(rest);
        if !nodes.contains(m) {
            continue;
        }
        let tail = rest[m.len()..].trim_start_matches("::");
        let names: Vec<&str> = match tail.strip_prefix('{') {
            Some(group) => group.split([',', '}']).map(|s| s.trim().rsplit("::").next().unwrap()).collect(),
            None => vec![tail.trim_end_matches(';').rsplit("::").next().unwrap()],
        };
        for n in names.into_iter().filter(|n| !n.is_empty()) {
            reexported.insert(n.to_string(), m.to_string());
        }
    }
    let mut graph: BTreeMap<String, BTreeSet<String>> = nodes.iter().map(|n| (n.clone(), BTreeSet::new())).collect();
    for (path, code) in files {
        let from = node(path);
        let top_level = path.parent() == Some(src);
        let target = |name: &str| -> String {
            if nodes.contains(name) {
                name.to_string()
            } else {
                reexported.get(name).cloned().unwrap_or_else(|| "crate".to_string())
            }
        };
        let mut to = Vec::new();
        for line in code.lines() {
            let t = line.trim_start();
            if from == "crate" && (t.starts_with("pub use ") || t.starts_with("pub(crate) use ") || t.contains("mod "))
            {
                continue;
            }
            let mut prefixes = vec!["crate::"];
            if top_level && from != "crate" {
                prefixes.push("super::");
            }
            for prefix in prefixes {
                for (at, _) in line.match_indices(prefix) {
                    let before = line[..at].chars().next_back();
                    if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':' || c == '$') {
                        continue;
                    }
                    let rest = &line[at + prefix.len()..];
                    match rest.strip_prefix('{') {
                        Some(group) => to.extend(group_heads(group).into_iter().map(target)),
                        None => to.push(target(ident(rest))),
                    }
                }
            }
            if from == "crate" {
                for m in nodes.iter().filter(|m| *m != "crate") {
                    let used = line.match_indices(&format!("{m}::")).any(|(at, _)| {
                        !line[..at]
                            .chars()
                            .next_back()
                            .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':')
                    });
                    if used {
                        to.push(m.clone());
                    }
                }
            }
        }
        let edges = graph.get_mut(&from).unwrap();
        edges.extend(to.into_iter().filter(|t| *t != from));
    }
    graph
}

/// The cycles of `graph`: each strongly connected set of two or more nodes.
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<BTreeSet<String>> {
    let reach = |from: &str| {
        let (mut seen, mut todo) = (BTreeSet::new(), vec![from.to_string()]);
        while let Some(n) = todo.pop() {
            for m in graph.get(&n).into_iter().flatten() {
                if seen.insert(m.clone()) {
                    todo.push(m.clone());
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&String, BTreeSet<String>> = graph.keys().map(|n| (n, reach(n))).collect();
    let mut out: Vec<BTreeSet<String>> = Vec::new();
    for n in graph.keys() {
        let set: BTreeSet<String> =
            graph.keys().filter(|m| *m == n || (reaches[n].contains(*m) && reaches[m].contains(n))).cloned().collect();
        if set.len() > 1 && !out.contains(&set) {
            out.push(set);
        }
    }
    out
}

#[test]
fn no_crate_has_a_module_cycle() {
    let mut by_crate: BTreeMap<String, Vec<(PathBuf, String)>> = BTreeMap::new();
    for (krate, path, code) in non_test_sources() {
        by_crate.entry(krate).or_default().push((path, code));
    }
    let mut found = Vec::new();
    for (krate, files) in &by_crate {
        let src = files[0].0.ancestors().find(|a| a.ends_with("src")).unwrap().to_path_buf();
        let graph = module_graph(files, &src);
        for cycle in cycles(&graph) {
            let edges: Vec<String> = cycle
                .iter()
                .flat_map(|a| graph[a].iter().filter(|b| cycle.contains(*b)).map(move |b| format!("{a} -> {b}")))
                .collect();
            found.push(format!("{krate}: {}", edges.join(", ")));
        }
    }
    assert!(found.is_empty(), "module cycles:\n{}", found.join("\n"));
}

/// The detector itself: a root that uses a module which names a root item
/// is a cycle; a root item re-exported from a module is that module's.
#[test]
fn the_module_cycle_check_sees_a_cycle_and_a_reexport() {
    let src = Path::new("/x/src");
    let file = |rel: &str, code: &str| (src.join(rel), code.to_string());
    let cyclic = [file("lib.rs", "mod a;\npub struct E;\nfn f() { a::g() }\n"), file("a.rs", "use crate::E;\n")];
    assert_eq!(cycles(&module_graph(&cyclic, src)).len(), 1);
    let layered = [
        file("lib.rs", "mod a;\nmod b;\npub use b::E;\n"),
        file("a.rs", "use crate::{E, b::F};\n"),
        file("b.rs", "pub struct E;\n"),
    ];
    let graph = module_graph(&layered, src);
    assert!(cycles(&graph).is_empty(), "{graph:?}");
    assert_eq!(graph["a"], BTreeSet::from(["b".to_string()]));
}

/// Every non-test function of `code` longer than `limit` lines, as
/// `name (lines)`: a `fn` line at some indent runs to the first `}` line
/// at the same indent (the code is rustfmt's).
fn long_functions(code: &str, limit: usize) -> Vec<String> {
    let lines: Vec<&str> = code.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let t = line.trim_start();
        let indent = line.len() - t.len();
        let signature =
            ["pub fn ", "pub(crate) fn ", "fn ", "pub const fn ", "const fn ", "unsafe fn ", "pub unsafe fn "]
                .iter()
                .find_map(|p| t.strip_prefix(p));
        let Some(rest) = signature else { continue };
        let close = format!("{}}}", " ".repeat(indent));
        let Some(end) = lines[i..].iter().position(|l| *l == close || l.trim_end().ends_with(';') && l == line) else {
            continue;
        };
        if end + 1 > limit {
            out.push(format!("{} ({} lines)", ident(rest), end + 1));
        }
    }
    out
}

#[test]
fn no_non_test_function_is_over_150_lines() {
    // Counted with their comments: the file as written, cut at its tests.
    let long: Vec<String> = non_test_sources()
        .into_iter()
        .flat_map(|(_, path, _)| {
            let text = std::fs::read_to_string(&path).expect("source");
            let code = text.split("#[cfg(test)]").next().unwrap().to_string();
            let file = path.strip_prefix(root()).unwrap().display().to_string();
            long_functions(&code, 150).into_iter().map(move |f| format!("{file}: {f}"))
        })
        .collect();
    assert!(long.is_empty(), "functions over 150 lines:\n{}", long.join("\n"));
    let sample = format!("fn short() {{\n{}}}\nfn long() {{\n{}}}\n", "    x;\n".repeat(3), "    x;\n".repeat(151));
    assert_eq!(long_functions(&sample, 150), ["long (153 lines)"], "the measure itself");
}
