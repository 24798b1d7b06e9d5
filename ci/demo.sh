#!/usr/bin/env bash
# Renders every preset of every kernel into OUT (PNG display values),
# then runs `vista check` over all golden cases and prints the report path.
set -euo pipefail
vista=${1:-target/debug/vista}
out=${2:-out}
mkdir -p "$out"
names=$("$vista" list --names)
count=$(grep -c . <<<"$names")
# Two renders at a time: each is its own process whose start and shader
# compilation use one core (42 presets, warm cache: 62-69 s against 78-79 s
# one at a time). xargs exits non-zero if any render failed.
export VISTA_DEMO_OUT=$out
xargs -P 2 -n 2 sh -c 'exec "$0" render "$1" --preset "$2" --size 256x256 -o "$VISTA_DEMO_OUT/$1-$2.png"' "$vista" <<<"$names"
echo "demo: rendered $count presets into $out/"
"$vista" check
