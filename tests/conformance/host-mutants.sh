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

# Each mutant: a name, a file, an exact text that occurs once in it, and
# its replacement.
mutants=(
    "every buffer gets VERTEX usage and is bound whole (the old host layer)"
    crates/vista-gpu/src/wgpu_run.rs
    "size: std::num::NonZeroU64::new(*size),"
    "size: None,"

    "dst-alpha and one-minus-dst-alpha swapped"
    crates/vista-gpu/src/raster.rs
    "BlendFactor::DstAlpha => W::DstAlpha,"
    "BlendFactor::DstAlpha => W::OneMinusDstAlpha,"

    "uniform mat3x3 packed without padding"
    crates/vista-kernels/src/layout.rs
    "let stride = if r == 2 { 8 } else { 16 };"
    "let stride = 4 * r;"

    "storage mat3x3 packed without padding"
    crates/vista-kernels/src/graph.rs
    "let col_stride = if *rows as u32 == 2 { 8 } else { 16 };"
    "let col_stride = 4 * *rows as u32;"

    "instance attributes stepped per vertex"
    crates/vista-gpu/src/raster.rs
    "step_mode: if b.instance { wgpu::VertexStepMode::Instance } else { wgpu::VertexStepMode::Vertex },"
    "step_mode: wgpu::VertexStepMode::Vertex,"

    "mirror-repeat sampled as repeat"
    crates/vista-gpu/src/graph.rs
    "Address::MirrorRepeat => wgpu::AddressMode::MirrorRepeat,"
    "Address::MirrorRepeat => wgpu::AddressMode::Repeat,"

    "a storage view of level 0 instead of its own level"
    crates/vista-gpu/src/wgpu_run.rs
    "base_mip_level: level.unwrap_or(0),"
    "base_mip_level: 0,"

    "depth compare less and less-equal swapped"
    crates/vista-gpu/src/graph.rs
    "let all = [C::Never, C::Less, C::Equal, C::LessEqual,"
    "let all = [C::Never, C::LessEqual, C::Equal, C::Less,"

    "uint16 indices drawn as uint32"
    crates/vista-gpu/src/raster.rs
    "if r.index_u16 { wgpu::IndexFormat::Uint16 } else { wgpu::IndexFormat::Uint32 }"
    "if r.index_u16 { wgpu::IndexFormat::Uint32 } else { wgpu::IndexFormat::Uint32 }"
    "a draw's first instance dropped"
    crates/vista-gpu/src/wgpu_run.rs
    "let instances = raster.first_instance..raster.first_instance + raster.instances;"
    "let instances = 0..raster.instances;"
    "an indexed draw's base vertex dropped"
    crates/vista-gpu/src/wgpu_run.rs
    "pass.draw_indexed(0..raster.count, raster.base_vertex, instances);"
    "pass.draw_indexed(0..raster.count, 0, instances);"
)

backup=$(mktemp -d)
# Restored with a new mtime (never the backup's old one: cargo would
# take the mutant's build for current).
trap 'cp -r "$backup/." . 2>/dev/null; (cd "$backup" && find . -type f -exec touch "$root/{}" \;); rm -rf "$backup"' EXIT

missed=0
for ((m = 0; m < ${#mutants[@]}; m += 4)); do
    name=${mutants[m]} file=${mutants[m + 1]} from=${mutants[m + 2]} to=${mutants[m + 3]}
    mkdir -p "$backup/$(dirname "$file")"
    [ -e "$backup/$file" ] || cp "$file" "$backup/$file"
    # The old host layer had both: VERTEX usage on every buffer, and the
    # binding left whole. (Either alone is not observable: a buffer bound with
    # its size shows its length whatever its usages.)
    if [ "$m" -eq 0 ]; then
        sed -i 's/usage: usages\[i\].unwrap_or_default().wgpu(),/usage: usages[i].unwrap_or_default().wgpu() | wgpu::BufferUsages::VERTEX,/' "$file"
    fi
    python3 - "$file" "$from" "$to" <<'PY' || { echo "MUTANT NOT APPLIED: $name ($file)"; missed=1; continue; }
import sys
path, a, b = sys.argv[1:]
text = open(path).read()
if text.count(a) != 1:
    sys.exit(f"{path}: the mutated text occurs {text.count(a)} times")
open(path, "w").write(text.replace(a, b))
PY
    out=$(cargo test --test conformance 2>&1)
    caught=$(grep -oE '^test conformance::[^ ]+ +\.\.\. FAILED' <<<"$out" | sed -E 's/^test (conformance::[^ ]+) .*/\1/' | sort)
    cp "$backup/$file" "$file"
    if [ -n "$caught" ]; then
        echo "caught: $name: $(wc -l <<<"$caught") probes: $(tr '\n' ' ' <<<"$caught")"
    elif grep -q "could not compile" <<<"$out"; then
        echo "DID NOT BUILD: $name"; missed=1
    else
        echo "NOT CAUGHT: $name"; missed=1
    fi
done
exit $missed
