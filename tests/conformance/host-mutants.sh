#!/usr/bin/env bash
# Mutates vista's host layer on purpose, one mutant at a time, and shows
# which conformance probes catch each (tests/conformance.rs on lavapipe,
# SwiftShader and Chromium). Every mutant must be caught; exits 1 if one
# is not. Restores each file afterwards, also when interrupted. Not part of
# `make test` (one rebuild per mutant): run `bash tests/conformance/host-mutants.sh`.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}

# name | file | exact text (once in the file) | its replacement
mutants=(
"every buffer VERTEX and bound whole (the old host layer)|crates/vista-gpu/src/wgpu_run.rs|usage: usages[i].unwrap_or_default().wgpu(),|usage: usages[i].unwrap_or_default().wgpu() \| wgpu::BufferUsages::VERTEX,"
"binding without its size|crates/vista-gpu/src/wgpu_run.rs|size: std::num::NonZeroU64::new(*size),|size: None,"
"dst-alpha and one-minus-dst-alpha swapped|crates/vista-gpu/src/raster.rs|BlendFactor::DstAlpha => W::DstAlpha,|BlendFactor::DstAlpha => W::OneMinusDstAlpha,"
"uniform mat3x3 packed without padding|crates/vista-kernels/src/layout.rs|let stride = if r == 2 { 8 } else { 16 };|let stride = 4 * r;"
"storage mat3x3 packed without padding|crates/vista-kernels/src/graph.rs|let col_stride = if *rows as u32 == 2 { 8 } else { 16 };|let col_stride = 4 * *rows as u32;"
"instance attributes stepped per vertex|crates/vista-gpu/src/raster.rs|step_mode: if b.instance { wgpu::VertexStepMode::Instance } else { wgpu::VertexStepMode::Vertex },|step_mode: wgpu::VertexStepMode::Vertex,"
"mirror-repeat sampled as repeat|crates/vista-gpu/src/graph.rs|Address::MirrorRepeat => wgpu::AddressMode::MirrorRepeat,|Address::MirrorRepeat => wgpu::AddressMode::Repeat,"
"storage view of level 0 instead of its level|crates/vista-gpu/src/wgpu_run.rs|base_mip_level: level.unwrap_or(0),|base_mip_level: 0,"
)

backup=$(mktemp -d)
trap 'for p in "$backup"/*.path; do [ -e "$p" ] && cp "${p%.path}" "$(cat "$p")"; done; rm -rf "$backup"' EXIT

missed=0
for m in "${mutants[@]}"; do
    IFS='|' read -r name file from to <<<"$m"
    key=$(echo "$file" | tr '/' '_')
    cp "$file" "$backup/$key"; echo "$file" >"$backup/$key.path"
    python3 - "$file" "$from" "$to" <<'PY' || { echo "MUTANT NOT APPLIED: $name ($file)"; missed=1; continue; }
import sys
path, a, b = sys.argv[1:]
text = open(path).read()
if text.count(a) != 1:
    sys.exit(f"{path}: the mutated text occurs {text.count(a)} times")
open(path, "w").write(text.replace(a, b))
PY
    out=$(cargo test -q --test conformance 2>&1)
    caught=$(grep -oE '^test conformance::[^ ]+ \.\.\. FAILED' <<<"$out" | sed -E 's/^test (conformance::[^ ]+) .*/\1/' | sort)
    cp "$backup/$key" "$file"; rm -f "$backup/$key" "$backup/$key.path"
    if [ -n "$caught" ]; then
        echo "caught: $name: $(wc -l <<<"$caught") probes: $(tr '\n' ' ' <<<"$caught")"
    elif grep -q "^error" <<<"$out"; then
        echo "DID NOT BUILD: $name"; missed=1
    else
        echo "NOT CAUGHT: $name"; missed=1
    fi
done
exit $missed
