#!/usr/bin/env bash
# The cost of `vista check --coverage` against `vista check`: each project's
# whole check run alternately without and with coverage (ROUNDS times, each
# with a fresh Mesa shader cache, as on a fresh CI machine), wall times
# and their ratio printed as a markdown table. Usage:
#   bash ci/coverage-cost.sh [VISTA] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
vista=$(realpath "${1:-target/debug/vista}")
rounds=${2:-2}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| project | cases | check s | check --coverage s | ratio | lines | branch arms |"
echo "|---|---|---|---|---|---|---|"
for project in . examples/project examples/graphs examples/render examples/sources; do
    plain=() covered=() cases="" summary=""
    for r in $(seq "$rounds"); do
        for mode in plain coverage; do
            flag=""; [ "$mode" = coverage ] && flag="--coverage"
            cache="$work/cache-$mode-$r"; mkdir -p "$cache"
            start=$(date +%s.%N)
            out=$(cd "$project" && MESA_SHADER_CACHE_DIR="$cache" "$vista" check $flag --report-dir "$work/report-$mode" 2>&1) || {
                echo "coverage-cost: $project: vista check $flag failed:" >&2; echo "$out" | tail -5 >&2; exit 1; }
            took=$(echo "$(date +%s.%N) - $start" | bc)
            if [ "$mode" = plain ]; then plain+=("$took"); else covered+=("$took"); fi
            cases=$(grep -o '^[0-9]* passed' <<<"$out" | head -1 | cut -d' ' -f1)
            [ "$mode" = coverage ] && summary=$(grep '^coverage: [0-9.]*% of lines' <<<"$out" | tail -1)
        done
    done
    median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
    p=$(median "${plain[@]}"); c=$(median "${covered[@]}")
    lines=$(sed -E 's/^coverage: ([0-9.]+%) of lines.*\(([0-9]+ of [0-9]+) lines.*/\2 (\1)/' <<<"$summary")
    arms=$(sed -E 's/.*, ([0-9.]+%) of branches.*, ([0-9]+ of [0-9]+) branch arms\).*/\2 (\1)/' <<<"$summary")
    printf '| %s | %s | %.1f | %.1f | %.2f | %s | %s |\n' "$project" "$cases" "$p" "$c" "$(echo "$c / $p" | bc -l)" "$lines" "$arms"
done
