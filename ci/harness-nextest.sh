#!/usr/bin/env bash
# The golden harness under cargo-nextest, which starts one process per
# test: examples/harness-crate's test binary (built by harness-example.sh)
# run by `cargo nextest run` over its own two cases, then over a generated
# project of 20 cheap cases (VISTA_ROOT): twice with --test-threads 4, the
# second run after a bless and with an orphaned golden, and as the README's
# three `--partition count:K/3` runs joined by `vista merge`. Each report,
# results.json, JUnit file and pending.toml must list every case of its run
# exactly once, none of an earlier run; golden::orphans must run once; the
# merged results.json must hold the verdicts and metrics of the
# unpartitioned run. Without cargo-nextest it checks nothing and says so in
# a line make test's closing summary repeats (ci/test-summary.sh).
set -euo pipefail
cd "$(dirname "$0")/../examples/harness-crate"
root=$(cd ../.. && pwd)
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$root/target}
cargo=${CARGO:-cargo}
if ! nextest=$("$cargo" nextest --version 2>/dev/null | head -n 1); then
    echo "!!! harness-nextest: NOT RUN: cargo-nextest is not installed, so the golden harness under nextest (a process per case, one report, partitions merged) was not tested"
    echo "!!! harness-nextest: install it (cargo install --locked cargo-nextest, or a release binary from https://get.nexte.st) and run make test again"
    exit 0
fi
# The vista binary, for bless and merge (make test has built it: a no-op).
(cd "$root" && "$cargo" build -q -p vista-cli)
vista="$CARGO_TARGET_DIR/debug/vista"
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
fail() { echo "harness-nextest: $*"; exit 1; }
# nextest's own runs: its exit status is checked against what each run must give.
nx() { # expected-status log args...
    local want=$1 log=$2 rc=0
    shift 2
    "$cargo" nextest run --hide-progress-bar --test golden "$@" >"$log" 2>&1 || rc=$?
    cat "$log"
    if [ "$want" = ok ] && [ "$rc" -ne 0 ]; then fail "cargo nextest run $* failed (exit $rc)"; fi
    if [ "$want" = fail ] && [ "$rc" -eq 0 ]; then fail "cargo nextest run $* passed, but cases were to fail"; fi
}
# Each of "$@" exactly once in FILE as PATTERN (@ stands for the id), and no more than $# in all.
once_each() { # file pattern all-pattern ids...
    local file=$1 pattern=$2 all=$3 n
    shift 3
    [ -f "$file" ] || fail "no $file"
    for id in "$@"; do
        n=$({ grep -oF "${pattern//@/$id}" "$file" || true; } | wc -l)
        [ "$n" -eq 1 ] || fail "$file lists case $id $n times, not once"
    done
    n=$({ grep -oE "$all" "$file" || true; } | wc -l)
    [ "$n" -eq $# ] || fail "$file lists $n cases, not the $# of the run"
    echo "harness-nextest: ${file#"$t"/} lists $n cases, each once"
}

echo "harness-nextest: $nextest"
# 1. The crate's own two cases, each in a process of its own: one report of both.
nx ok "$t/own.log"
once_each target/vista-report/results.json '"id":"@",' '"id":"[^"]*",' glow glow-blue
once_each target/vista-report/results.json '"test":"@"' '"test":"[^"]*"' wgsl::glow::core_is_one_over_e_at_the_radius

# 2. 20 cases of a tiny kernel at 8x8; c18..c20 have no golden yet.
p="$t/project"
mkdir -p "$p/kernels" "$p/shaders" "$p/golden"
echo 'name = "twenty cheap cases for the harness under nextest"' >"$p/vista.toml"
cat >"$p/kernels/tiny.toml" <<'TOML'
summary = "a ramp: tint * level * (0.5 + 0.5 t), t from the pixel's x + y"
shader = "tiny.wgsl"

[[pass]]
entry = "ramp"

[[param]]
name = "tint"
type = "vec3"
range = [0, 1]
default = [1.0, 0.5, 0.25]
[[param]]
name = "level"
type = "f32"
range = [0, 1]
default = 0.5
TOML
cat >"$p/shaders/tiny.wgsl" <<'WGSL'
struct Tiny {
    tint: vec3<f32>,
    level: f32,
}

@group(0) @binding(0) var<uniform> tiny: Tiny;
@group(0) @binding(1) var out_image: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8)
fn ramp(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(out_image);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let t = f32(id.x + id.y) / f32(size.x + size.y);
    textureStore(out_image, id.xy, vec4<f32>(tiny.tint * (tiny.level * (0.5 + 0.5 * t)), 1.0));
}
WGSL
# Two WGSL unit tests, one failing: each a process of its own too.
cat >"$p/shaders/tiny.test.wgsl" <<'WGSL'
#import wgsl_test::{expectNear}

@test
fn half_is_half() {
    expectNear(0.5 * 1.0, 0.5);
}

@test
fn deliberately_wrong() {
    expectNear(0.5 * 1.0, 0.75);
}
WGSL
units=(wgsl::tiny::deliberately_wrong wgsl::tiny::half_is_half)
ids=()
for i in $(seq 1 20); do
    id=$(printf 'c%02d' "$i")
    ids+=("$id")
    printf '[[case]]\nid = "%s"\nkernel = "tiny"\nsize = "8x8"\nset = { level = %s }\n\n' "$id" \
        "$(awk -v i="$i" 'BEGIN { print i / 20 }')" >>"$p/golden/cases.toml"
done
bless() { "$vista" bless --force --root "$p" --case "$1" >"$t/bless.log" 2>&1 || { cat "$t/bless.log"; fail "vista bless --case '$1' failed"; }; }
bless 'c0*'
bless 'c1[0-7]'
export VISTA_ROOT="$p" VISTA_JUNIT=junit.xml
report="$p/target/vista-report"
check_run() { # pending ids..., then -- and the run's ids
    local pending=()
    while [ "$1" != -- ]; do pending+=("$1"); shift; done
    shift
    once_each "$report/results.json" '"id":"@",' '"id":"[^"]*",' "$@"
    once_each "$report/index.html" 'id="case-@"' 'id="case-[^"]*"' "$@"
    once_each "$p/junit.xml" 'name="golden::tiny::@"' '<testcase name="golden::[^"]*"' "$@"
    # The unit tests, recorded by their own processes, each once in every file.
    once_each "$report/results.json" '"test":"@"' '"test":"[^"]*"' "${units[@]}"
    once_each "$p/junit.xml" '<testcase name="@"' '<testcase name="wgsl::[^"]*"' "${units[@]}"
    once_each "$report/index.html" '<td class="id">@</td>' '<td class="id">wgsl::[^<]*</td>' wgsl::tiny::deliberately_wrong
    grep -qF 'Passed: <code>wgsl::tiny::half_is_half</code>' "$report/index.html" || fail "index.html does not list the passing unit test"
    once_each "$report/pending.toml" '[case.@]' '^\[case\.[A-Za-z0-9_-]*\]$' "${pending[@]}"
    # Every image the index shows is there (no process pruned another's thumbnail).
    local shown broken
    shown=$(grep -oE '(src|href|data-src)="[^"#:]+\.png"' "$report/index.html" | sed -E 's/^[a-z-]+="//; s/"$//' | sort -u)
    broken=$(echo "$shown" | while read -r f; do [ -f "$report/$f" ] || echo "$f"; done | head -3)
    [ -z "$broken" ] || fail "index.html links missing $broken"
    echo "harness-nextest: the $(echo "$shown" | wc -l) images index.html links are all there"
}

# Run 1: 17 pass, 3 missing (pending), each case in its own process, 4 at once.
echo "harness-nextest: run 1 of the 20 cases, 4 processes at once"
nx fail "$t/run1.log" --no-fail-fast --test-threads 4
grep -qE "22 tests run: 18 passed( \([0-9]+ leaky\))?, 4 failed" "$t/run1.log" || fail "run 1 did not run 20 cases and 2 unit tests, 18 passing"
check_run c18 c19 c20 -- "${ids[@]}"

# Run 2, after blessing c18 and with an orphaned golden: nothing of run 1
# is mixed in (c18 passes, pending.toml lists c19 and c20 only), and
# golden::orphans runs once, in a process of its own.
bless c18
cp "$p/golden/tiny/c01.png" "$p/golden/tiny/gone.png"
echo "harness-nextest: run 2 of the 20 cases, 4 processes at once, c18 blessed since run 1, an orphaned golden"
nx fail "$t/run2.log" --no-fail-fast --test-threads 4
grep -qE "23 tests run: 19 passed( \([0-9]+ leaky\))?, 4 failed" "$t/run2.log" || fail "run 2 did not run 20 cases, 2 unit tests and golden::orphans once"
grep -q "gone.png" "$t/run2.log" || fail "golden::orphans did not name the orphaned golden"
check_run c19 c20 -- "${ids[@]}"
grep -F '"id":"c18",' "$report/results.json" | grep -qF '"verdict":"pass"' || fail "c18 is not the pass of run 2"
rm "$p/golden/tiny/gone.png"

# 3. The README's nextest CI recipe, its lines as written (VISTA_ROOT
# stands for a crate inside the project): three partitions, each its own
# report folder (VISTA_REPORT_DIR, relative to the project root), joined by
# `vista merge`: the verdicts and metrics of the whole run.
step=$(grep -F 'cargo nextest run' "$root/README.md" | grep -F -- '--partition count:${{ matrix.shard }}/3' | head -n 1)
[ -n "$step" ] || fail "README.md's CI recipe has no cargo nextest run --partition step"
step=${step#*- run: }
unset VISTA_JUNIT
for k in 1 2 3; do
    echo "harness-nextest: partition $k/3: ${step//'${{ matrix.shard }}'/$k}"
    rc=0
    bash -c "${step//'${{ matrix.shard }}'/$k}" >"$t/part$k.log" 2>&1 || rc=$?
    cat "$t/part$k.log"
    # 100: a case failed (c19 and c20 have no golden); anything else is nextest's own error.
    [ "$rc" -eq 0 ] || [ "$rc" -eq 100 ] || fail "partition $k/3 ended with exit $rc"
done
merge=$(grep -E '^ *- run: vista merge ' "$root/README.md" | head -n 1)
merge=${merge#*- run: }
(cd "$p" && "$vista" ${merge#vista }) >"$t/merge.log" 2>&1 || true
cat "$t/merge.log"
grep -q "merged 3 shards: 18 passed, 2 failed" "$t/merge.log" || fail "vista merge did not join the 3 partitions"
cases_of() { grep -F '"id":"' "$1" | sed -E 's/"gpu_ms":[^,]*,//' | sort; }
if ! diff <(cases_of "$report/results.json") <(cases_of "$p/vista-report/results.json") >"$t/diff"; then
    cat "$t/diff"; fail "the merged partitions' results.json differs from the unpartitioned run's"
fi
echo "harness-nextest: the merged results.json holds the $(cases_of "$report/results.json" | wc -l) cases of the unpartitioned run, verdicts and metrics equal"
once_each "$p/vista-report/results.json" '"test":"@"' '"test":"[^"]*"' "${units[@]}"
once_each "$p/vista-report/pending.toml" '[case.@]' '^\[case\.[A-Za-z0-9_-]*\]$' c19 c20
echo "harness-nextest: under cargo-nextest, 2 and 20 cases each in a process of their own gave one whole report (results.json, index.html, JUnit, pending.toml: every case and WGSL unit test once, none of the run before); golden::orphans ran once; 3 partitions merged equal the whole run, unit tests included"
