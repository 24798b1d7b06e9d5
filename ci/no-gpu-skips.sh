#!/usr/bin/env bash
# Proves that GPU tests never pass silently without an adapter: with no
# Vulkan driver visible and VISTA_ALLOW_NO_GPU=1, every GPU suite must report
# all of its tests ignored and none passed.
set -euo pipefail
cd "$(dirname "$0")/.."
suites=(golden agreement atmosphere clouds cloudmap heightfield landscape mutate noise reliability backends)
args=()
for s in "${suites[@]}"; do args+=(--test "$s"); done
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# No Vulkan driver and no Chromium: every backend is missing.
export VISTA_CHROMIUM=/nonexistent/chromium
VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES=/nonexistent/icd.json VISTA_ALLOW_NO_GPU=1 \
    ${CARGO:-cargo} test -q "${args[@]}" >"$log" 2>&1 || { cat "$log"; echo "no-gpu-skips: the suites failed without an adapter"; exit 1; }
# The browser crate's own suite needs only Chromium.
VISTA_ALLOW_NO_GPU=1 ${CARGO:-cargo} test -q -p vista-browser --test run >>"$log" 2>&1 \
    || { cat "$log"; echo "no-gpu-skips: the browser suite failed without Chromium"; exit 1; }
suites+=(vista-browser/run)
results=$(grep -E '^test result:' "$log")
n=$(echo "$results" | wc -l)
if [ "$n" -ne "${#suites[@]}" ]; then
    cat "$log"; echo "no-gpu-skips: expected ${#suites[@]} suites, saw $n"; exit 1
fi
if echo "$results" | grep -vqE ' 0 passed; 0 failed; [1-9][0-9]* ignored'; then
    echo "$results"; echo "no-gpu-skips: a GPU test passed or failed without an adapter instead of being ignored"; exit 1
fi
# The skip run must leave the last real report whole: every file it links exists.
report=target/vista-report
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
    ${CARGO:-cargo} test -q -p vista-cli --test cli >"$log" 2>&1 || { cat "$log"; echo "no-gpu-skips: the CLI suite failed without an adapter"; exit 1; }
cli=$(grep -E '^test result:' "$log")
if ! echo "$cli" | grep -qE ' [1-9][0-9]* passed; 0 failed; [1-9][0-9]* ignored'; then
    echo "$cli"; echo "no-gpu-skips: the CLI suite did not both run its bad-input tests and ignore its rendering ones"; exit 1
fi
echo "no-gpu-skips: CLI suite without an adapter: $(echo "$cli" | sed 's/.*ok\. //; s/; 0 measured.*//')"
