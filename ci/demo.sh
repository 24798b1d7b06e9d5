#!/usr/bin/env bash
# Renders every preset of every kernel into OUT (PNG display values),
# then runs `vista check` over all golden cases and prints the report path.
set -euo pipefail
vista=${1:-target/debug/vista}
out=${2:-out}
mkdir -p "$out"
count=0
while read -r kernel preset; do
    "$vista" render "$kernel" --preset "$preset" --size 256x256 -o "$out/$kernel-$preset.png"
    count=$((count + 1))
done < <("$vista" list --names)
echo "demo: rendered $count presets into $out/"
"$vista" check
