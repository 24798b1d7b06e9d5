#!/usr/bin/env bash
# Proves that GPU tests never pass silently without an adapter: with no
# Vulkan driver visible and VISTA_ALLOW_NO_GPU=1, every GPU suite must report
# all of its tests ignored and none passed.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
suites=(golden agreement atmosphere clouds cloudmap heightfield landscape mutate noise reliability backends conformance references)
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# The test executables `cargo test --workspace` built (make test's), run
# directly: `cargo test -p ...` or one package's `--test` would resolve
# features for fewer packages and rebuild vista's crates (a minute in CI).
built=$(${CARGO:-cargo} test --workspace --no-run --message-format=json 2>/dev/null |
    grep -E '"profile":\{[^}]*"test":true' | grep '"executable":"/')
run_suite() { # package-dir suite
    local exe
    exe=$(echo "$built" | grep -F "\"src_path\":\"$1/tests/$2.rs\"" | sed -E 's/.*"executable":"([^"]*)".*/\1/' | awk 'NR == 1')
    [ -n "$exe" ] || { echo "no-gpu-skips: no test executable for $1/tests/$2.rs"; exit 1; }
    (cd "$1" && "$exe")
}
# No Vulkan driver and no Chromium: every backend is missing.
export VISTA_CHROMIUM=/nonexistent/chromium
# The golden harness runs as make test ran it, under the validation layer,
# so that it targets the report make test wrote (checked below).
for s in "${suites[@]}"; do
    validation=0
    [ "$s" = golden ] && validation=1
    VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES=/nonexistent/icd.json VISTA_ALLOW_NO_GPU=1 \
        VISTA_VALIDATION=$validation run_suite "$root" "$s" >>"$log" 2>&1 \
        || { cat "$log"; echo "no-gpu-skips: suite $s failed without an adapter"; exit 1; }
done
# The browser crate's own suite needs only Chromium.
VISTA_ALLOW_NO_GPU=1 run_suite "$root/crates/vista-browser" run >>"$log" 2>&1 \
    || { cat "$log"; echo "no-gpu-skips: the browser suite failed without Chromium"; exit 1; }
suites+=(vista-browser/run)
results=$(grep -E '^test result:' "$log")
n=$(echo "$results" | wc -l)
if [ "$n" -ne "${#suites[@]}" ]; then
    cat "$log"; echo "no-gpu-skips: expected ${#suites[@]} suites, saw $n"; exit 1
fi
if grep -vqE ' 0 passed; 0 failed; [1-9][0-9]* ignored' <<<"$results"; then
    echo "$results"; echo "no-gpu-skips: a GPU test passed or failed without an adapter instead of being ignored"; exit 1
fi
# The skip run must leave the last real report whole: every file it links exists.
report=target/vista-report-lavapipe-validation
if [ -f "$report/index.html" ]; then
    broken=$(grep -oE '(src|href|data-src)="[^"#:]+\.(png|js)"' "$report/index.html" | sed -E 's/^[a-z-]+="//; s/"$//' |
        while read -r f; do [ -f "$report/$f" ] || echo "$f"; done | head -3)
    if [ -n "$broken" ]; then
        echo "no-gpu-skips: the run without an adapter broke $report/index.html: it links missing $broken"; exit 1
    fi
fi
skipped=$(echo "$results" | awk '{ for (i = 1; i <= NF; i++) if ($(i + 1) ~ /^ignored/) s += $i } END { print s }')
echo "no-gpu-skips: without an adapter all $skipped GPU tests of ${#suites[@]} suites are reported ignored, none ok"

# The CLI suite mixes both: its rendering tests must be ignored, its
# bad-input tests (which stop before any GPU work) must still pass.
VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES=/nonexistent/icd.json VISTA_ALLOW_NO_GPU=1 \
    run_suite "$root/crates/vista-cli" cli >"$log" 2>&1 || { cat "$log"; echo "no-gpu-skips: the CLI suite failed without an adapter"; exit 1; }
cli=$(grep -E '^test result:' "$log")
if ! grep -qE ' [1-9][0-9]* passed; 0 failed; [1-9][0-9]* ignored' <<<"$cli"; then
    echo "$cli"; echo "no-gpu-skips: the CLI suite did not both run its bad-input tests and ignore its rendering ones"; exit 1
fi
echo "no-gpu-skips: CLI suite without an adapter: $(echo "$cli" | sed 's/.*ok\. //; s/; 0 measured.*//')"
