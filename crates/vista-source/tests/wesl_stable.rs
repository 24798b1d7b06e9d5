//! The wesl crate's output names the shader by its hash, and a worker's
//! shader set must match its parent's, so compiling one package must give
//! the same text in every process. An integration test (an edge of its
//! own): it starts itself again to compile in two more processes, whose
//! hash maps are seeded apart, told so by a variable.

use vista_source::{Assembled, SourceSpec, compile_wesl};

/// Many modules and a package, compiled 20 times: the text and the
/// parts' order must not change (a hash of them names the shader).
#[test]
fn compiling_twice_gives_the_same_text() {
    let text = twenty_compiles();
    // And in two more processes (their hash maps are seeded apart).
    if std::env::var_os("VISTA_WESL_CHILD").is_some() {
        println!("text-hash {:x}", fnv(&text));
        return;
    }
    for _ in 0..2 {
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args(["--exact", "compiling_twice_gives_the_same_text", "--nocapture"])
            .env("VISTA_WESL_CHILD", "1")
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(stdout.contains(&format!("text-hash {:x}", fnv(&text))), "{stdout}");
    }
}

fn fnv(text: &str) -> u64 {
    text.bytes().fold(0xcbf29ce484222325, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100000001b3))
}

fn twenty_compiles() -> String {
    let mut files: Vec<(String, String)> = vec![(
        "vendor/consts/package.wesl".into(),
        "public const SCALE: f32 = 2.0;\npublic const BIAS: f32 = 0.5;\n".into(),
    )];
    let mut main = String::new();
    let mut body = String::new();
    for i in 0..12 {
        files.push((
            format!("shaders/m{i}.wesl"),
            format!("import consts::BIAS;\npublic fn f{i}() -> f32 {{ return f32({i}) + BIAS; }}\n"),
        ));
        main += &format!("import package::m{i}::f{i};\n");
        body += &format!(" + f{i}()");
    }
    main += &format!("import consts::SCALE;\n@compute @workgroup_size(1) fn main() {{ let x = SCALE{body}; }}\n");
    files.push(("shaders/k.wesl".into(), main));
    let read = |p: &str| files.iter().find(|(f, _)| f == p).map(|(_, t)| (t.clone(), format!("/p/{p}")));
    let spec = SourceSpec { packages: vec![("consts".into(), "vendor/consts".into())], ..Default::default() };
    let first = compile_wesl("shaders/k.wesl", &spec, &[], &read).unwrap();
    for _ in 0..20 {
        let again = compile_wesl("shaders/k.wesl", &spec, &[], &read).unwrap();
        assert_eq!(again.text, first.text);
        let paths = |a: &Assembled| a.parts.iter().map(|p| p.path.clone()).collect::<Vec<_>>();
        assert_eq!(paths(&again), paths(&first));
    }
    first.text
}
