#!/usr/bin/env bash
# Installs Debian's lcov (genhtml) so that the suite checks that the
# lcov.info of `vista check --coverage` is one genhtml accepts. Idempotent.
set -euo pipefail
if command -v genhtml >/dev/null 2>&1; then
    echo "install-lcov: genhtml is already installed"
    exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-lcov: installing lcov with apt"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get install -y -qq --no-install-recommends lcov >/dev/null 2>&1 \
    || { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends lcov >/dev/null; }
command -v genhtml >/dev/null || { echo "install-lcov: genhtml still missing after installing lcov" >&2; exit 1; }
echo "install-lcov: $(genhtml --version)"
