#!/usr/bin/env bash
# Regenerates docs/mutants/: vista mutate over every kernel with cases, at
# the committed seed and sample, its terminal summary (score per kernel,
# survivors) and the JSON report. Not part of `make test`.
set -euo pipefail
vista=${1:-target/debug/vista}
out=${2:-docs/mutants}
seed=${SEED:-1}
sample=${SAMPLE:-60}
mkdir -p "$out"
start=$(date +%s)
# Survivors argued equivalent (one-line reasons) are kept in $out/equivalent.toml.
args=()
[ -f "$out/equivalent.toml" ] && args=(--equivalent "$out/equivalent.toml")
"$vista" mutate --sample "$sample" --seed "$seed" "${args[@]}" --json "$out/mutants.json" | tee "$out/summary.txt"
secs=$(( $(date +%s) - start ))
{
    echo "# Mutation score (vista mutate --sample $sample --seed $seed)"
    echo
    echo "Regenerate with \`make mutants\` ($secs s on this machine). Each mutant is one"
    echo "change in a kernel's WGSL or the lib modules it imports, run against the"
    echo "kernel's golden cases and its GPU-vs-CPU check (see SPEC 12)."
    echo "\`equivalent?\` survivors are bit-identical to the unmutated render on every"
    echo "case: truly equivalent, or code no case reaches. Survivors argued equivalent,"
    echo "each with a one-line reason, are listed in \`equivalent.toml\` and excluded"
    echo "from the score (\`argued\`); every other survivor counts, and"
    echo "[SURVIVORS.md](SURVIVORS.md) says why each is harmless."
    echo
    echo '```'
    cat "$out/summary.txt"
    echo '```'
} > "$out/SUMMARY.md"
echo "mutants: wrote $out/SUMMARY.md and $out/mutants.json in ${secs} s"
