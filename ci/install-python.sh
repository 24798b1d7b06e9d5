#!/usr/bin/env bash
# Installs Debian's python3 for examples/sources' template renderer
# (tools/render_template.py), which its blur kernel runs through
# `[source] command` in the suite. Idempotent.
set -euo pipefail
if command -v python3 >/dev/null 2>&1; then
    echo "install-python: $(python3 --version) is already installed"
    exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-python: installing python3 with apt"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get install -y -qq --no-install-recommends python3 >/dev/null 2>&1 \
    || { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends python3 >/dev/null; }
command -v python3 >/dev/null || { echo "install-python: python3 still missing after installing it" >&2; exit 1; }
echo "install-python: $(python3 --version)"
