#!/usr/bin/env bash
# `cargo test --workspace`, with the test binaries run JOBS at a time
# (default 2) instead of one after another. Many of them wait on processes,
# the device or the browser for much of their run (the serial suite keeps
# about 1.2 of 2 cores busy), so running two at once cuts the wall time
# without changing a test. Each binary runs from its package's directory,
# as cargo runs it; its output is kept apart and printed whole, in cargo's
# order, with cargo's "Running" headers, so target/test.log and
# ci/test-summary.sh read the same as with `cargo test`. Exits non-zero if
# any binary failed, after printing all of them. Extra arguments go to
# every test binary (e.g. a filter). Doc tests run afterwards, as in cargo.
# JOBS=1 runs them one at a time; EXCLUDE (below) leaves some out.
set -uo pipefail
cargo=${CARGO:-cargo}
jobs=${JOBS:-2}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT

# One line per test binary: <package dir> <source> <executable>, from cargo's build messages.
"$cargo" test --workspace --no-run --message-format=json-render-diagnostics >"$logs/build.json" || exit 1
grep -E '"profile":\{[^}]*"test":true' "$logs/build.json" | grep '"executable":"/' |
    sed -E 's/.*"manifest_path":"([^"]*)\/Cargo.toml".*"src_path":"([^"]*)".*"executable":"([^"]*)".*/\1 \2 \3/' >"$logs/list"
# EXCLUDE: a regex of package dirs / sources to leave out (timing a subset).
if [ -n "${EXCLUDE:-}" ]; then
    grep -vE "$EXCLUDE" "$logs/list" >"$logs/list.kept" || true
    mv "$logs/list.kept" "$logs/list"
fi
[ -s "$logs/list" ] || { echo "test-parallel: no test binaries found" >&2; exit 1; }
# PASSES: "NAME=VALUE ..." environments, each one more run of the golden
# harness (tests/golden.rs) in the same pool, e.g. every case on SwiftShader.
# Each is printed as its own binary, after the workspace's ones.
# GOLDEN_ENV: "NAME=VALUE ..." for the workspace's own golden run, e.g.
# VISTA_VALIDATION=1, so that one run covers lavapipe and the validation
# layer instead of two runs of the same cases on the same driver.
golden=$(grep ' [^ ]*/tests/golden.rs ' "$logs/list" | head -n 1)
if [ -n "${PASSES:-}${GOLDEN_ENV:-}" ] && [ -z "$golden" ]; then
    echo "test-parallel: PASSES and GOLDEN_ENV need tests/golden.rs" >&2; exit 1
fi
if [ -n "${PASSES:-}" ]; then
    while IFS= read -r pass; do
        [ -n "$pass" ] && echo "$golden env:${pass// /,}" >>"$logs/list"
    done <<<"$PASSES"
fi
if [ -n "${GOLDEN_ENV:-}" ]; then
    awk -v g="$golden" -v e="env:${GOLDEN_ENV// /,}" '$0 == g { $0 = $0 " " e } { print }' "$logs/list" >"$logs/list.env"
    mv "$logs/list.env" "$logs/list"
fi
# Longest first, so that the last one to start is short (the order of the
# printed output stays cargo's): the CLI suite and the golden runs.
awk '{ long = ($2 ~ /\/tests\/(cli|golden)\.rs$/) ? 0 : 1; print long "\t" NR "\t" $0 }' "$logs/list" |
    sort -k1,1n -k2,2n | cut -f2- >"$logs/order"

run_one() { # index package-dir source executable env args...
    local i=$1 dir=$2 src=$3 exe=$4 envs=$5
    shift 5
    local vars=()
    [ -n "$envs" ] && IFS=, read -r -a vars <<<"${envs#env:}"
    echo "$i start $(date +%s.%N) $src ${envs}" >> /tmp/timeline
    {
        echo "     Running ${src#"$dir"/} (${exe#"$root"/})${envs:+ with ${vars[*]}}"
        (cd "$dir" && env "${vars[@]}" "$exe" "$@") 2>&1
        echo "exit $?" >"$logs/rc.$i"
    } >"$logs/out.$i" 2>&1
    echo "$i end $(date +%s.%N)" >> /tmp/timeline
}
export -f run_one
export logs root

n=$(wc -l <"$logs/list")
while IFS=$'\t' read -r i line; do
    read -r dir src exe envs <<<"$line"
    printf '%s\0%s\0%s\0%s\0%s\0' "$((i - 1))" "$dir" "$src" "$exe" "${envs:-}"
done <"$logs/order" | xargs -0 -n 5 -P "$jobs" bash -c 'run_one "$@" '"$(printf '%q ' "$@")" _

failed=0
for ((i = 0; i < n; i++)); do
    cat "$logs/out.$i"
    if [ "$(cat "$logs/rc.$i" 2>/dev/null)" != "exit 0" ]; then
        failed=$((failed + 1))
    fi
done
"$cargo" test --workspace --doc "$@" 2>&1 || failed=$((failed + 1))
if [ "$failed" -ne 0 ]; then
    echo "test-parallel: $failed test binaries failed" >&2
    exit 1
fi
