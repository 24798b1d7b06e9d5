#!/usr/bin/env bash
# Installs Debian's python3 for examples/sources' template renderer
# (tools/render_template.py), which its blur kernel runs through
# `[source] command` in the suite. Idempotent.
set -euo pipefail
bash "$(dirname "$0")/apt-install.sh" python3 python3
echo "install-python: $(python3 --version)"
