use super::*;

/// A compute kernel with known paths, one statement per line.
const KERNEL: &str = "@group(0) @binding(0) var<storage, read_write> out: array<u32, 8>;
fn unused(x: u32) -> u32 {
    return x * 2u;
}
@compute @workgroup_size(8)
fn main(@builtin(local_invocation_index) i: u32) {
    var acc = 0u;
    if (i < 3u) {
        acc = 1u;
    } else {
        acc = 2u;
    }
    for (var k = 0u; k < i; k++) {
        acc += k;
        if (k == 4u) { break; }
    }
    out[i] = acc;
}
@vertex
fn vs(@builtin(vertex_index) v: u32) -> @builtin(position) vec4f {
    return vec4f(f32(helper(v)), 0.0, 0.0, 1.0);
}
fn helper(v: u32) -> u32 {
    return v + 1u;
}
";

fn parse(text: &str) -> Module {
    naga::front::wgsl::parse_str(text).unwrap()
}

fn validate(m: &Module) -> naga::valid::ModuleInfo {
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(m)
        .unwrap_or_else(|e| panic!("{e:?}"))
}

fn line_of(text: &str) -> impl Fn(Span) -> Option<Place> + '_ {
    move |s: Span| {
        let r = s.to_range()?;
        let loc = s.location(text);
        (r.end > r.start).then(|| Place { file: "k.wgsl".into(), line: loc.line_number, col: loc.line_position })
    }
}

/// The instrumented module validates and writes back as WGSL with one
/// counter buffer; every counted line is a statement's; without vertex
/// counting, the vertex entry and what it calls are not measured.
#[test]
fn the_instrumented_module_validates_and_counts_statement_lines() {
    let module = parse(KERNEL);
    let inst = instrument(&module, 1, false);
    validate(&inst.module);
    let info = validate(&inst.module);
    let wgsl = naga::back::wgsl::write_string(&inst.module, &info, naga::back::wgsl::WriterFlags::empty()).unwrap();
    assert!(
        wgsl.contains("@group(1) @binding(0) \nvar<storage, read_write> vista_coverage: array<atomic<u32>>;")
            || wgsl.contains("var<storage, read_write> vista_coverage: array<atomic<u32>>;"),
        "{wgsl}"
    );
    assert_eq!(inst.not_measured, ["helper", "vs"]);
    let place = line_of(KERNEL);
    let mut lines: Vec<u32> =
        inst.counters.iter().flat_map(|c| c.spans.iter().filter_map(|s| place(*s)).map(|p| p.line)).collect();
    lines.sort();
    lines.dedup();
    // unused's return (3) and main's statements, nothing else (`var acc =
    // 0u` is a declaration with a constant: no statement in naga's IR).
    assert_eq!(lines, [3, 8, 9, 11, 13, 14, 15, 17], "{:#?}", inst.counters);
    // Arms: the if's two; the loop's body and its condition's two (naga
    // lowers `for` to a loop whose body starts `if !(k < i) { break; }`);
    // the inner if's two.
    let mut arms: Vec<(u32, u32)> =
        inst.counters.iter().filter_map(|c| c.arm).map(|a| (place(a.at).unwrap().line, a.branch)).collect();
    arms.sort();
    assert_eq!(arms, [(8, 0), (8, 1), (13, 0), (13, 0), (13, 1), (15, 0), (15, 1)]);
}

/// Where the vertex stage may write storage, the vertex entry and what
/// it calls are counted like any function, and the module still validates.
#[test]
fn vertex_code_is_counted_where_the_vertex_stage_may_write_storage() {
    let inst = instrument(&parse(KERNEL), 1, true);
    validate(&inst.module);
    assert!(inst.not_measured.is_empty(), "{:?}", inst.not_measured);
    let place = line_of(KERNEL);
    let mut lines: Vec<u32> =
        inst.counters.iter().flat_map(|c| c.spans.iter().filter_map(|s| place(*s)).map(|p| p.line)).collect();
    lines.sort();
    lines.dedup();
    // The compute lines as without, and vs's return (21) and helper's (24).
    assert_eq!(lines, [3, 8, 9, 11, 13, 14, 15, 17, 21, 24], "{:#?}", inst.counters);
    let functions: std::collections::BTreeSet<&str> = inst.counters.iter().map(|c| c.function.as_str()).collect();
    assert!(functions.contains("vs") && functions.contains("helper"), "{functions:?}");
}

/// Counts map lines to their segments' values, summed over runs; LCOV
/// lists every line (0 where never run) and each arm, `-` where its
/// statement never ran.
#[test]
fn counts_sum_runs_and_write_lcov() {
    let module = parse(KERNEL);
    let inst = instrument(&module, 1, false);
    let place = line_of(KERNEL);
    // A run where only `unused` never ran: every counter 2 but each if's
    // accept arm 1, so that its reject arm (the if's runs less the accept
    // arm's, no word of its own) is 1 too.
    let accepts: Vec<usize> = inst.counters.iter().filter_map(|c| c.derived.map(|d| d.1)).collect();
    let values: Vec<u32> = (0..inst.counters.len())
        .map(|i| match (inst.counters[i].function.as_str(), accepts.contains(&i)) {
            ("unused", _) => 0,
            (_, true) => 1,
            _ => 2,
        })
        .collect();
    let mut counts = Counts::default();
    counts.add(&inst.counters, &values, &place);
    counts.add(&inst.counters, &values, &place);
    let lines = counts.lines("k.wgsl");
    assert_eq!(lines[0], (3, 0));
    assert_eq!(&lines[1..], [(8, 4), (9, 2), (11, 2), (13, 4), (14, 4), (15, 4), (17, 4)]);
    let lcov = counts.lcov("vista");
    assert!(lcov.starts_with("TN:vista\nSF:k.wgsl\n"), "{lcov}");
    assert!(lcov.contains("DA:3,0\n") && lcov.contains("DA:9,2\n") && lcov.contains("DA:13,4\n"), "{lcov}");
    assert!(lcov.contains("BRDA:8,5,0,2\n") && lcov.contains("BRDA:8,5,1,2\n"), "{lcov}");
    assert!(lcov.contains("BRDA:13,5,0,4\n") && lcov.contains("BRDA:13,21,1,2\n"), "the for loop's condition: {lcov}");
    assert!(lcov.contains("BRF:7\nBRH:7\n") && lcov.contains("LF:8\nLH:7\nend_of_record\n"), "{lcov}");
    assert_eq!(counts.totals(), (8, 7, 7, 7));
    // A run where nothing ran: every line 0, every arm `-` (never reached).
    let mut none = Counts::default();
    none.add(&inst.counters, &vec![0; inst.counters.len()], &place);
    let lcov = none.lcov("vista");
    assert!(lcov.contains("BRDA:8,5,0,-\n") && lcov.contains("DA:17,0\n") && lcov.contains("LH:0\n"), "{lcov}");
    let mut twice = counts.clone();
    twice.merge(&counts);
    assert_eq!(twice.lines("k.wgsl")[1].1, 8);
}

/// LCOV read back is the counts written: what sums cases and shards.
#[test]
fn lcov_reads_back_as_the_counts_it_was_written_from() {
    let module = parse(KERNEL);
    let inst = instrument(&module, 1, false);
    let place = line_of(KERNEL);
    let values: Vec<u32> = (0..inst.counters.len() as u32).collect();
    let mut counts = Counts::default();
    counts.add(&inst.counters, &values, &place);
    let main = Place { file: "k.wgsl".into(), line: 8, col: 1 };
    counts.add_functions(&[(main, "main".into(), 1)], &values);
    assert!(counts.lcov("a").contains("FN:8,main\nFNDA:1,main\nFNF:1\nFNH:1\n"), "{}", counts.lcov("a"));
    assert_eq!(Counts::from_lcov(&counts.lcov("a")), counts);
    let mut none = Counts::default();
    none.add(&inst.counters, &vec![0; inst.counters.len()], &place);
    assert_eq!(Counts::from_lcov(&none.lcov("a")), none, "`-` arms read as 0");
    let mut sum = Counts::from_lcov(&counts.lcov("a"));
    sum.merge(&Counts::from_lcov(&counts.lcov("b")));
    let mut twice = counts.clone();
    twice.merge(&counts);
    assert_eq!(sum, twice);
    assert!(Counts::default().is_empty() && !counts.is_empty());
}

/// One name declared on two lines of a file (WESL `@if` alternatives) is
/// two functions, written `name@line` (LCOV joins `FNDA` to `FN` by name)
/// and read back as they were; alone, a name is written as it is.
#[test]
fn a_name_declared_on_two_lines_is_two_functions() {
    let mut counts = Counts::from_lcov("SF:c.wesl\nDA:8,3\nend_of_record\n");
    let at = |line| Place { file: "c.wesl".into(), line, col: 1 };
    let functions =
        [(at(7), "curve".to_string(), 0), (at(22), "curve".to_string(), 1), (at(30), "other".to_string(), 2)];
    counts.add_functions(&functions, &[3, 5, 0]);
    let lcov = counts.lcov("t");
    let want =
        "FN:7,curve@7\nFN:22,curve@22\nFN:30,other\nFNDA:3,curve@7\nFNDA:5,curve@22\nFNDA:0,other\nFNF:3\nFNH:2\n";
    assert!(lcov.contains(want), "{lcov}");
    assert_eq!(Counts::from_lcov(&lcov), counts);
    let mut twice = Counts::from_lcov(&lcov);
    twice.merge(&counts);
    assert!(twice.lcov("t").contains("FNDA:6,curve@7\nFNDA:10,curve@22\n"), "{}", twice.lcov("t"));
    counts.keep_lines("c.wesl", 10);
    assert!(counts.lcov("t").contains("FN:7,curve\nFNDA:3,curve\nFNF:1\nFNH:1\n"), "{}", counts.lcov("t"));
}
