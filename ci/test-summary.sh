#!/usr/bin/env bash
# Sums the closing lines of every test binary in a `cargo test` log, so that
# `make test` ends with one line saying how many tests ran, failed and were
# skipped (reported ignored); then, loudly, any check the log says was not
# run for want of a tool (cargo-nextest: ci/harness-nextest.sh).
set -euo pipefail
log=${1:?usage: test-summary.sh LOG}
grep -E '^test result:' "$log" | awk '
    { for (i = 1; i <= NF; i++) {
        if ($(i + 1) ~ /^passed/) p += $i
        if ($(i + 1) ~ /^failed/) f += $i
        if ($(i + 1) ~ /^ignored/) s += $i } }
    END { printf "make test: %d passed, %d failed, %d skipped (ignored)\n", p, f, s }'
if grep -q '^!!! harness-nextest: NOT RUN' "$log"; then
    echo "!!! make test: NOT RUN: the golden harness under cargo-nextest (a process per case, one report, partitions"
    echo "!!! merged): cargo-nextest is not installed here. Install it (cargo install --locked cargo-nextest) and rerun."
elif grep -q '^harness-nextest: under cargo-nextest' "$log"; then
    echo "make test: the golden harness under cargo-nextest: checked (ci/harness-nextest.sh)"
fi
