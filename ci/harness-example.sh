#!/usr/bin/env bash
# examples/harness-crate: a crate outside vista's workspace (its own
# [workspace], vista as a path dependency) whose tests/golden.rs is only
# `vista::harness::main()`. Its golden cases run inside its own `cargo test`,
# each a test named golden::<kernel>::<case> that libtest's arguments select.
# It shares vista's target directory, so the third-party crates build once.
set -euo pipefail
ci=$(cd "$(dirname "$0")" && pwd)
cd "$ci/../examples/harness-crate"
CARGO_TARGET_DIR="$(cd ../.. && pwd)/target"
export CARGO_TARGET_DIR
cargo=${CARGO:-cargo}
list=$("$cargo" test -q --test golden -- --list)
for t in golden::glow::glow golden::glow::glow-blue wgsl::glow::core_is_one_over_e_at_the_radius; do
    grep -qx "$t: test" <<<"$list" || { echo "$list"; echo "harness-example: --list lacks $t"; exit 1; }
done
"$cargo" test --test golden
# The WGSL unit test is in the report beside the cases.
unit=wgsl::glow::core_is_one_over_e_at_the_radius
grep -qF "\"test\":\"$unit\"" target/vista-report/results.json ||
    { echo "harness-example: results.json does not list $unit"; exit 1; }
grep -qF 'id="unit-tests"' target/vista-report/index.html && grep -qF "$unit" target/vista-report/index.html ||
    { echo "harness-example: index.html has no WGSL unit tests section listing $unit"; exit 1; }
# VISTA_COVERAGE=1: the cases and the unit test file run again with
# counters; lcov.info beside the report sums both (the unit test's own
# lines are in glow.test.wgsl), and the verdicts are the plain run's.
VISTA_COVERAGE=1 "$cargo" test -q --test golden >/dev/null
lcov=target/vista-report/lcov.info
for sf in shaders/glow.wgsl shaders/glow.test.wgsl; do
    grep -qx "SF:$sf" "$lcov" || { cat "$lcov"; echo "harness-example: VISTA_COVERAGE=1 left no counts of $sf"; exit 1; }
done
grep -q 'WGSL coverage: <a href="coverage/index.html">' target/vista-report/index.html ||
    { echo "harness-example: the report has no coverage line"; exit 1; }
"$cargo" test -q --test golden >/dev/null
[ ! -e "$lcov" ] || { echo "harness-example: a run without coverage left the older lcov.info"; exit 1; }
one=$("$cargo" test -q --test golden -- --exact golden::glow::glow-blue 2>&1)
grep -q "1 passed; 0 failed; 0 ignored; 0 measured; 2 filtered out" <<<"$one" ||
    { echo "$one"; echo "harness-example: --exact did not select one case"; exit 1; }
for f in index.html results.json; do
    [ -f "target/vista-report/$f" ] || { echo "harness-example: no $f in examples/harness-crate/target/vista-report"; exit 1; }
done
# A golden no case refers to fails one more test, golden::orphans.
orphan=golden/glow/gone.png
cp golden/glow/glow.png "$orphan"
trap 'rm -f "$orphan"' EXIT
if out=$("$cargo" test -q --test golden 2>&1); then
    echo "$out"; echo "harness-example: an orphaned golden did not fail the run"; exit 1
fi
grep -q "golden::orphans.*FAILED\|---- golden::orphans" <<<"$out" ||
    { echo "$out"; echo "harness-example: the orphaned golden did not fail golden::orphans"; exit 1; }
grep -q "gone.png" <<<"$out" || { echo "$out"; echo "harness-example: golden::orphans did not name the file"; exit 1; }
rm -f "$orphan"
# A driver crash (injected) fails its case's test alone: the worker dies, the next case gets a new one.
if out=$(VISTA_WORKER_FAULT=segv:glow "$cargo" test -q --test golden 2>&1); then
    echo "$out"; echo "harness-example: a crashed case did not fail the run"; exit 1
fi
grep -q "crashed (signal 11, SIGSEGV) in pass 1" <<<"$out" ||
    { echo "$out"; echo "harness-example: the crash was not named"; exit 1; }
grep -q "2 passed; 1 failed" <<<"$out" || { echo "$out"; echo "harness-example: the other case and the unit test did not pass"; exit 1; }
echo "harness-example: the crate's own cargo test ran its 2 golden cases and its WGSL unit test through vista::harness::main()"
# The same test binary under cargo-nextest, a process per case (where nextest is installed; else a loud line).
bash "$ci/harness-nextest.sh"
