#!/usr/bin/env bash
# Installs Debian's lcov (genhtml) so that the suite checks that the
# lcov.info of `vista check --coverage` is one genhtml accepts. Idempotent.
set -euo pipefail
bash "$(dirname "$0")/apt-install.sh" genhtml lcov
echo "install-lcov: $(genhtml --version)"
