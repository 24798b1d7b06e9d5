#!/usr/bin/env bash
# The figures on a hardware GPU, in one run: `vista bench` for every
# kernel (its default params) and the seed's clouds study on both scenes,
# written under OUT with the adapter named. Never part of make test or CI.
# Usage: ci/device-figures.sh VISTA OUT [WxH]
#   (1920x1080 and `--backend gpu` by default; BACKEND=lavapipe and a small
#   size, e.g. 64x36, try the script itself without a GPU.)
# Writes OUT/bench.jsonl (one `vista bench --json` object per kernel),
# OUT/bench.md (a table of them) and OUT/seed-study/{slab,shell,README.md}.
set -euo pipefail
vista=${1:?usage: ci/device-figures.sh VISTA OUT [WxH]}
out=${2:?usage: ci/device-figures.sh VISTA OUT [WxH]}
size=${3:-1920x1080}
backend=${BACKEND:-gpu}
[[ $size =~ ^[0-9]+x[0-9]+$ ]] || { echo "device-figures: size '$size' is not WIDTHxHEIGHT" >&2; exit 2; }
# Both paths as the caller meant them, before moving to the repository root.
vista=$(command -v "$vista" || true)
[ -x "$vista" ] || { echo "device-figures: no vista executable '${1}'" >&2; exit 2; }
vista=$(cd "$(dirname "$vista")" && pwd)/$(basename "$vista")
mkdir -p "$out"
out=$(cd "$out" && pwd)
cd "$(dirname "$0")/.."
# The study's 512-step reference at 1920x1080 is above the default work cap.
export VISTA_MAX_WORK=${VISTA_MAX_WORK:-1e14}
start=$SECONDS

kernels=$("$vista" list --names | awk '{ print $1 }' | sort -u)
: >"$out/bench.jsonl.tmp"
for k in $kernels; do
    echo "device-figures: vista bench $k --size $size --backend $backend"
    "$vista" bench "$k" --size "$size" --backend "$backend" --json >>"$out/bench.jsonl.tmp"
done
mv "$out/bench.jsonl.tmp" "$out/bench.jsonl"
# One field of the JSON object in $line, by name, so that a new field in
# bench's JSON moves nothing.
f() { sed -E "s/.*\"$1\":(\"[^\"]*\"|[^,}]*).*/\\1/; s/^\"//; s/\"$//" <<<"$line"; }
{
    echo "| kernel | size | median ms | Mpix/s | first dispatch ms | adapter |"
    echo "|---|---|---|---|---|---|"
    while IFS= read -r line; do
        printf '| %s | %sx%s | %.3f | %.1f | %.1f | %s |\n' "$(f kernel)" "$(f width)" "$(f height)" \
            "$(f median_ms)" "$(f mpix_per_s)" "$(f first_dispatch_ms)" "$(f adapter | sed 's/ | .*//')"
    done <"$out/bench.jsonl"
} >"$out/bench.md.tmp"
mv "$out/bench.md.tmp" "$out/bench.md"
cat "$out/bench.md"

export VISTA_STUDY_ARGS="--backend $backend ${VISTA_STUDY_ARGS:-}"
bash ci/seed-study.sh "$vista" "$out/seed-study/slab" "$size" seed
bash ci/seed-study.sh "$vista" "$out/seed-study/shell" "$size" seed-scene
bash ci/seed-study-index.sh "$out/seed-study"
echo "device-figures: $out/bench.md and $out/seed-study/README.md in $((SECONDS - start)) s"
