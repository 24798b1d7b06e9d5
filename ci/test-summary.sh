#!/usr/bin/env bash
# Sums the closing lines of every test binary in a `cargo test` log, so that
# `make test` ends with one line saying how many tests ran, failed and were
# skipped (reported ignored).
set -euo pipefail
log=${1:?usage: test-summary.sh LOG}
grep -E '^test result:' "$log" | awk '
    { for (i = 1; i <= NF; i++) {
        if ($(i + 1) ~ /^passed/) p += $i
        if ($(i + 1) ~ /^failed/) f += $i
        if ($(i + 1) ~ /^ignored/) s += $i } }
    END { printf "make test: %d passed, %d failed, %d skipped (ignored)\n", p, f, s }'
