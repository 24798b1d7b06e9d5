#!/usr/bin/env bash
# Times the phases of a new user's first run from a fresh clone, with an
# empty cargo registry and target dir: the apt installs, the crate download,
# the build, then `make demo`'s and `make test`'s own work. Prints one line
# per phase. Usage: ci/first-run.sh [REPO] [WORKDIR]. Needs network for the
# crate download (apt only when something is missing).
set -euo pipefail
repo=${1:-$(cd "$(dirname "$0")/.." && pwd)}
work=${2:-$(mktemp -d)}
export CARGO_HOME="$work/cargo-home" XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
mkdir -p "$CARGO_HOME"
# Keep the toolchain's own config (rustup), nothing cached.
[ -f "${HOME}/.cargo/config.toml" ] && cp "${HOME}/.cargo/config.toml" "$CARGO_HOME/"
git clone -q "$repo" "$work/clone"
cd "$work/clone"
lines=()
n=0
phase() {
    local name=$1
    shift
    local start=$SECONDS log
    n=$((n + 1))
    log="$work/phase-$n.log"
    "$@" >"$log" 2>&1 || { echo "first-run: $name failed, see $log" >&2; tail -20 "$log" >&2; exit 1; }
    lines+=("$(printf '%-34s %5d s' "$name" $((SECONDS - start)))")
}
phase "apt (ci/install-*.sh)" bash -c 'for s in lavapipe swiftshader validation browser; do bash ci/install-$s.sh; done'
phase "crate download (cargo fetch)" cargo fetch
phase "build: vista binary" cargo build -p vista-cli
phase "make demo after the build" make demo
phase "build: tests (cargo test --no-run)" cargo test --workspace --no-run
phase "make test after the build" make test
printf '%s\n' "${lines[@]}"
echo "first-run: total $SECONDS s; logs in $work"
