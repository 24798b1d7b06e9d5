#!/usr/bin/env bash
# Time and memory of `vista check` per case against image size and case
# count, passing and failing: prints a markdown table. Builds
# throwaway projects of fbm cases under a temporary folder; not part of
# `make test`. Usage: bash ci/scaling.sh [vista binary] [counts...]
set -euo pipefail
vista=$(realpath "${1:-target/debug/vista}")
shift || true
counts=("${@:-100 1000}")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# project DIR N SIZE: N fbm cases of SIZE, one seed each.
project() {
    mkdir -p "$1/golden"
    : > "$1/vista.toml"
    for ((i = 0; i < $2; i++)); do
        printf '[[case]]\nid = "fbm-%d"\nkernel = "fbm"\nsize = "%s"\nset = { seed = %d }\n\n' "$i" "$3" "$i"
    done > "$1/golden/cases.toml"
    (cd "$1" && "$vista" bless > /dev/null 2>&1)
}

# measure DIR LABEL N SIZE: one row, from check's own time line and /usr/bin/time.
measure() {
    local out rss wall gpu report size
    out=$(cd "$1" && /usr/bin/time -f "rss %M" "$vista" check --jobs 1 2>&1 || true)
    rss=$(grep -o 'rss [0-9]*' <<< "$out" | cut -d' ' -f2)
    wall=$(grep -o '^time: [0-9.]* s' <<< "$out" | cut -d' ' -f2)
    gpu=$(grep -o 'GPU runs [0-9.]* s' <<< "$out" | cut -d' ' -f3)
    report=$(du -sb "$1/target/vista-report" | cut -f1)
    size=$4
    local px=$(( ${size%x*} * ${size#*x} ))
    awk -v l="$2" -v n="$3" -v s="$size" -v w="$wall" -v g="$gpu" -v r="$rss" -v b="$report" -v px="$px" 'BEGIN {
        printf "| %s | %d x %s | %.2f s | %.2f s | %.1f ms | %.0f MB (%.0f B/px) | %.1f KB |\n",
            l, n, s, w, g, 1000 * (w - g) / n, r / 1024, r * 1024 / px, b / n / 1024 }'
}

# Turns every case's seed into another: every case then fails.
break_all() { sed -i 's/seed = \([0-9]*\) }/seed = 1\1 }/' "$1/golden/cases.toml"; }

echo "| cases | count x size | wall | GPU runs | vista's own per case | peak RSS (per pixel of one case) | report per case |"
echo "|---|---|---|---|---|---|---|"
for size in 64x64 256x256 1024x1024 2048x2048; do
    d="$work/size-$size"
    project "$d" 4 "$size"
    measure "$d" passing 4 "$size"
    break_all "$d"
    measure "$d" failing 4 "$size"
done
for n in ${counts[@]}; do
    d="$work/count-$n"
    project "$d" "$n" 32x32
    measure "$d" passing "$n" 32x32
    break_all "$d"
    measure "$d" failing "$n" 32x32
done
