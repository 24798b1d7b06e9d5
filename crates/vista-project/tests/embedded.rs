//! The embedded built-ins are exactly the repository's files: nothing in
//! `shaders/` or `kernels/` is left out of the binary's list, and the list
//! names no file that is gone. (Their text cannot be stale: `include_str!`
//! reads the very file at build time, so comparing it would prove nothing.)

use std::path::{Path, PathBuf};

use vista_project::builtin::{KERNELS, SHADERS};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).unwrap().to_path_buf()
}

fn files(dir: &Path, ext: &str, skip: &[&str]) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            let rel = p.strip_prefix(dir).unwrap().to_string_lossy().replace('\\', "/");
            // WGSL unit tests (`vista test`) are the repository's own, not built-ins.
            if skip.iter().any(|s| rel.starts_with(s)) || rel.ends_with(".test.wgsl") {
                continue;
            }
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == ext) {
                out.push(rel);
            }
        }
    }
    out.sort();
    out
}

fn same_set(embedded: &[(&str, &str)], dir: &Path, ext: &str, skip: &[&str]) {
    let mut names: Vec<String> = embedded.iter().map(|(r, _)| r.to_string()).collect();
    names.sort();
    assert_eq!(names, files(dir, ext, skip), "embedded list vs {}", dir.display());
}

#[test]
fn every_builtin_shader_is_embedded() {
    // shaders/test/ holds test-only shaders (NaN injection), not built-ins.
    same_set(SHADERS, &repo().join("shaders"), "wgsl", &["test/"]);
}

#[test]
fn every_builtin_manifest_is_embedded() {
    same_set(KERNELS, &repo().join("kernels"), "toml", &[]);
}

/// The check fails when a file is left out of the list (a new shader that
/// builtin.rs does not name).
#[test]
#[should_panic(expected = "embedded list vs")]
fn a_shader_left_out_of_the_list_fails() {
    same_set(&SHADERS[1..], &repo().join("shaders"), "wgsl", &["test/"]);
}
